"""Bad parameter values are one ValueError naming the parameter, never an OverflowError,
a MemoryError, numpy's own message or a crash (each case was one of those)."""

from __future__ import annotations

import numpy as np
import pytest

import trackers


@pytest.mark.parametrize(
    ("name", "params", "needle"),
    [
        ("meanshift", {"bins": float("inf")}, "bins must be an integer in [1, 32]"),  # Overflow
        ("meanshift", {"bins": None}, "bins must be an integer in [1, 32]"),
        ("meanshift", {"max_iter": float("nan")}, "max_iter must be an integer in [0, 10000]"),
        ("meanshift", {"eps": "abc"}, "eps must be a finite number >= 0"),
        ("meanshift", {"kernel": [1]}, "unknown kernel [1]"),  # was "unhashable type"
        ("annealed", {"sigma": "abc"}, "sigma must be a number or"),
        ("annealed", {"sigma": np.array([30, 15])}, "(one per layer), got [30, 15]"),  # np.int64
        ("kams", {"n_layers": 10**8}, "n_layers must be an integer in [1, 1000]"),  # 23 s, 1.6 GB
        ("condensation", {"n_parts": 10**12}, "n_parts must be an integer in [1, 256]"),
        # 10**6 was accepted: 880 MB per box histogram.
        ("dps", {"n_parts": 10**6}, "n_parts must be an integer in [1, 256] or None, got 1000000"),
        ("ps", {"model": "rgb", "bins": 256, "n_parts": 2},
         "n_parts=2 with bins=256 makes a 'rgb' histogram of 33554432 bins, more than"),
        ("condensation", {"rng": -1}, "rng must be a numpy Generator, a non-negative int"),
        ("kalman", {"process_std": 1e300}, "process_std must be in [0, 1e+06]"),  # Overflow
        # NaN boxes (a1 was bounded by 100, which still overflowed: see below).
        ("kalman", {"motion": "ar2", "a1": 1e300}, "a1, a2 must not be explosive"),
        ("shm", {"velocity_std": 1e300}, "velocity_std must be in (0, 1e+06]"),
        # Explosive AR2 (the particle trackers' check_ar2): the covariance grew without
        # bound, the boxes ran to the frame's corner, and a1=100 gave NaN boxes at frame 157.
        ("kalman", {"motion": "ar2", "a1": 2.5, "a2": -0.5},
         "a1, a2 must not be explosive (|a2| <= 1 and |a1| <= 1 - a2), got a1=2.5, a2=-0.5"),
        ("kalman", {"motion": "ar2", "a1": 100.0, "a2": 0.0}, "a1, a2 must not be explosive"),
        ("shm", {"motion": "ar2", "a1": 0.0, "a2": -1.5}, "a1, a2 must not be explosive"),
        ("shm-fast", {"motion": "ar2", "a1": -2.5, "a2": -0.5}, "a1, a2 must not be explosive"),
        ("shm-fast", {"motion": "ar2", "a2": float("nan")}, "a2 must be finite, got nan"),
        # R = r_floor + r_gain e overflowed (NaN boxes at the first frame) ...
        ("kalman", {"r_gain": 1e308}, "r_gain must be in [0, 1e+12], got 1e+308"),
        ("shm", {"r_gain": 1e305}, "r_gain must be in [0, 1e+12]"),
        ("shm-fast", {"r_floor": 1e308}, "r_floor must be in [1e-06, 1e+12], got 1e+308"),
        # ... or a subnormal floor made S singular: NaN boxes, LinAlgError in shm-fast.
        ("kalman", {"r_floor": 1e-310}, "r_floor must be in [1e-06, 1e+12], got 1e-310"),
        ("shm-fast", {"r_floor": 5e-324}, "r_floor must be in [1e-06, 1e+12]"),
        # The evidence -lam sum(e / mse scale) overflowed: NaN boxes and order_prob.
        ("shm", {"lam": 1e308}, "lam must be in [0, 1e+06], got 1e+308"),
        ("shm-fast", {"lam": 1e7}, "lam must be in [0, 1e+06]"),
        ("shm", {"mse_floor": 5e-324}, "mse_floor must be finite and >= 1e-06, got 5e-324"),
        # A number written as text was read (lam="30" tracked as 30) where an integer
        # written as text is refused: a typed field takes numbers only.
        ("dps", {"lam": "30"}, "lam must be finite and > 0, got '30'"),
        ("kalman", {"process_std": "1"}, "process_std must be in [0, 1e+06], got '1'"),
        ("annealed", {"alpha": b"0.5"}, "alpha must be in (0, 1), got b'0.5'"),
        # ... and so were the AR2 dynamics and the annealing noise, read with float():
        # a1="2" tracked as 2 (AR2(a1="2") kept the text and failed at its first step).
        ("dps", {"sigma": ("2", "2", "0.001")}, "sigma must be 3 finite non-negative"),
        ("condensation", {"a1": "2"}, "a1 must be finite, got '2'"),
        ("ps", {"a2": b"-1"}, "a2 must be finite, got b'-1'"),
        ("kalman", {"motion": "ar2", "a1": "1.5"}, "a1 must be finite, got '1.5'"),
        ("annealed", {"sigma": "12"}, "sigma must be a number or 3 numbers"),
        ("kams", {"sigma": ("30", "15", "7.5")}, "sigma must be a number or 3 numbers"),
    ],
)
def test_bad_values_name_the_parameter(name, params, needle):
    with pytest.raises(ValueError) as info:
        trackers.make(name, **params)
    assert needle in str(info.value)


@pytest.mark.parametrize("name", ["kalman", "shm", "shm-fast"])
@pytest.mark.parametrize(
    "params",
    [
        # The most explosive accepted AR2s (a double root at -1, a unit root) at the
        # largest noise.
        {"motion": "ar2", "a1": -2.0, "a2": -1.0, "process_std": 1e6, "velocity_std": 1e6},
        {"motion": "ar2", "a1": 0.0, "a2": 1.0, "process_std": 1e6},
        # The smallest floors with nothing else in the noise (a subnormal r_floor gave NaN
        # boxes at the second frame; a subnormal mse_floor NaN boxes after an exact match).
        {"r_floor": 1e-6, "r_gain": 0.0, "process_std": 0.0, "mse_floor": 1e-6, "lam": 1e6},
        {"r_floor": 1e12, "r_gain": 1e12, "mse_floor": 1e-6, "lam": 0.0},
    ],
)
def test_accepted_extremes_stay_finite(name, params):
    import warnings

    rng = np.random.default_rng(0)
    frame = rng.integers(0, 256, (80, 120, 3), dtype=np.uint8)
    boxes = np.array([[20.0, 20.0, 24.0, 24.0], [70.0, 30.0, 20.0, 20.0]])
    valid = trackers.registry.parameters(name)
    tracker = trackers.make(name, **{k: v for k, v in params.items() if k in valid})
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow or invalid value on the way
        tracker.init(frame, boxes)
        for t in range(60):
            f = frame
            if t >= 3:  # exact matches first, then a slight change (e > 0 after e = 0)
                f = frame.copy()
                f[21:44, 20:44] = np.roll(frame[21:44, 20:44], t % 3, axis=1)
            est = tracker.step(f)
            assert np.all(np.isfinite(est.boxes)), (t, est.boxes)
            assert np.all(np.isfinite(est.extras.get("order_prob", 0.0))), t


def test_integral_floats_are_integers_for_the_matcher_too():
    # search_radius=12.0 was refused though every other integer field takes it.
    t = trackers.make("kalman", search_radius=12.0, step=2.0)
    assert t.params.search_radius == 12 and isinstance(t.params.search_radius, int)


@pytest.mark.parametrize(
    ("params", "needle"),
    [
        ({"featureSetNumFeatures": 0}, "featureSetNumFeatures must be in (0, 25000]"),  # SIGSEGV
        ({"featureSetNumFeatures": -3}, "featureSetNumFeatures must be in (0, 25000]"),
        ({"samplerSearchWinSize": float("nan")}, "samplerSearchWinSize must be a finite"),
        ({"samplerSearchWinSize": 1e30}, "samplerSearchWinSize must be in (0, 2500]"),
    ],
)
def test_opencv_parameters_that_would_crash_it_are_refused(params, needle):
    from trackers.adapters import opencv

    with pytest.raises(ValueError) as info:
        opencv("MIL", rng=0, **params)
    assert needle in str(info.value)


@pytest.mark.parametrize(
    ("params", "needle"),
    [
        # init failed for 17 seeds in 30 (cv2's "!negSamples.empty()"), 3 in 30 with 3.
        ({"samplerInitMaxNegNum": 1}, "cv2.TrackerMIL parameter samplerInitMaxNegNum=1 gives "
                                      "init 0.76 negative samples on average (with "
                                      "samplerSearchWinSize=25, samplerInitInRadius=3), so "
                                      "init fails for some seeds: it must be >= 27"),
        ({"samplerInitMaxNegNum": 26}, "samplerInitMaxNegNum=26 gives init 19.8"),
        # Fewer window positions: the default 65 is too few.
        ({"samplerSearchWinSize": 3.0}, "samplerInitMaxNegNum=65 gives init 15.4 negative"),
        # No position at all between the radii: init failed for every seed.
        ({"samplerInitInRadius": 40.0}, "samplerSearchWinSize=25, samplerInitInRadius=40 "
                                        "leave init no negative samples"),
        ({"samplerSearchWinSize": 2.0}, "leave init no negative samples"),
        ({"samplerInitMaxNegNum": 40.5}, "samplerInitMaxNegNum must be an integer, got 40.5"),
    ],
)
def test_mil_parameters_whose_init_depends_on_the_seed_are_refused(params, needle):
    from trackers.adapters import opencv

    with pytest.raises(ValueError) as info:
        opencv("MIL", rng=0, **params)
    assert needle in str(info.value) and "\n" not in str(info.value)


def test_mil_parameters_just_accepted_start_for_every_seed():
    from trackers.adapters import opencv

    frame = np.random.default_rng(0).integers(0, 256, (120, 160, 3), dtype=np.uint8)
    for seed in range(20):
        # 65.0 (as --param may give it) was cv2's "required to be an integer".
        for params in ({"samplerInitMaxNegNum": 27}, {"samplerSearchWinSize": 3.0,
                                                       "samplerInitMaxNegNum": 85.0}):
            t = opencv("MIL", rng=seed, **params)
            t.init(frame, [[60.0, 40.0, 30.0, 30.0]])
            assert t.step(frame).boxes.shape == (1, 4)


def test_an_opencv_tracker_that_cannot_start_is_one_line(monkeypatch):
    # cv2's init raised its multi-line cv2.error (here: made to, whatever cv2's version).
    import cv2

    from trackers.adapters import opencv

    class Refuses:
        def init(self, frame, box):
            raise cv2.error("OpenCV(5.0.0) matrix.cpp:1226: error: (-215:Assertion failed)\nmore")

    frame = np.zeros((60, 80, 3), np.uint8)
    t = opencv("MIL", rng=0)
    monkeypatch.setattr(t, "_make", lambda: Refuses())
    with pytest.raises(ValueError, match=r"cv2.TrackerMIL could not start on box") as info:
        t.init(frame, [[30, 20, 20, 20]])
    assert "\n" not in str(info.value)


def test_an_opencv_failure_at_init_names_the_params_given(monkeypatch):
    # MIL with samplerInitMaxNegNum=1 failed at init naming no parameter, and the cv2 path
    # pushed the reason past the 200 characters a tracker's failure line keeps.
    import cv2

    from trackers.adapters import opencv

    class Refuses:
        def init(self, frame, box):
            raise cv2.error("OpenCV(5.0.0) /io/opencv/modules/video/src/tracking/tracker_mil"
                            ".cpp:81: error: (-215:Assertion failed) !negSamples.empty() in "
                            "function 'init'\n")  # fmt: skip

    # (samplerInitMaxNegNum=1 itself is now refused at construction: check_mil.)
    t = opencv("MIL", rng=0, samplerInitMaxNegNum=40)
    monkeypatch.setattr(t, "_make", lambda: Refuses())
    with pytest.raises(ValueError) as info:
        t.init(np.zeros((60, 80, 3), np.uint8), [[30, 20, 20, 20]])
    assert str(info.value) == (
        "cv2.TrackerMIL with params samplerInitMaxNegNum=40 could not start on box "
        "(30, 20, 20, 20): (-215:Assertion failed) !negSamples.empty() in function 'init'"
    )


def test_an_opencv_failure_at_construction_names_the_params_given(monkeypatch):
    import importlib

    import cv2

    module = importlib.import_module("trackers.adapters.opencv")

    class Refuses:
        @staticmethod
        def create(params=None):
            raise cv2.error("OpenCV(5.0.0) x.cpp:1: error: (-2:Unspecified error) no model")

    monkeypatch.setattr(module, "_lookup", lambda name: (Refuses, cv2.TrackerMIL_Params))
    with pytest.raises(ValueError) as info:
        module.opencv("MIL", samplerSearchWinSize=30.0)
    assert str(info.value) == (
        "cv2.TrackerMIL with params samplerSearchWinSize=30.0: (-2:Unspecified error) no model"
    )


@pytest.mark.parametrize("dtype", [np.uint16, np.float32, bool])
def test_frames_that_are_not_uint8_are_refused_not_converted(dtype):
    # A 16-bit frame was clipped to 0/255, a float one rescaled by its own maximum.
    t = trackers.make("meanshift")
    frame = np.zeros((40, 40, 3), dtype=dtype)
    with pytest.raises(ValueError, match=f"frame must be uint8 RGB, got dtype {np.dtype(dtype)}"):
        t.init(frame, [[10, 10, 8, 8]])


def test_an_opencv_init_refused_on_a_later_box_leaves_it_uninitialised(monkeypatch):
    # The cv2 trackers of the boxes before the refused one were kept, and step returned
    # fewer rows than init's boxes.
    import cv2

    from trackers.adapters import opencv

    class Still:
        def __init__(self, ok):
            self.ok = ok

        def init(self, frame, box):
            if not self.ok:
                raise cv2.error("OpenCV(5.0.0) x.cpp:1: error: (-215:Assertion failed) no")

        def update(self, frame):
            return True, (1, 1, 8, 8)

    made = iter([True, False])
    t = opencv("MIL", rng=0)
    monkeypatch.setattr(t, "_make", lambda: Still(next(made)))
    frame = np.zeros((60, 80, 3), np.uint8)
    with pytest.raises(ValueError, match="could not start on box"):
        t.init(frame, [[30, 20, 20, 20], [5, 5, 20, 20]])
    with pytest.raises(ValueError, match=r"call init\(\) before step\(\)"):
        t.step(frame)


def test_an_opencv_init_refused_by_the_box_check_leaves_it_uninitialised(monkeypatch):
    # A box outside the frame was refused before the adapter unset its trackers: step
    # went on with the previous init's.
    from trackers.adapters import opencv

    class Still:
        def init(self, frame, box):
            pass

        def update(self, frame):
            return True, (1, 1, 8, 8)

    t = opencv("MIL", rng=0)
    monkeypatch.setattr(t, "_make", Still)
    frame = np.zeros((60, 80, 3), np.uint8)
    t.init(frame, [[30, 20, 20, 20]])
    assert t.step(frame).boxes.shape == (1, 4)
    with pytest.raises(ValueError):
        t.init(frame, [[500, 500, 20, 20]])
    with pytest.raises(ValueError, match=r"call init\(\) before step\(\)"):
        t.step(frame)
