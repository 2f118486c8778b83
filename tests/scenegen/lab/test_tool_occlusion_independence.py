"""``tools/occlusion/independence.py``: whether a scene decides who loses the walker
(docs/experiments.md, "The re-tuned `dps-occlusion-2` on the same 30 scenes")."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from scenegen.cli import main

TOOL = Path(__file__).resolve().parents[3] / "tools" / "occlusion" / "independence.py"


def _runs(table: dict[str, list[list[int]]]) -> dict[str, dict[tuple[int, int], bool]]:
    """label -> outcomes[scene][run] as the tool's per-method mapping."""
    return {lb: {(s, r): bool(v) for s, row in enumerate(rows) for r, v in enumerate(row)}
            for lb, rows in table.items()}  # fmt: skip


def test_identical_methods_correlate_fully_and_any_ordering_is_the_union_bound(tool):
    a = [[1, 0], [1, 1], [0, 0]]
    s = tool.summary(_runs({"PS(1,2,3)": a, "PS(2,3,1)": a, "DPS": [[1, 1], [0, 1], [1, 0]]}))
    assert s["phi"][1] == pytest.approx(1.0)
    assert s["rate"]["PS(1,2,3)"] == pytest.approx(0.5)
    assert s["any"] == pytest.approx(1 - 0.5 * 0.5)
    assert s["dps"] == pytest.approx(4 / 6) and s["ps_mean"] == pytest.approx(0.5)
    assert (s["scenes"], s["pairs"]) == (3, 6)


def test_scene_spread_is_one_for_alike_scenes_and_large_when_scenes_decide(tool):
    # Each scene decides: every method and run succeed on scene 0 and fail on scene 1.
    decided = tool.summary(_runs({"PS(1,2,3)": [[1, 1], [0, 0]] * 5,
                                  "DPS": [[1, 1], [0, 0]] * 5}))  # fmt: skip
    assert decided["spread"] > 3 and decided["scene_range"] == (0.0, 1.0)
    # Alike scenes: the same outcomes on every scene (variance 0 across scenes).
    alike = tool.summary(_runs({"PS(1,2,3)": [[1, 0]] * 6, "DPS": [[0, 1]] * 6}))
    assert alike["spread"] == pytest.approx(0.0) and alike["phi"][0] == pytest.approx(-1.0)


def test_only_pairs_every_method_ran_are_used(tool):
    runs = _runs({"PS(1,2,3)": [[1, 0], [1, 1]], "DPS": [[1, 1]]})
    s = tool.summary(runs)
    assert s["pairs"] == 2 and s["rate"]["PS(1,2,3)"] == pytest.approx(0.5)


def test_the_tool_reads_an_experiment_folder(tool, tmp_path, capsys):
    out = tmp_path / "occ"
    assert main(["experiment", "dps-occlusion", "--scenes", "2", "--runs", "1", "--quick",
                 "--method", "nonps", "--method", "ps-123", "--method", "dps", "--jobs", "1",
                 "-o", str(out)]) == 0
    capsys.readouterr()
    res = subprocess.run([sys.executable, str(TOOL), str(out)], capture_output=True, text=True,
                         timeout=300)
    assert res.returncode == 0, res.stderr
    lines = res.stdout.strip().splitlines()
    assert lines[0].startswith("dps-occlusion: 2 scenes, 2 (scene, run) pairs; Non-PS ")
    assert any(ln.startswith("  any ordering keeps it: ") for ln in lines)
    assert sum(ln.startswith("dps-occlusion-2: 2 scenes, 2 (scene") for ln in lines) == 1
    assert sum(ln.startswith("  per-scene success ") for ln in lines) == 2
    assert sum(ln.startswith("  DPS's lead per scene: variance ") for ln in lines) == 2
    assert sum(ln.startswith("  DPS - PS pooled: ") for ln in lines) == 2

    # The pooled lead is the experiment's own claim (one definition: the same bootstrap
    # over the same per-scene differences), and pooling a folder with itself keeps it.
    claims = {c["claim"]: c for c in json.loads((out / "results.json").read_text())["claims"]}
    claim = claims["dps-occlusion: occluded object's success of DPS above the PS orderings' "
                   "(pooled)"]  # fmt: skip
    one = tool.lead(tool.outcomes(out)["dps-occlusion"])
    assert one[0] == pytest.approx(claim["effect"], abs=1e-3)
    twice = tool.pooled([out, out])
    assert sorted({sc for sc, _ in twice["dps-occlusion"]["DPS"]}) == [(0, 0), (0, 1),
                                                                       (1, 0), (1, 1)]
    assert tool.lead(twice["dps-occlusion"])[0] == pytest.approx(one[0])
    res = subprocess.run([sys.executable, str(TOOL), str(out), str(out)], capture_output=True,
                         text=True, timeout=300)  # fmt: skip
    assert res.returncode == 0, res.stderr
    lines = res.stdout.strip().splitlines()
    assert lines[0] == f"pooled over 2 folders: {out}, {out}"
    assert lines[1].startswith("dps-occlusion: 4 scenes, 4 (scene, run) pairs; Non-PS ")


def _alike(n_scenes: int, seed: int) -> dict[str, dict[tuple[int, int], bool]]:
    """DPS and three orderings with the same success chance, 50 %, on every scene."""
    rng = np.random.default_rng(seed)
    return _runs({lb: rng.integers(0, 2, (n_scenes, 5)).tolist()
                  for lb in ("PS(1,2,3)", "PS(2,3,1)", "PS(3,1,2)", "DPS")})  # fmt: skip


def test_the_lead_is_the_mean_per_scene_difference_with_a_scene_bootstrap(tool):
    runs = _runs({"PS(1,2,3)": [[0, 0], [1, 0], [0, 0]], "PS(2,3,1)": [[0, 0], [1, 1], [0, 1]],
                  "DPS": [[1, 1], [1, 1], [0, 0]]})  # fmt: skip
    effect, (lo, hi), p = tool.lead(runs)
    # Per scene: 100 - 0, 100 - 75, 0 - 25 points; their mean.
    assert effect == pytest.approx((100 + 25 - 25) / 3)
    assert lo <= effect <= hi and 0 < p < 0.5
    assert tool.lead(runs, rng=3) == tool.lead(runs, rng=3)  # seeded
    every = _runs({"PS(1,2,3)": [[0, 0]] * 4, "DPS": [[1, 1]] * 4})
    effect, ci, p = tool.lead(every)
    assert (effect, ci) == (100.0, (100.0, 100.0)) and p < 0.001  # the bootstrap's floor
    assert tool.lead(_runs({"PS(1,2,3)": [[1]]})) is None


def test_pooled_folders_key_scenes_by_folder(tool, monkeypatch):
    a = {"dps-occlusion": _runs({"PS(1,2,3)": [[1], [0]], "DPS": [[1], [1]]}),
         "dps-occlusion-2": _runs({"DPS": [[0]]})}
    b = {"dps-occlusion": _runs({"PS(1,2,3)": [[0]], "DPS": [[0]], "Non-PS": [[1]]})}
    monkeypatch.setattr(tool, "outcomes", lambda f: {"a": a, "b": b}[f])
    out = tool.pooled(["a", "b"])
    assert list(out) == ["dps-occlusion"]  # only presets and methods every folder has
    assert out["dps-occlusion"]["DPS"] == {((0, 0), 0): True, ((0, 1), 0): True,
                                           ((1, 0), 0): False}
    assert set(out["dps-occlusion"]) == {"DPS", "PS(1,2,3)"}
    assert tool.pooled(["a"]) is a
    s = tool.summary(out["dps-occlusion"])
    assert (s["scenes"], s["pairs"]) == (3, 3)
    # The permutation test and the planted-scene power take (folder, scene) keys too.
    assert tool.interaction(out["dps-occlusion"])["argmax"] in {(0, 1), (0, 0)}
    assert 0.0 <= tool.power(out["dps-occlusion"], 1, trials=3, n_perm=20) <= 1.0


def test_the_interaction_is_flat_when_dps_leads_alike_on_every_scene(tool):
    same = [[1, 0, 1, 0, 1], [0, 1, 0, 1, 0]] * 4
    it = tool.interaction(_runs({"PS(1,2,3)": same, "PS(2,3,1)": same, "DPS": same}))
    assert np.allclose(it["lead"], 0.0) and it["p_var"] == 1.0 and it["p_max"] == 1.0
    assert tool.interaction(_runs({"PS(1,2,3)": same})) is None  # no DPS: nothing to test


def test_the_interaction_flags_scenes_on_which_dps_alone_keeps_the_walker(tool):
    runs = _alike(20, 0)
    for r in range(5):  # scene 7: DPS always keeps the walker, no ordering ever does
        runs["DPS"][(7, r)] = True
        for lb in ("PS(1,2,3)", "PS(2,3,1)", "PS(3,1,2)"):
            runs[lb][(7, r)] = False
    it = tool.interaction(runs)
    assert it["argmax"] == 7 and it["max"] == pytest.approx(1.0) and it["p_max"] < 0.01
    # Without an interaction the test keeps its level: of 40 folders of alike methods,
    # about 2 give p < 0.05 (7 or more has chance 0.001).
    flat = [tool.interaction(_alike(20, seed), n_perm=300, rng=seed) for seed in range(40)]
    assert sum(f["p_var"] < 0.05 for f in flat) < 7 and sum(f["p_max"] < 0.05 for f in flat) < 7
    # Seeded: the same outcomes give the same p-values.
    assert tool.interaction(runs)["p_var"] == it["p_var"]


def test_planted_paper_like_scenes_are_found_more_often_the_more_there_are(tool):
    runs = _alike(20, 1)
    one, four = (tool.power(runs, k, trials=40, n_perm=300, rng=2) for k in (1, 4))
    assert 0.0 < one < four and four > 0.8
    with pytest.raises(ValueError, match="--power 21: between 1 and the 20 scenes"):
        tool.power(runs, 21)
