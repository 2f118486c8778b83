"""``tools/occlusion/spread.py``: whether the walker's spread decides the occlusion scenes
(docs/experiments.md, "Does the walker's spread decide it?")."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

TOOL = Path(__file__).resolve().parents[3] / "tools" / "occlusion" / "spread.py"


def test_the_difference_pools_ps_and_dps_and_leaves_non_ps_out(tool, tmp_path, monkeypatch):
    # σ = 1: PS and DPS lose the walker in every run, Non-PS keeps it; σ = 3: the reverse.
    def fake(folder):
        sigma = float(Path(folder).parent.name.split("-")[1])
        ok = sigma > 2
        runs = {lb: {(s, r): ok for s in range(4) for r in range(2)}
                for lb in ("PS(1,2,3)", "PS(2,3,1)", "DPS")}  # fmt: skip
        runs["Non-PS"] = {(s, r): not ok for s in range(4) for r in range(2)}
        return {"dps-occlusion": runs}

    monkeypatch.setattr(tool, "outcomes", fake)
    lines = tool.table(tmp_path, [1.0, 3.0], [1, 2])
    assert lines[0] == ("dps-occlusion sigma 1: PS(1,2,3) 0 %, PS(2,3,1) 0 %, DPS 0 %, "
                        "Non-PS 100 %; PS pooled 0 %")
    assert lines[1].endswith("Non-PS 0 %; PS pooled 100 %")
    assert lines[2] == ("dps-occlusion: PS and DPS pooled, sigma 3 - sigma 1: +100.0 points "
                        "(95 % interval +100.0 to +100.0; 8 scenes)")
    assert tool.folder(tmp_path, 2.5, 7) == tmp_path / "sigma-2.5" / "seed-7"


def test_the_command_runs_resumes_and_prints_both_presets(tmp_path):
    cmd = [sys.executable, str(TOOL), "--seeds", "1", "--sigmas", "1,3", "--scenes", "1",
           "--runs", "1", "--quick", "--jobs", "1", "--method", "ps-123", "--method", "dps",
           "-o", str(tmp_path)]
    first = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert first.returncode == 0, first.stderr
    records = sorted((tmp_path / "sigma-3" / "seed-1" / "runs").iterdir())
    assert len(records) == 4 and all("sigma-(3, 3, 0.001)" in p.name for p in records)
    stamps = [p.stat().st_mtime_ns for p in records]
    again = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert again.returncode == 0 and "warning" not in again.stderr
    assert [p.stat().st_mtime_ns for p in records] == stamps  # resumed, not recomputed
    lines = [ln for ln in again.stdout.splitlines() if ln.startswith("dps-occlusion")]
    assert [ln.split(":")[0] for ln in lines] == [
        "dps-occlusion sigma 1", "dps-occlusion sigma 3", "dps-occlusion",
        "dps-occlusion-2 sigma 1", "dps-occlusion-2 sigma 3", "dps-occlusion-2"]
    assert "PS and DPS pooled, sigma 3 - sigma 1: " in lines[2]
