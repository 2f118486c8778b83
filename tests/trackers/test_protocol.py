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


@pytest.mark.parametrize("value", ["abc", [1, 2], None, True])
def test_matcher_parameters_of_the_wrong_type_are_named(value):
    # numpy's "ufunc 'isfinite' not supported" named no parameter.
    from trackers.models.layered import check_matcher_params

    with pytest.raises(ValueError, match=r"blur must be in \[0, 20\] pixels, got"):
        check_matcher_params(5, 1, 0.5, "box", value)
