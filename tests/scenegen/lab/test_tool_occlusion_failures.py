"""``tools/occlusion/failures.py``: where the walker is lost, against the scene's events
(docs/experiments.md, "Where the walker is lost")."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from scenegen.cli import main
from scenegen.errors import DataError
from scenegen.io.sealed import seal

TOOL = Path(__file__).resolve().parents[3] / "tools" / "occlusion" / "failures.py"


def test_events_name_who_the_walker_crosses_and_on_which_side(tool):
    # dps-occlusion-2: behind the first stationary person, then in front of the second.
    ev = tool.events("dps-occlusion-2", 1, 0, 10)
    assert [e[0] for e in ev] == ["behind standing1", "in front of standing2"]
    (_, a1, b1), (_, a2, b2) = ev
    assert 0 < a1 < b1 < a2 < b2
    assert tool.events("dps-occlusion-2", 1, 0, 0)[1][2] == b2 - 10  # the grace
    vis = tool.visibility("dps-occlusion-2", 1, 0)
    assert vis[a1:b1].min() < 0.05  # hidden behind the first person
    assert vis[a2:b2 - 10].min() > 0.95  # in front of the second: visible throughout
    # dps-occlusion: behind both.
    assert [e[0] for e in tool.events("dps-occlusion", 1, 0, 10)] == [
        "behind standing1", "behind standing2"]


def test_first_lost_ignores_frame_0_and_unscored_frames(tool):
    assert tool.first_lost([0, 1, None, 1, 0, 1]) == 4
    assert tool.first_lost([0, 1, 1]) is None


def test_failures_are_placed_at_the_event_they_begin_in(tmp_path, tool, capsys):
    out = tmp_path / "occ"
    assert main(["experiment", "dps-occlusion", "--scenes", "1", "--runs", "1", "--seed", "1",
                 "--method", "nonps", "--jobs", "1", "-o", str(out)]) == 0
    capsys.readouterr()
    # Mark the walker lost from the middle of its first occlusion on in one record,
    # resealed (the tool reads records as the experiment does).
    (_, a, b), _ = tool.events("dps-occlusion-2", 1, 0, 10)
    lost_at = (a + b) // 2
    rec_path = next((out / "runs").glob("nonps__dps-occlusion-2__*.json"))
    rec = json.loads(rec_path.read_text())
    rec.pop("sha256")
    walker = rec["targets"][0]
    walker["state"] = [1] * lost_at + [0] * (len(walker["state"]) - lost_at)
    rec_path.write_text(json.dumps(seal(rec)))
    table, names = tool.lost(out)
    assert names["dps-occlusion-2"] == ["behind standing1", "in front of standing2",
                                        "elsewhere"]
    (row,) = table[("dps-occlusion-2", "Non-PS")]
    assert row[:2] == (lost_at, "behind standing1")
    vis = tool.visibility("dps-occlusion-2", 1, 0)
    assert np.isclose(row[2], vis[lost_at])
    assert row[3] == lost_at - np.flatnonzero(vis[:lost_at + 1] < 0.05)[-1]
    edited = seal(rec)
    edited["n_frames"] += 1  # an edit the digest does not cover
    rec_path.write_text(json.dumps(edited))
    with pytest.raises(DataError, match=rec_path.name):
        tool.lost(out)
    rec_path.write_text(json.dumps(seal(rec)))
    res = subprocess.run([sys.executable, str(TOOL), str(out)], capture_output=True, text=True,
                         timeout=300)
    assert res.returncode == 0, res.stderr
    lines = res.stdout.strip().splitlines()
    assert lines[0].startswith("dps-occlusion: method") and lines[2].startswith(
        "dps-occlusion-2: method")
    assert lines[3].split()[:4] == ["Non-PS", "1", "/", "1"]
