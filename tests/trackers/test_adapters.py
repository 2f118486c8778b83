"""trackers.adapters.opencv: cv2 trackers behind the protocol, one per target."""

from __future__ import annotations

import numpy as np
import pytest

import trackers
from trackers.adapters import opencv, opencv_names

cv2 = pytest.importorskip("cv2")


def _scene(n=6, shift=2):
    frames = np.full((n, 48, 64, 3), 255, dtype=np.uint8)
    for t in range(n):
        x = 10 + shift * t
        frames[t, 15:27, x : x + 12] = (200, 30, 30)
        frames[t, 15:21, x : x + 6] = (30, 30, 200)
    return frames


def test_every_listed_opencv_tracker_constructs_and_tracks():
    assert "MIL" in opencv_names()
    for name in opencv_names():
        t = opencv(name, rng=0)
        assert isinstance(t, trackers.Tracker) and t.deterministic is False
        out = trackers.track(t, _scene(), [[10, 15, 12, 12], [40, 30, 8, 8]])
        assert out.boxes.shape == (6, 2, 4) and out.extras["ok"].shape == (6, 2)
        ok = out.extras["ok"][1:]
        assert np.all(np.isfinite(out.boxes[1:][ok])) and np.all(np.isnan(out.boxes[1:][~ok]))


def test_small_boxes_are_grown_for_opencv_and_reported_at_their_size():
    # cv2.TrackerMIL never returns on boxes under 5 px; the adapter grows them.
    out = trackers.track(opencv("MIL", rng=0), _scene(3), [[0, 0, 1, 1], [63.5, 47.5, 0.5, 0.5]])
    found = out.extras["ok"][1:]
    np.testing.assert_array_equal(
        out.boxes[1:][found][:, 2:], np.array([[1, 1], [0.5, 0.5]])[np.nonzero(found)[1]]
    )


def test_failure_is_nan():
    class Failing:
        def update(self, frame):
            return False, (0, 0, 0, 0)

    t = opencv("MIL")
    t.init(_scene(1)[0], [[10, 15, 12, 12]])
    t._trackers = [Failing()]
    est = t.step(_scene(1)[0])
    assert np.isnan(est.boxes).all() and not est.extras["ok"][0]


@pytest.mark.parametrize(
    ("name", "kw", "needle"),
    [
        ("KCFX", {}, "unknown OpenCV tracker 'KCFX'"),
        ("MIL", {"bogus": 1}, "unknown parameter 'bogus' for cv2.TrackerMIL; valid: "),
        ("MIL", {"samplerSearchWinSize": "x"}, "samplerSearchWinSize must be a finite number"),
        ("MIL", {"rng": 1.5}, "rng of an OpenCV tracker must be a Generator, an int seed or "
                              "None, not 1.5"),
        ("MIL", {"rng": -(2**31) - 1}, "rng of an OpenCV tracker must be >= -2**31"),
        # The message was three lines: a SeedSequence's repr.
        ("MIL", {"rng": np.random.SeedSequence(0)}, "int seed or None, not SeedSequence"),
    ],
)
def test_bad_construction_names_the_problem(name, kw, needle):
    with pytest.raises(ValueError) as info:
        opencv(name, **kw)
    assert needle in str(info.value) and "\n" not in str(info.value)


def test_params_reach_opencv():
    t = opencv("MIL", samplerSearchWinSize=30.0)
    assert repr(t) == "opencv('MIL', rng=None, samplerSearchWinSize=30.0)"
    out = trackers.track(t, _scene(3), [[10, 15, 12, 12]])
    assert out.boxes.shape == (3, 1, 4)


def test_docstring_example_runs():
    import doctest
    import importlib

    module = importlib.import_module("trackers.adapters.opencv")  # the attribute is the function
    result = doctest.testmod(module)
    assert result.attempted > 0 and result.failed == 0


def test_any_seed_becomes_a_c_int_seed(monkeypatch):
    # A derived 63-bit seed (scenegen benchmark, the experiments) or a Generator reaches
    # cv2.setRNGSeed as a C int; a seed that already is one is passed unchanged.
    import cv2

    from trackers.adapters import cv2_seed

    seen = []
    monkeypatch.setattr(cv2, "setRNGSeed", seen.append)
    for rng in (7, -(2**31), 2**31 - 1, 2**31, 2**63 - 1, np.random.default_rng(5)):
        t = opencv("MIL", rng=rng)
        t.init(_scene(1)[0], [[10, 15, 12, 12]])
    assert seen[:3] == [7, -(2**31), 2**31 - 1]
    assert all(isinstance(s, int) and 0 <= s < 2**31 for s in seen[3:])
    assert seen[3] != seen[4] and seen[3] == cv2_seed(2**31) and seen[5] == cv2_seed(
        np.random.default_rng(5))  # fmt: skip
    assert cv2_seed(None) is None and opencv("MIL").rng is None
