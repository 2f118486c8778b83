"""The particle filters' pluggable observation model (``observation=``) and its contract."""

import numpy as np
import pytest

import trackers
from trackers.models.observation import ColourModel, ObservationModel, PositionModel

FILTERS = ("condensation", "joint-pf", "ps", "dps")


def _moving(n_frames=8, k=2):
    """True centres (T, K, 2) of K objects moving right, and initial boxes (K, 4)."""
    centres = np.empty((n_frames, k, 2))
    centres[..., 0] = 20.0 + 2.0 * np.arange(n_frames)[:, None]
    centres[..., 1] = 15.0 + 25.0 * np.arange(k)[None, :]
    boxes0 = np.column_stack([centres[0] - 5.0, np.full((k, 2), 10.0)])
    return centres, boxes0


class _Recorder:
    """Wraps an observation model and records how the filter calls it."""

    def __init__(self, inner):
        self.inner, self.calls = inner, []

    def set_references(self, frame, boxes):
        self.calls.append(("set_references", frame.shape, np.shape(boxes)))
        self.inner.set_references(frame, boxes)

    def observe(self, frame):
        self.calls.append(("observe", frame.shape))
        inner = self.inner.observe(frame)
        calls = self.calls

        class _Frame:
            def log_likelihoods(self, boxes, objects):
                calls.append(("ll", boxes.shape, objects.shape, objects.dtype.kind))
                return inner.log_likelihoods(boxes, objects)

        return _Frame()


def test_colour_and_position_models_satisfy_the_protocol():
    assert isinstance(ColourModel("hsv"), ObservationModel)
    z, _ = _moving()
    assert isinstance(PositionModel(z, np.eye(2)), ObservationModel)


@pytest.mark.parametrize("name", FILTERS)
def test_filters_call_the_model_as_documented(name):
    z, boxes0 = _moving(n_frames=4)
    frames = np.zeros((4, 50, 60, 3), np.uint8)
    rec = _Recorder(PositionModel(z, np.eye(2)))
    trackers.track(trackers.make(name, n_particles=20, observation=rec, rng=0), frames, boxes0)
    assert rec.calls[0] == ("set_references", (50, 60, 3), (2, 4))
    assert [c for c in rec.calls if c[0] != "ll"][1:] == [("observe", (50, 60, 3))] * 3
    for call in rec.calls:
        if call[0] == "ll":
            p = call[1][0]
            assert call[1] == (p, 4) and call[2] == (p,) and call[3] == "i"
            assert p in (20, 40)


@pytest.mark.parametrize("name", FILTERS)
def test_a_gaussian_position_likelihood_drives_the_filters(name):
    """Blank frames: the estimate can only come from the plugged-in position model."""
    z, boxes0 = _moving()
    frames = np.zeros((len(z), 50, 60, 3), np.uint8)
    model = PositionModel(z, np.eye(2))
    res = trackers.track(trackers.make(name, n_particles=300, observation=model, rng=1),
                         frames, boxes0)
    centres = res.boxes[..., :2] + res.boxes[..., 2:] / 2
    assert np.abs(centres - z).max() < 2.0
    # The same run with the colour model on blank frames cannot follow the motion.
    colour = trackers.track(trackers.make(name, n_particles=300, rng=1), frames, boxes0)
    assert np.abs(colour.boxes[-1, :, 0] - res.boxes[-1, :, 0]).max() > 4.0


def test_position_model_rejects_bad_input():
    with pytest.raises(ValueError, match=r"measurements must have shape \(T, K, 2\)"):
        PositionModel(np.zeros((3, 2)), np.eye(2))
    with pytest.raises(ValueError, match="positive definite"):
        PositionModel(np.zeros((3, 1, 2)), -np.eye(2))
    model = PositionModel(np.zeros((2, 1, 2)), np.eye(2))
    with pytest.raises(ValueError, match="measurements of 1 objects, init got 2 boxes"):
        model.set_references(np.zeros((5, 5, 3), np.uint8), np.ones((2, 4)))
    model.set_references(np.zeros((5, 5, 3), np.uint8), np.ones((1, 4)))
    model.observe(None)
    with pytest.raises(ValueError, match="frame 2 observed"):
        model.observe(None)


@pytest.mark.parametrize(
    ("objects", "needle"),
    [
        ([0, 2], r"objects must be integers in \[0, 2\) .*got \[0, 2\]"),  # was IndexError
        ([-1, 0], r"got \[-1, 0\]"),  # was read silently from the last object
        ([0.0, 1.0], "got dtype float64"),  # was IndexError
    ],
)
def test_position_model_names_an_object_index_out_of_range(objects, needle):
    model = PositionModel(np.zeros((2, 2, 2)), np.eye(2))
    model.set_references(np.zeros((5, 5, 3), np.uint8), np.ones((2, 4)))
    obs = model.observe(None)
    with pytest.raises(ValueError, match=needle):
        obs.log_likelihoods(np.ones((2, 4)), np.array(objects))
