"""trackers.Tracker is a protocol: trackers.track runs anything with init/step."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import trackers
from trackers.base import BaseTracker


class Still:
    """Only init and step; step returns a plain namespace with boxes."""

    def init(self, frame, boxes):
        self.boxes = np.asarray(boxes, dtype=float)

    def step(self, frame):
        return SimpleNamespace(boxes=self.boxes + 1.0)


def _frames(n=4):
    return np.zeros((n, 20, 30, 3), dtype=np.uint8)


def test_protocol_is_runtime_checkable_and_ours_satisfy_it():
    assert isinstance(Still(), trackers.Tracker)
    assert not isinstance(object(), trackers.Tracker)
    for name in trackers.names():
        assert isinstance(trackers.make(name), trackers.Tracker), name
        assert issubclass(trackers.get_class(name), BaseTracker)


def test_track_runs_a_tracker_with_only_init_and_step():
    out = trackers.track(Still(), _frames(), [[2, 3, 5, 6]])
    assert out.boxes.shape == (4, 1, 4) and out.extras == {}
    np.testing.assert_array_equal(out.boxes[:, 0, 0], [2, 3, 3, 3])


@pytest.mark.parametrize(
    ("estimate", "needle"),
    [
        (np.zeros((1, 4)), "which has no .boxes"),
        (SimpleNamespace(boxes=np.zeros((2, 4))), "shape (2, 4), expected (1, 4)"),
        (SimpleNamespace(boxes=np.full((1, 4), np.inf)), "holds inf"),
        (SimpleNamespace(boxes=np.array([[1, 2, np.nan, 4]])), "box 0 is [1.0, 2.0, nan, 4.0]"),
    ],
)
def test_track_names_the_protocol_breach(estimate, needle):
    class Bad(Still):
        def step(self, frame):
            return estimate

    with pytest.raises(ValueError, match="frame 1") as info:
        trackers.track(Bad(), _frames(), [[2, 3, 5, 6]])
    assert needle in str(info.value) and "Bad.step()" in str(info.value)


def test_track_rejects_a_non_tracker_and_bad_boxes():
    with pytest.raises(TypeError, match="no step method"):
        trackers.track(SimpleNamespace(init=lambda f, b: None), _frames(), [[1, 1, 2, 2]])
    with pytest.raises(ValueError, match=r"init_boxes must have shape \(K, 4\)"):
        trackers.track(Still(), _frames(), [[1, 2, 3]])
    # A class has init and step too (isinstance(Still, Tracker) is True): it was run and
    # failed with "Still.init() missing 1 required positional argument: 'boxes'".
    with pytest.raises(TypeError, match=r"Still is a class, not a tracker: pass an instance"):
        trackers.track(Still, _frames(), [[1, 1, 2, 2]])


def test_track_stacks_extras_and_names_a_missing_key():
    class WithExtras(Still):
        def init(self, frame, boxes):
            super().init(frame, boxes)
            self.t = 0

        def step(self, frame):
            self.t += 1
            extras = {"score": np.array([0.5 * self.t])} if self.t < 3 else {}
            return SimpleNamespace(boxes=self.boxes, extras=extras)

    out = trackers.track(WithExtras(), _frames(3), [[2, 3, 5, 6]])
    assert np.isnan(out.extras["score"][0, 0]) and out.extras["score"][2, 0] == 1.0
    with pytest.raises(ValueError, match="extras lacks 'score'"):
        trackers.track(WithExtras(), _frames(4), [[2, 3, 5, 6]])


def test_track_keeps_an_extras_key_first_given_after_frame_1():
    # A key first given at frame 2 was silently dropped (only frame 1's keys were stacked).
    class Late(Still):
        def init(self, frame, boxes):
            super().init(frame, boxes)
            self.t = 0

        def step(self, frame):
            self.t += 1
            extras = {"n": np.array(self.t)} if self.t >= 2 else {}
            if self.t >= 3:
                extras["late"] = np.array([0.5 * self.t])
            return SimpleNamespace(boxes=self.boxes, extras=extras)

    out = trackers.track(Late(), _frames(4), [[2, 3, 5, 6]])
    assert list(out.extras) == ["n", "late"]
    assert out.extras["n"].tolist() == [0, 0, 2, 3]  # an integer key: 0 before
    assert np.isnan(out.extras["late"][:3]).all() and out.extras["late"][3, 0] == 1.5

    class Gone(Late):
        def step(self, frame):
            est = super().step(frame)
            if self.t == 3:
                del est.extras["n"]
            return est

    with pytest.raises(ValueError, match="at frame 3: extras lacks 'n', given at frame 2"):
        trackers.track(Gone(), _frames(4), [[2, 3, 5, 6]])


@pytest.mark.parametrize("value", ["abc", [1, 2], None, True])
def test_matcher_parameters_of_the_wrong_type_are_named(value):
    # numpy's "ufunc 'isfinite' not supported" named no parameter.
    from trackers.models.layered import check_matcher_params

    with pytest.raises(ValueError, match=r"blur must be in \[0, 20\] pixels, got"):
        check_matcher_params(5, 1, 0.5, "box", value)


_FIVE = [[i * 5.0, 2.0, 4.0, 4.0] for i in range(5)]


@pytest.mark.parametrize(
    ("name", "params", "refused"),
    [
        ("shm", {}, _FIVE),  # 5 targets: 120 orderings, refused by _init
        ("shm-fast", {}, _FIVE),
        ("dps", {"n_particles": 3}, _FIVE),  # one group per target > n_particles
        ("ps", {"ordering": (1, 0)}, [[2.0, 3.0, 5.0, 6.0]]),  # not a permutation of 1
        # Refused by the box check before _init: the previous init's state was kept.
        ("condensation", {}, [[500.0, 500.0, 5.0, 5.0]]),  # outside the frame
        ("kalman", {}, [[2.0, 3.0, -5.0, 6.0]]),  # a negative width
        ("meanshift", {}, [[2.0, float("nan"), 5.0, 6.0]]),
    ],
)
def test_an_init_that_fails_leaves_the_tracker_uninitialised(name, params, refused):
    # step after a refused init ran on the previous init's state (SHM: 2 boxes from a
    # tracker whose n_targets said 5) or failed with an IndexError / AttributeError.
    frames = _frames()
    t = trackers.make(name, rng=0, **params)
    with pytest.raises(ValueError):
        t.init(frames[0], refused)
    with pytest.raises(ValueError, match=r"call init\(\) before step\(\)"):
        t.step(frames[1])
    t.init(frames[0], [[2.0, 3.0, 5.0, 6.0], [15.0, 10.0, 6.0, 5.0]])
    assert t.step(frames[1]).boxes.shape == (2, 4)
    with pytest.raises(ValueError):
        t.init(frames[0], refused)
    with pytest.raises(ValueError, match=r"call init\(\) before step\(\)"):
        t.step(frames[2])


@pytest.mark.parametrize("frames", [(f for f in _frames()), iter(_frames()), None, {1, 2}])
def test_track_names_frames_without_a_length(frames):
    # len() said "object of type 'generator' has no len()", naming no argument.
    with pytest.raises(TypeError, match=r"^frames must be an array \(T, H, W, 3\) or a sequence"):
        trackers.track(Still(), frames, [[1, 1, 2, 2]])


@pytest.mark.parametrize(
    ("boxes", "needle"),
    [
        ([["a", 1, 2, 3]], "could not convert string to float: 'a'"),
        ([[1, 2, 3, 4], [1, 2]], "inhomogeneous shape"),
        ({"x": 1}, "got dict"),
    ],
)
def test_boxes_that_are_not_numbers_are_one_error_naming_them(boxes, needle):
    # numpy's own message, naming neither boxes nor init_boxes.
    with pytest.raises(ValueError, match=r"^init_boxes must be numbers \[x, y, w, h\]") as info:
        trackers.track(Still(), _frames(), boxes)
    assert needle in str(info.value) and "\n" not in str(info.value)
    with pytest.raises(ValueError, match=r"^boxes must be numbers \[x, y, w, h\]"):
        trackers.make("meanshift").init(_frames()[0], boxes)


@pytest.mark.parametrize(
    ("name", "box"),
    [("condensation", [0.0, 0.0, 1e308, 1e308]), ("kalman", [0.0, 0.0, 1e20, 1e20]),
     ("meanshift", [-2e9, 5.0, 3e9, 4.0])],
)
def test_a_box_beyond_the_largest_value_is_refused_at_init(name, box):
    # 1e308 passed init and failed at the first step with "boxes must be finite with
    # positive width and height"; 1e20 made the template trackers cast to int64 with
    # undefined results (RuntimeWarning: invalid value encountered in cast).
    t = trackers.make(name, rng=0)
    with pytest.raises(ValueError, match=r"^box 0 .* is too large: .* <= 1e\+09 px$"):
        t.init(_frames()[0], [box])
    t.init(_frames()[0], [[0.0, 0.0, 1e9, 1e9]])  # the largest is accepted and tracked
    assert np.isfinite(t.step(_frames()[1]).boxes).all()
