"""`scenegen track`: result files per CONTRACT, bad parameters exit 2."""

from __future__ import annotations

import h5py
import numpy as np
import pytest

import scenegen
from scenegen.cli import main
from scenegen.io import read_result
from scenegen.io.integrity import as_text


@pytest.fixture(scope="module")
def crossing(tmp_path_factory):
    path = tmp_path_factory.mktemp("track") / "crossing.h5"
    scenegen.write(path, scenegen.generate("shm-crossing", seed=2, frames=15))
    return path


def test_track_writes_result_with_orderings(crossing, tmp_path, capsys):
    out = tmp_path / "r.h5"
    code = main(["track", str(crossing), "--tracker", "shm-fast", "--seed", "1", "-o", str(out)])
    assert code == 0, capsys.readouterr().err
    res = read_result(out)
    assert res.tracker == "shm-fast" and res.sequence == "shm-crossing" and res.seed == 1
    assert res.boxes.shape == (15, 2, 4) and res.target_ids.tolist() == [1, 2]
    assert res.orderings.shape == (2, 2) and res.order_prob.shape == (15, 2)
    np.testing.assert_allclose(res.order_prob.sum(axis=1), 1.0, atol=1e-5)
    seq = scenegen.read(crossing)
    np.testing.assert_array_equal(res.boxes[0], seq.gt.box[0, :2])
    with h5py.File(out) as f:
        assert as_text(f.attrs["schema"]) == "scenegen/1"
        assert as_text(f["results/shm-fast"].attrs["tracker"]) == "shm-fast"


def test_track_params_are_parsed_and_recorded(crossing, tmp_path, capsys):
    out = tmp_path / "k.h5"
    code = main(["track", str(crossing), "--tracker", "kalman", "-o", str(out)])
    assert code == 0, capsys.readouterr().err
    assert read_result(out).orderings is None


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--tracker", "nope"], "unknown tracker 'nope'; valid trackers: condensation"),
        (["--tracker", "kalman", "--param", "bogus=1"], "unknown parameter 'bogus'"),
        (["--tracker", "kalman", "--param", "noequals"], "--param must be KEY=VALUE"),
        # Accepted, these ran the boxes into a corner of the frame or gave NaN boxes.
        (["--tracker", "kalman", "--param", "motion=ar2", "--param", "a1=2.5", "--param",
          "a2=-0.5"], "a1, a2 must not be explosive (|a2| <= 1 and |a1| <= 1 - a2), got a1=2.5"),
        (["--tracker", "shm", "--param", "motion=ar2", "--param", "a2=-1.5"],
         "a1, a2 must not be explosive"),
        (["--tracker", "shm-fast", "--param", "lam=1e308"], "lam must be in [0, 1e+06]"),
    ],
)
def test_track_bad_usage_exits_2(crossing, tmp_path, capsys, args, needle):
    out = tmp_path / "x.h5"
    code = main(["track", str(crossing), *args, "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and needle in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_track_refuses_to_replace_its_input(crossing, tmp_path, capsys):
    # -o naming the input replaced the sequence with the result.
    seq = tmp_path / "in.h5"
    seq.write_bytes(crossing.read_bytes())
    for out in (seq, tmp_path / "." / "in.h5"):
        code = main(["track", str(seq), "--tracker", "kalman", "-o", str(out)])
        err = capsys.readouterr().err
        assert code == 2 and len(err.strip().splitlines()) == 1, err
        assert "would replace the input" in err
    assert seq.read_bytes() == crossing.read_bytes()
