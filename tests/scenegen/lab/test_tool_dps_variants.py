"""``tools/dps/variants.py``: the scene and experiment variants it runs the DPS
experiments on (docs/experiments.md, "Other readings of PS")."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import scenegen
from scenegen import presets
from scenegen.lab.experiments.definitions import EXPERIMENTS

TOOL = Path(__file__).resolve().parents[3] / "tools" / "dps" / "variants.py"



def test_astray_draws_the_distractor_over_object_1_from_frame_0(tool):
    base = presets.get("dps-synthetic")
    cfg = tool.astray(base)
    (d,) = [e for e in cfg.entities if e.role == "distractor"]
    assert d.appear == 0 and d.disappear == 9
    assert [e for e in cfg.entities if e.role != "distractor"] == \
        [e for e in base.entities if e.role != "distractor"]
    seq = scenegen.generate(cfg, seed=3, frames=4)
    ids = {name: i for i, name in zip(seq.entities.id, seq.entities.name, strict=True)}
    x, y, w, h = np.round(seq.init_boxes(0)[0]).astype(int)
    patch = np.asarray(seq.labels[0])[y + 2:y + h - 2, x + 2:x + w - 2]
    # At frame 0 object 1's box shows the distractor: trackers learn its model from it.
    assert np.mean(patch == ids["distractor1"]) > 0.9
    assert np.mean(np.asarray(scenegen.generate(base, seed=3, frames=4).labels[0])
                   [y + 2:y + h - 2, x + 2:x + w - 2] == ids["object1"]) > 0.9
    with pytest.raises(SystemExit, match="no distractor"):
        tool.astray(presets.get("dps-occlusion"))


def test_lam_replaces_the_sweep_or_every_methods_lam(tool):
    syn = tool.with_lam(EXPERIMENTS["dps-synthetic"], (150.0,))
    assert syn.sweep == (("lam", (150.0,)),)
    occ = tool.with_lam(EXPERIMENTS["dps-occlusion"], (40.0,))
    assert all(m.param_dict()["lam"] == 40.0 for m in occ.methods)
    assert [m.slug for m in occ.methods] == [m.slug for m in EXPERIMENTS["dps-occlusion"].methods]
    with pytest.raises(SystemExit, match="one --lam"):
        tool.with_lam(EXPERIMENTS["dps-occlusion"], (20.0, 40.0))


def test_astray_is_refused_outside_dps_synthetic(tmp_path):
    out = subprocess.run([sys.executable, str(TOOL), "dps-occlusion", "--seeds", "1",
                          "--astray", "-o", str(tmp_path)], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode != 0 and "dps-synthetic only" in out.stderr
    assert not any(tmp_path.iterdir())
