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


@pytest.mark.parametrize(("experiment", "flag", "message"), [
    ("dps-occlusion", "--astray", "dps-synthetic only"),
    ("dps-synthetic", "--crowd", "dps-occlusion only"),
])
def test_a_variant_is_refused_on_another_experiment(tmp_path, experiment, flag, message):
    out = subprocess.run([sys.executable, str(TOOL), experiment, "--seeds", "1", flag,
                          "-o", str(tmp_path)], capture_output=True, text=True, timeout=120)
    assert out.returncode != 0 and message in out.stderr
    assert not any(tmp_path.iterdir())


def _overlap(a, b) -> bool:
    return a[0] < b[0] + b[2] and b[0] < a[0] + a[2] and a[1] < b[1] + b[3] and b[1] < a[1] + a[3]


@pytest.mark.parametrize("name", ["dps-occlusion", "dps-occlusion-2"])
def test_crowd_adds_four_tracked_objects_away_from_the_walkers_path(tool, name):
    base = presets.get(name)
    cfg = tool.crowd(base)
    assert cfg.entities[:len(base.entities)] == base.entities
    extra = cfg.entities[len(base.entities):]
    assert [e.name for e in extra] == ["extra1", "extra2", "extra3", "extra4"]
    assert all(e.role == "target" and e.motion is None for e in extra)
    assert [e.appearance.pattern for e in extra] == [p for _, p, _ in presets._DPS_LOOKS[1:5]]
    seq = scenegen.generate(cfg, seed=2)
    box = np.asarray(seq.gt.box)
    assert box.shape[1] == len(base.entities) + 4
    n0 = len(base.entities)
    # Over the whole sequence no extra object's box touches the walker's or a person's.
    for t in range(seq.n_frames):
        for i in range(n0, n0 + 4):
            assert not any(_overlap(box[t, i], box[t, j]) for j in range(n0)), (t, i)


def test_crowd_experiment_tracks_seven_objects_with_every_ordering(tool):
    exp = tool.crowd_experiment(EXPERIMENTS["dps-occlusion"], 7)
    slugs = [m.slug for m in exp.methods]
    assert slugs[0] == "nonps" and slugs[-1] == "dps"
    assert slugs[1:-1] == ["ps-1234567", "ps-2345671", "ps-3456712", "ps-4567123",
                           "ps-5671234", "ps-6712345", "ps-7123456"]
    assert all(m.param_dict()["n_particles"] == 300 for m in exp.methods)
    assert all(m.param_dict()["lam"] == 20.0 for m in exp.methods)


def test_tune_sets_a_presets_tuned_quantities_in_this_process(tool, monkeypatch):
    table = dict(presets.OCCLUSION2_TUNING)
    monkeypatch.setattr(presets, "OCCLUSION2_TUNING", table)
    done = tool.tune("dps-occlusion-2", ["shirt2=[[40, 140, 40]]", "speed=1.4"])
    assert done == {"shirt2": ((40, 140, 40),), "speed": 1.4}
    assert table["shirt2"] == ((40, 140, 40),) and table["speed"] == 1.4
    cfg = presets.get("dps-occlusion-2")
    walker, _, second = cfg.entities
    assert walker.motion.velocity == (1.4, 0.0)
    assert (40, 140, 40) in second.appearance.colors
    assert (200, 60, 40) not in second.appearance.colors  # the preset's shirt is replaced
    with pytest.raises(SystemExit, match="no tuned quantity 'shirt3'; its quantities: speed"):
        tool.tune("dps-occlusion-2", ["shirt3=1"])
    with pytest.raises(SystemExit, match="has no tuned quantities"):
        tool.tune("dps-synthetic", ["speed=1"])


def test_preset_runs_one_preset_and_tune_needs_it_named(tmp_path):
    out = subprocess.run([sys.executable, str(TOOL), "dps-occlusion", "--seeds", "1",
                          "--tune", "speed=1.4", "-o", str(tmp_path)], capture_output=True,
                         text=True, timeout=120)
    assert out.returncode != 0 and "name the preset (--preset)" in out.stderr
    out = subprocess.run([sys.executable, str(TOOL), "dps-occlusion", "--seeds", "1",
                          "--preset", "dps-occlusion-2", "--tune", "speed=1.4", "--scenes", "1",
                          "--runs", "1", "--method", "nonps", "-o", str(tmp_path)],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    runs = sorted(p.name for p in (tmp_path / "seed-1" / "runs").iterdir())
    assert runs == ["nonps__dps-occlusion-2__s000__r000.json"]
    import json

    variant = json.loads((tmp_path / "seed-1" / "variant.json").read_text())
    assert variant["preset"] == "dps-occlusion-2" and variant["tune"] == {"speed": 1.4}
