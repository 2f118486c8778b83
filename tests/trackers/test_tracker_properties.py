"""Properties every tracker must have, checked on scenes drawn by ``scenegen.testing.strategies``.

For each name in ``trackers.names()``:

- the same seed gives the same output (boxes and extras, bit for bit);
- a scene shifted by whole pixels, away from the borders, shifts the estimates by the
  same amount: within ``DETERMINISTIC_ATOL`` = 1e-6 px (floating-point rounding only)
  for deterministic trackers, and within ``SAMPLER_ATOL`` = 3 px for samplers. Samplers
  draw the same random numbers in both scenes, and the pure particle filters come out
  exact too; kams and hybrid run mean shift from every particle, whose stopping test and
  step halving compare quantities that rounding can tip differently in the two scenes
  (a particle then stops one step apart, and resampling compounds it), and a few of their
  widest proposals reach the border: 2.5-5 % of examples deviate, by up to 2.2 px in 80
  examples per tracker. "Away from the borders" means ``SHIFT_MARGIN`` = 64 px, over
  5 sigma of the widest proposal (12 px), since particles are kept inside the frame;
  kams, whose first layer spreads 30 px by default, runs this test with 12 px
  (``SHIFT_PARAMS``);
- particle weights (``tracker.weights``, where a tracker exposes them) and the
  probability vectors in the extras (``order_prob``, ``mixture_weights``) are finite,
  non-negative and sum to 1 after every step;
- estimates are finite, with positive sizes and centres inside the frame;
- no tracker raises on any drawn scene: entities leaving and entering the frame, total
  occlusion, distractors, 1-pixel objects, clutter everywhere, noise; nor on any initial
  box that the shared validation (``trackers.base.check_boxes``) accepts, however little
  of it overlaps the frame.

Scenes are small (64x48 to 120x90, at most 8 frames; 160x144 to 200x160 for the shift)
and samplers run with 16 particles.
"""

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

import trackers
from scenegen.config import AR2, Appearance, EntitySpec, Motion, SceneConfig
from scenegen.render.plan import generate
from scenegen.testing.strategies import boxes, scene_configs, sequences
from trackers.registry import parameters

NAMES = trackers.names()
SAMPLERS = frozenset({"condensation", "joint-pf", "ps", "dps", "annealed", "hybrid", "kams"})
N_PARTICLES = 16
DETERMINISTIC_ATOL = 1e-6  # pixels
SAMPLER_ATOL = 3.0  # pixels
PROBABILITY_EXTRAS = ("order_prob", "mixture_weights")
SIZE = {"min_width": 64, "max_width": 120, "min_height": 48, "max_height": 90, "max_frames": 8}

anything = sequences(
    scene_configs(
        **SIZE,
        max_entities=4,
        min_size=1,
        occlusion=True,
        clutter=True,
        distractors=True,
        noise=True,
        exits=True,
    )
)
seeds = st.integers(0, 2**32 - 1)


# Proposals within SHIFT_MARGIN / 5 for the shift test (see the module docstring).
SHIFT_PARAMS = {"kams": {"sigma": 12.0}}


def _make(name, seed, **extra):
    params = {"n_particles": N_PARTICLES} if "n_particles" in parameters(name) else {}
    return trackers.make(name, rng=seed, **params, **extra)


def _init_boxes(seq):
    """Ground-truth boxes (M, 4) of the targets present at frame 0 (as ``scenegen track``)."""
    targets = seq.target_indices()
    targets = targets[seq.gt.present[0, targets]]
    assume(targets.size > 0)
    return np.asarray(seq.gt.box[0, targets], dtype=np.float64)


def _check_probabilities(name, what, p, n_axis=None):
    p = np.asarray(p, dtype=np.float64)
    assert np.all(np.isfinite(p)), f"{name}: {what} not finite: {p}"
    assert np.all(p >= 0), f"{name}: {what} negative: {p.min()}"
    axis = -1 if n_axis is None else n_axis
    sums = p.sum(axis=axis)
    assert np.allclose(sums, 1.0, rtol=0, atol=1e-9), f"{name}: {what} sum to {sums}"


def _run(name, frames, boxes, seed, **params):
    """Step ``name`` over ``frames`` checking weights and estimates after every step.

    Returns the boxes (T, M, 4) and the per-step extras.
    """
    tracker = _make(name, seed, **params)
    tracker.init(frames[0], boxes)
    h, w = frames.shape[1:3]
    out = [np.asarray(boxes, dtype=np.float64)]
    extras = []
    for t in range(1, frames.shape[0]):
        est = tracker.step(frames[t])
        b = np.asarray(est.boxes, dtype=np.float64)
        assert b.shape == boxes.shape, f"{name}: boxes {b.shape} at frame {t}"
        assert np.all(np.isfinite(b)), f"{name}: non-finite estimate at frame {t}: {b}"
        assert np.all(b[:, 2:] > 0), f"{name}: non-positive size at frame {t}: {b}"
        cx, cy = b[:, 0] + b[:, 2] / 2, b[:, 1] + b[:, 3] / 2
        assert np.all((cx >= 0) & (cx <= w) & (cy >= 0) & (cy <= h)), (
            f"{name}: centre outside the {w}x{h} frame at frame {t}: {b}"
        )
        weights = getattr(tracker, "weights", None)
        if weights is not None:
            wt = np.asarray(weights)
            _check_probabilities(name, "weights", wt, wt.shape.index(N_PARTICLES))
        for key in PROBABILITY_EXTRAS:
            if key in est.extras:
                _check_probabilities(name, key, est.extras[key])
        out.append(b)
        extras.append(est.extras)
    return np.stack(out), extras


@pytest.mark.parametrize("name", NAMES)
@settings(max_examples=40)
@given(seq=anything, seed=seeds)
def test_never_raises_and_stays_valid(name, seq, seed):
    """Any drawn scene: no exception; finite, in-frame estimates; normalised weights."""
    _run(name, np.asarray(seq.frames), _init_boxes(seq), seed)


@st.composite
def scenes_and_boxes(draw):
    """A scene and 1-3 initial boxes anywhere that overlap its frame (not ground truth)."""
    seq = draw(sequences(scene_configs(**SIZE, max_entities=2, clutter=True)))
    within = boxes(width=seq.width, height=seq.height, inside=False, max_size=40)
    return seq, np.array(draw(st.lists(within, min_size=1, max_size=3)))


# A box overlapping the top row by 7/16 px: no whole pixel of it lies inside the frame.
_SLIVER = (
    generate(
        SceneConfig(
            width=76,
            height=58,
            n_frames=3,
            entities=(EntitySpec("t", "target", position=(30.0, 30.0)),),
        ),
        seed=0,
    ),
    np.array([[12.0, -7.5, 19.0625, 7.9375]]),
)
@pytest.mark.parametrize("name", NAMES)
@settings(max_examples=15)
@example(case=_SLIVER, seed=0)
@given(case=scenes_and_boxes(), seed=seeds)
def test_accepts_every_box_the_protocol_accepts(name, case, seed):
    seq, init = case
    _run(name, np.asarray(seq.frames), init, seed)


@pytest.mark.parametrize("name", NAMES)
@settings(max_examples=15)
@given(seq=anything, seed=seeds)
def test_same_seed_same_output(name, seq, seed):
    frames, boxes = np.asarray(seq.frames), _init_boxes(seq)
    a, extras_a = _run(name, frames, boxes, seed)
    b, extras_b = _run(name, frames, boxes, seed)
    np.testing.assert_array_equal(a, b)
    for ea, eb in zip(extras_a, extras_b, strict=True):
        assert ea.keys() == eb.keys()
        for key in ea:
            np.testing.assert_array_equal(np.asarray(ea[key]), np.asarray(eb[key]), err_msg=key)


SHIFT_MARGIN = 64
shiftable = scene_configs(
    min_width=160,
    max_width=200,
    min_height=144,
    max_height=160,
    max_frames=8,
    max_entities=3,
    margin=SHIFT_MARGIN,
    max_size=16,
    occlusion=True,
    distractors=True,
)


# Exact ties: two identical 3x3 squares side by side at half-pixel centres. Found by this
# test (meanshift and sok were off by 0.5 and 2.5 px: weighted means in absolute
# coordinates carried rounding onto pixel-centre ties; fixed in 97545c3), kept as an
# explicit example so that every run checks it.
_square = Appearance(size=(3, 3))
_still_x = AR2(boundary="reflect", a1=1.0, a2=0.0, sigma=0.0, margin=SHIFT_MARGIN)
_jitter_y = AR2(boundary="reflect", a1=1.0, a2=0.0, sigma=0.32, margin=SHIFT_MARGIN)
TIES = SceneConfig(
    width=160,
    height=144,
    n_frames=4,
    entities=(
        EntitySpec(name="target1", role="target", appearance=_square, position=(65.5, 65.5)),
        EntitySpec(
            name="target2",
            role="target",
            appearance=_square,
            position=(68.0, 65.5),
            motion=Motion(x=_still_x, y=_jitter_y),
            depth=((0, 1),),
        ),
    ),
)


@pytest.mark.parametrize("name", NAMES)
@settings(max_examples=25)
@example(config=TIES, scene_seed=0, seed=0, dx=0, dy=-3)
@given(
    config=shiftable,
    scene_seed=seeds,
    seed=seeds,
    dx=st.integers(-8, 8),
    dy=st.integers(-8, 8),
)
def test_shift_moves_estimates_by_the_shift(name, config, scene_seed, seed, dx, dy):
    seq = generate(config, seed=scene_seed)
    frames, labels = np.asarray(seq.frames), np.asarray(seq.labels)
    # Uniform background and every entity at least `band` pixels from the border in both
    # scenes: rolling the frames is then exactly the shifted scene.
    band = max(abs(dx), abs(dy)) + 1
    assume(
        not labels[:, :band].any()
        and not labels[:, -band:].any()
        and not labels[:, :, :band].any()
        and not labels[:, :, -band:].any()
    )
    boxes = _init_boxes(seq)
    shifted = np.roll(frames, (dy, dx), axis=(1, 2))
    offset = np.array([dx, dy, 0.0, 0.0])
    params = SHIFT_PARAMS.get(name, {})
    a, _ = _run(name, frames, boxes, seed, **params)
    b, _ = _run(name, shifted, boxes + offset, seed, **params)
    atol = SAMPLER_ATOL if name in SAMPLERS else DETERMINISTIC_ATOL
    np.testing.assert_allclose(b - offset, a, rtol=0, atol=atol)
