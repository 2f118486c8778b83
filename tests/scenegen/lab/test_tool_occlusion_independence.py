"""``tools/occlusion/independence.py``: whether a scene decides who loses the walker
(docs/experiments.md, "The re-tuned `dps-occlusion-2` on the same 30 scenes")."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

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


def test_the_tool_reads_an_experiment_folder(tmp_path, capsys):
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
