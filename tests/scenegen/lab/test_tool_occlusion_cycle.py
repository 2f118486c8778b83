"""``tools/occlusion/cycle.py``: the walker's diversity at its own propagation and at the
end of the step (docs/experiments.md, "DPS Table 3 with the `stage` weighting")."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np

TOOL = Path(__file__).resolve().parents[3] / "tools" / "occlusion" / "cycle.py"


def test_the_last_placed_object_ends_the_step_unique_but_moved_from_few_ancestors(tool):
    # PS(2,3,1) samples the walker last: after its propagation every particle carries a
    # distinct walker state (end uniqueness 1), yet it moved from a minority of distinct
    # ancestors, thinned by the two stages before it.
    last = tool.measure("dps-occlusion", 1, 0, "ps-231", 0)
    first = tool.measure("dps-occlusion", 1, 0, "ps-123", 0)
    assert last.shape == (6,)
    assert last[2] == 1.0 and last[5] == 1.0
    assert first[2] < 0.6  # sampled first, thinned by the next two stages
    assert 0.0 < last[0] < 0.5 and 0.0 < first[0] < 0.5
    assert np.all(last[[1, 4]] > 0.0)


def test_param_reaches_every_method_and_a_peaked_likelihood_keeps_fewer_ancestors(tool):
    base = tool.measure("dps-occlusion", 1, 0, "dps", 0)
    peaked = tool.measure("dps-occlusion", 1, 0, "dps", 0, extra={"lam": 150.0})
    assert peaked[0] < 0.5 * base[0]
    assert not np.allclose(tool.measure("dps-occlusion", 1, 0, "dps", 0, weighting="placed"),
                           base)


def test_command_line_prints_one_row_per_method():
    out = subprocess.run([sys.executable, str(TOOL), "dps-occlusion-2", "--seeds", "1",
                          "--scenes", "1", "--param", "lam=40"], capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    rows = out.stdout.strip().splitlines()
    assert rows[0].startswith("method")
    assert [r.split()[0] for r in rows[1:]] == ["Non-PS", "PS(1,2,3)", "PS(2,3,1)",
                                               "PS(3,1,2)", "DPS"]


def test_mixture_weights_leave_a_third_only_under_the_prior_mixture(tool):
    evidence = tool.largest_mixture_weight("dps-occlusion", 1, 0, 0)
    prior = tool.largest_mixture_weight("dps-occlusion", 1, 0, 0, {"mixture": "prior"})
    np.testing.assert_allclose(prior, 67 / 200)  # N = 200 in groups of 67, 67, 66
    assert evidence[0] > 0.38 and evidence[1] >= evidence[0]


def test_command_line_prints_the_mixture_weights_per_scene():
    out = subprocess.run([sys.executable, str(TOOL), "dps-occlusion", "--seeds", "1",
                          "--scenes", "1", "--mixture", "--param", "mixture=prior"],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    rows = out.stdout.strip().splitlines()
    assert len(rows) == 2 and rows[1].split() == ["1", "0", "0", "0.335", "0.335"]
