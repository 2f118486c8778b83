"""Condensation, joint PF, PS and DPS: reductions, tracking, impoverishment, bad input."""

import dataclasses

import numpy as np
import pytest

import trackers
from scenegen.config import AR2, Motion
from scenegen.presets import get
from scenegen.render.plan import generate
from trackers.particle import (
    Condensation,
    DistributedPartitionedSampling,
    PartitionedSampling,
    circular_shift,
)

PF_NAMES = ("condensation", "joint-pf", "ps", "dps")
COLOURS = [((220, 40, 40), (40, 60, 200)), ((30, 160, 60), (250, 220, 60)),
           ((200, 40, 200), (90, 230, 230)), ((250, 140, 0), (20, 20, 20))]


def _scene(n_objects, n_frames=6, seed=0):
    """Two-colour 20x20 squares moving ~1.5 px/frame on noise; frames and true boxes."""
    rng = np.random.default_rng(seed)
    h, w = 90, 120
    start = np.array([[15.0, 15.0], [70.0, 20.0], [20.0, 55.0], [75.0, 60.0]])[:n_objects]
    vel = rng.uniform(-1.5, 1.5, (n_objects, 2))
    frames, boxes = [], []
    for t in range(n_frames):
        f = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
        pos = np.round(start + t * vel)
        for k, (x, y) in enumerate(pos.astype(int)):
            f[y:y + 10, x:x + 20] = COLOURS[k][0]
            f[y + 10:y + 20, x:x + 20] = COLOURS[k][1]
        frames.append(f)
        boxes.append(np.column_stack([pos, np.full((n_objects, 2), 20.0)]))
    return np.stack(frames), np.stack(boxes)


def _run(tracker, frames, boxes):
    tracker.init(frames[0], boxes[0])
    out = []
    for f in frames[1:]:
        est = tracker.step(f)
        out.append((est.boxes.copy(), tracker.particles.copy(), np.array(tracker.weights),
                    {k: np.array(v) for k, v in est.extras.items()}))
    return out


def _assert_same_runs(a, b):
    for (ba, pa, wa, _), (bb, pb, wb, _) in zip(a, b, strict=True):
        np.testing.assert_array_equal(ba, bb)
        np.testing.assert_array_equal(pa, pb)
        np.testing.assert_array_equal(np.ravel(wa), np.ravel(wb))


@pytest.mark.parametrize("resampler", ["systematic", "residual"])
def test_ps_with_one_object_is_condensation(resampler):
    frames, boxes = _scene(1)
    a = _run(PartitionedSampling(n_particles=80, rng=5, resampler=resampler), frames, boxes)
    b = _run(Condensation(n_particles=80, rng=5, resampler=resampler), frames, boxes)
    _assert_same_runs(a, b)


def test_dps_with_one_group_is_ps():
    frames, boxes = _scene(3)
    a = _run(DistributedPartitionedSampling(n_groups=1, n_particles=90, rng=3), frames, boxes)
    b = _run(PartitionedSampling(ordering=0, n_particles=90, rng=3), frames, boxes)
    _assert_same_runs(a, b)


@pytest.mark.parametrize("tracker", [PartitionedSampling, DistributedPartitionedSampling])
def test_the_stage_layout_is_built_once_and_rebuilt_for_other_arrays(tracker):
    """PS and DPS pass the same group sizes and orderings every step: the stage layout
    built at the first step is the one every later step uses, and another pair of arrays
    (equal or not) gets a layout of its own, built from them."""
    frames, boxes = _scene(3)
    t = tracker(n_particles=90, rng=3)
    t.init(frames[0], boxes[0])
    t.step(frames[1])
    sizes, orderings, layout = t._kept_layout
    for f in frames[2:]:
        t.step(f)
        assert t._kept_layout[2] is layout
    objects, starts, rows = layout
    group = np.repeat(np.arange(sizes.size), sizes)
    assert np.array_equal(objects, orderings[group].T)
    assert np.array_equal(starts, np.cumsum(sizes) - sizes)
    assert np.array_equal(rows, np.arange(90))
    for other_sizes, other_orderings in ((sizes.copy(), orderings),
                                         (sizes, orderings.copy()),
                                         (np.array([40, 50]), orderings[[0, 0]][:, ::-1])):
        again = t._layout(other_sizes, other_orderings)
        assert again[0] is not objects and t._kept_layout[2] is again
        group = np.repeat(np.arange(other_sizes.size), other_sizes)
        assert np.array_equal(again[0], other_orderings[group].T)
        assert np.array_equal(again[1], np.cumsum(other_sizes) - other_sizes)


def test_circular_shift_ordering_equals_explicit_permutation():
    frames, boxes = _scene(3)
    a = _run(PartitionedSampling(ordering=2, n_particles=60, rng=1), frames, boxes)
    b = _run(PartitionedSampling(ordering=(2, 0, 1), n_particles=60, rng=1), frames, boxes)
    _assert_same_runs(a, b)
    np.testing.assert_array_equal(circular_shift(4, 1), [1, 2, 3, 0])


@pytest.mark.parametrize("name", PF_NAMES)
def test_same_seed_same_track_and_exposed_state(name):
    frames, boxes = _scene(3)
    a = _run(trackers.make(name, n_particles=60, rng=11), frames, boxes)
    b = _run(trackers.make(name, n_particles=60, rng=11), frames, boxes)
    c = _run(trackers.make(name, n_particles=60, rng=12), frames, boxes)
    _assert_same_runs(a, b)
    assert not np.array_equal(a[-1][1], c[-1][1])
    box, particles, weights, extras = a[-1]
    assert box.shape == (3, 4) and particles.shape == (60, 3, 3)
    assert weights.shape == ((60, 3) if name == "condensation" else (60,))
    np.testing.assert_allclose(weights.sum(axis=0), 1.0)
    assert extras["uniqueness"].shape == (3,) and extras["effective_dynamics"].shape == (3,)
    assert np.all((extras["uniqueness"] > 0) & (extras["uniqueness"] <= 1))
    if name == "dps":
        assert extras["mixture_weights"].shape == (3,)
        np.testing.assert_allclose(extras["mixture_weights"].sum(), 1.0)


def _iou(a, b):
    x0 = np.maximum(a[..., 0], b[..., 0])
    y0 = np.maximum(a[..., 1], b[..., 1])
    x1 = np.minimum(a[..., 0] + a[..., 2], b[..., 0] + b[..., 2])
    y1 = np.minimum(a[..., 1] + a[..., 3], b[..., 1] + b[..., 3])
    inter = np.clip(x1 - x0, 0, None) * np.clip(y1 - y0, 0, None)
    return inter / (a[..., 2] * a[..., 3] + b[..., 2] * b[..., 3] - inter)


def _easy_config(n_objects, n_frames):
    """DPS synthetic targets only (no distractor, no clutter), moving gently."""
    cfg = get("dps-synthetic")
    walk = AR2(boundary="reflect", a1=1.5, a2=-0.5, sigma=1.5, margin=2.0)
    targets = [dataclasses.replace(e, motion=Motion(x=walk, y=walk))
               for e in cfg.entities if e.role == "target"][:n_objects]
    return dataclasses.replace(cfg, entities=tuple(targets), n_frames=n_frames)


@pytest.fixture(scope="module")
def easy_scenes():
    out = []
    for seed in (0, 1):
        seq = generate(_easy_config(2, 20), seed=seed)
        out.append((np.asarray(seq.frames), seq.init_boxes(0),
                    np.asarray(seq.gt.box)[:, seq.target_indices()]))
    return out


@pytest.mark.parametrize("name", PF_NAMES)
def test_tracks_easy_generated_scenes(name, easy_scenes):
    for i, (frames, init, gt) in enumerate(easy_scenes):
        result = trackers.track(trackers.make(name, n_particles=300, rng=i), frames, init)
        iou = _iou(result.boxes[1:], gt[1:])
        assert np.mean(iou >= 0.5) >= 0.95, (name, i, np.round(iou, 2))


def test_ps_impoverishes_early_objects():
    """DPS §3.3: the first object of a PS ordering goes through every weighted-resampling
    stage and keeps the fewest distinct values; the last keeps them all."""
    seq = generate(_easy_config(3, 12), seed=2)
    for ordering, (first, last) in ((0, (0, 2)), (1, (1, 0))):
        result = trackers.track(trackers.make("ps", ordering=ordering, n_particles=200, rng=4),
                                np.asarray(seq.frames), seq.init_boxes(0))
        u = result.extras["uniqueness"][1:].mean(axis=0)
        assert u[first] < u[last], (ordering, u)
    # DPS shares the burden: no object as impoverished as PS's first.
    result = trackers.track(trackers.make("dps", n_particles=201, rng=4),
                            np.asarray(seq.frames), seq.init_boxes(0))
    assert result.extras["uniqueness"][1:].mean(axis=0).min() > u[1]


@pytest.mark.parametrize("name", PF_NAMES)
def test_bad_boxes_and_frames_raise(name):
    frames, boxes = _scene(2)
    with pytest.raises(ValueError, match="outside"):
        trackers.make(name, n_particles=20).init(frames[0], [[500.0, 5.0, 10.0, 10.0]])
    with pytest.raises(ValueError, match="zero or negative size"):
        trackers.make(name, n_particles=20).init(frames[0], [[5.0, 5.0, 0.0, 10.0]])
    tracker = trackers.make(name, n_particles=20, rng=0)
    tracker.init(frames[0], boxes[0])
    with pytest.raises(ValueError, match="shape changed"):
        tracker.step(frames[1][:50])


@pytest.mark.parametrize("name, params, match", [
    ("particle", {}, "unknown tracker 'particle'; valid trackers: condensation"),
    ("ps", {"orderings": 1}, "unknown parameter 'orderings' for tracker 'ps'; valid: .*ordering"),
    ("dps", {"n_groups": 0}, "n_groups"),
    ("dps", {"assignment": "greedy"},
     "unknown assignment 'greedy'; valid: random, interleaved, persistent"),
    ("dps", {"mixture": "equal"}, "unknown mixture 'equal'; valid: evidence, prior"),
    ("ps", {"weighting": "joint"}, "unknown weighting 'joint'; valid: stage, placed, g-only"),
    ("dps", {"resample_scope": "all"}, "unknown resample_scope 'all'; valid: joint, placed"),
    ("joint-pf", {"weighting": "stage"}, "unknown parameter 'weighting' for tracker 'joint-pf'"),
    ("joint-pf", {"n_particles": 0}, "n_particles"),
    ("condensation", {"resampler": "best"}, "unknown resampler 'best'"),
    ("ps", {"model": "lab"}, "unknown observation model 'lab'"),
    ("ps", {"ordering": "first"}, "ordering"),
    ("joint-pf", {"sigma": (1.0, 1.0)}, "sigma"),
])
def test_bad_parameters_raise(name, params, match):
    with pytest.raises(ValueError, match=match):
        trackers.make(name, **params)


@pytest.mark.parametrize("name", PF_NAMES)
@pytest.mark.parametrize("params, match", [
    # Each failed in the first steps with "boxes must be finite with positive width and
    # height" (or overflow warnings), naming no parameter.
    ({"a1": 1e200}, r"^a1, a2 must not be explosive \(\|a2\| <= 1 and \|a1\| <= 1 - a2\), "
                    r"got a1=1e\+200, a2=-1 \(a root"),
    ({"a2": -50}, r"got a1=2, a2=-50 \(a root of z\^2 - a1 z - a2 has modulus 7.07\)$"),
    ({"a1": 3, "a2": -1}, "a1, a2 must not be explosive .* modulus 2.62"),
    ({"a1": 0.5, "a2": 1.0}, "a1, a2 must not be explosive"),
    ({"sigma": (1e300, 1e300, 1e300)},
     r"^sigma must be \(u, v, a\) with u, v <= 1e\+09 px and a <= 20.7, got \(1e\+300"),
    ({"sigma": (2.0, 2.0, 1000.0)}, "sigma must be .* a <= 20.7, got .*1000.0"),
    ({"sigma": (2.0, 2e9, 0.0)}, "sigma must be .* u, v <= 1e"),
    ({"sigma": (True, 1.0, 0.0)}, "sigma must be 3 finite non-negative numbers"),  # was 1 px
    ({"sigma": "abc"}, "sigma must be 3 finite non-negative numbers"),
    ({"a1": "x"}, "a1 must be finite, got 'x'"),
    ({"a2": True}, "a2 must be finite, got True"),
])
def test_dynamics_that_leave_the_box_range_are_refused_naming_the_parameter(name, params,
                                                                           match):
    with pytest.raises(ValueError, match=match) as info:
        trackers.make(name, **params)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("name", PF_NAMES)
@pytest.mark.parametrize("params", [
    {"a1": 2.0, "a2": -1.0},            # constant velocity: a double root at 1
    {"a1": 1.0, "a2": 0.0},             # random walk
    {"a1": -2.0, "a2": -1.0},           # a double root at -1
    {"a1": 0.0, "a2": 1.0},             # roots +-1
    {"a1": 1.6, "a2": -0.64},           # damped
    {"sigma": (1e9, 1e9, 20.7)},        # the largest noise
    {"sigma": (0.0, 0.0, 0.0)},
])
def test_dynamics_on_the_boundary_are_accepted_and_stay_finite(name, params):
    frames, boxes = _scene(2, n_frames=8)
    tracker = trackers.make(name, n_particles=40, rng=3, **params)
    tracker.init(frames[0], boxes[0])
    for f in frames[1:]:
        est = tracker.step(f)
        assert np.all(np.isfinite(est.boxes))
        # sigma 0 gave NaN: 0 / 0 (the set never spreads in a coordinate without noise).
        assert np.all(np.isfinite(est.extras["effective_dynamics"]))


@pytest.mark.parametrize("rng", [0, None, np.random.RandomState(0)])
def test_dynamics_draw_from_a_generator_only(rng):
    # A seed was "'int' object has no attribute 'standard_normal'" (AttributeError); a
    # seed turned into a Generator at every call would repeat the same draws.
    from trackers.models.dynamics import AR2 as Dynamics

    x = np.zeros((4, 2, 3))
    with pytest.raises(ValueError, match="rng must be a numpy Generator"):
        Dynamics().propagate(x, x, np.zeros(3), rng=rng)


def test_effective_dynamics_without_noise_is_one():
    frames, boxes = _scene(2)
    tracker = trackers.make("ps", n_particles=30, sigma=(0.0, 2.0, 0.0), rng=0)
    tracker.init(frames[0], boxes[0])
    est = tracker.step(frames[1])
    want = (1.0 + tracker.particles[:, :, 1].var(axis=0) / 4.0) / 2
    np.testing.assert_allclose(est.extras["effective_dynamics"], want, rtol=1e-12)
    est = trackers.make("dps", n_particles=30, sigma=(0.0, 0.0, 0.0), rng=0)
    est.init(frames[0], boxes[0])
    assert est.step(frames[1]).extras["effective_dynamics"].tolist() == [1.0, 1.0]


@pytest.mark.parametrize("tracker, match", [
    (PartitionedSampling(ordering=3), r"ordering \(circular shift\) must lie in \[0, 2\)"),
    (PartitionedSampling(ordering=(0, 0)), "not a permutation"),
    (DistributedPartitionedSampling(n_particles=1), "exceeds n_particles = 1"),
])
def test_bad_ordering_or_groups_for_the_targets_raise(tracker, match):
    frames, boxes = _scene(2)
    with pytest.raises(ValueError, match=match):
        tracker.init(frames[0], boxes[0])


def test_interleaved_assignment_tracks():
    frames, boxes = _scene(3)
    runs = _run(DistributedPartitionedSampling(assignment="interleaved", n_particles=61, rng=2),
                frames, boxes)
    for (box, _, _, extras), truth in zip(runs, boxes[1:], strict=True):
        np.testing.assert_allclose(extras["mixture_weights"].sum(), 1.0)
        assert np.all(_iou(box, truth) > 0.5)


def test_mixture_reassembly_weights_groups_by_size_and_evidence():
    """§3.4: π_c ∝ (N_c / N) Σ_{n∈c} w̃_n, with w̃ relative to normalised π' in the group."""
    sizes = np.array([3, 2])
    logpi = np.log(np.array([1.0, 1.0, 2.0, 5.0, 5.0]))  # unnormalised π' per group
    lik = np.array([0.5, 1.0, 2.0, 3.0, 1.0])
    weights, mixture, log_mixture = DistributedPartitionedSampling._reassemble(
        logpi + np.log(lik), logpi, sizes)
    pi = np.exp(logpi)
    ev = np.array([np.sum(pi[:3] * lik[:3]) / pi[:3].sum(),
                   np.sum(pi[3:] * lik[3:]) / pi[3:].sum()])
    expected_mix = sizes / 5 * ev / np.sum(sizes / 5 * ev)
    np.testing.assert_allclose(mixture, expected_mix)
    w = pi * lik
    expected = np.concatenate([expected_mix[0] * w[:3] / w[:3].sum(),
                               expected_mix[1] * w[3:] / w[3:].sum()])
    np.testing.assert_allclose(weights, expected)
    np.testing.assert_allclose(np.exp(log_mixture), mixture)
    # Components that keep their particles carry their mixture weight: π_c,t ∝ π_c,t−1 ×
    # evidence_c, here with π_c,t−1 = (0.9, 0.1) instead of the sizes' (0.6, 0.4); a
    # component whose prior weight underflows stays finite in log and weighs nothing.
    prior = np.log([0.9, 0.1])
    weights, mixture, log_mixture = DistributedPartitionedSampling._reassemble(
        logpi + np.log(lik), logpi, sizes, prior)
    np.testing.assert_allclose(mixture, [0.9, 0.1] * ev / np.sum([0.9, 0.1] * ev))
    _, mixture, log_mixture = DistributedPartitionedSampling._reassemble(
        logpi + np.log(lik), logpi, sizes, np.array([0.0, -2000.0]))
    assert mixture[1] == 0.0 and np.isfinite(log_mixture).all()
    assert log_mixture[1] == pytest.approx(-2000.0 + np.log(ev[1] / ev[0]))
    # One group: plain normalisation, mixture (1,) and log mixture (0,).
    weights, mixture, log_mixture = DistributedPartitionedSampling._reassemble(
        np.log(lik), np.zeros(5), np.array([5]))
    np.testing.assert_allclose(weights, lik / lik.sum())
    assert mixture.tolist() == [1.0] and log_mixture.tolist() == [0.0]


def test_prior_mixture_keeps_each_groups_share_whatever_its_evidence():
    """``mixture="prior"``: π_c,t = π_c,t−1; inside a group the weights are π' p, normalised."""
    sizes = np.array([3, 2])
    logpi = np.log(np.array([1.0, 1.0, 2.0, 5.0, 5.0]))
    lik = np.array([0.5, 1.0, 2.0, 1e-6, 3e-6])  # group 2's evidence is a millionth
    w = np.exp(logpi) * lik
    for prior, share in ((None, sizes / 5), (np.log([0.9, 0.1]), np.array([0.9, 0.1]))):
        weights, mixture, log_mixture = DistributedPartitionedSampling._reassemble(
            logpi + np.log(lik), logpi, sizes, prior, evidence=False)
        np.testing.assert_allclose(mixture, share)
        np.testing.assert_allclose(np.exp(log_mixture), share)
        np.testing.assert_allclose(weights, np.concatenate(
            [share[0] * w[:3] / w[:3].sum(), share[1] * w[3:] / w[3:].sum()]))
    # With the evidence the second group weighs next to nothing.
    _, mixture, _ = DistributedPartitionedSampling._reassemble(logpi + np.log(lik), logpi,
                                                               sizes)
    assert mixture[1] < 1e-5


@pytest.mark.parametrize("mixture", ["evidence", "prior"])
def test_dps_reports_the_mixture_weights_its_rule_gives(mixture):
    frames, boxes = _scene(3)
    runs = _run(DistributedPartitionedSampling(mixture=mixture, n_particles=61, rng=2),
                frames, boxes)
    sizes = np.array([21, 20, 20]) / 61
    for (box, _, _, extras), truth in zip(runs, boxes[1:], strict=True):
        assert np.all(_iou(box, truth) > 0.5)
        if mixture == "prior":
            np.testing.assert_allclose(extras["mixture_weights"], sizes)
        else:
            assert not np.allclose(extras["mixture_weights"], sizes)


@pytest.mark.parametrize("assignment, kept", [("persistent", True), ("random", False)])
def test_persistent_components_keep_their_particles(assignment, kept):
    """With ``assignment="persistent"`` every particle of component c moves from an
    ancestor of component c at the end of the previous step; with "random" they mix."""
    frames, boxes = _scene(3)
    tr = DistributedPartitionedSampling(assignment=assignment, n_particles=60, rng=5)
    moved: list = []
    tr.propagation_hook = lambda before, after, objects: moved.append((before, objects))
    tr.init(frames[0], boxes[0])
    sizes = tr._sizes_c
    group = np.repeat(np.arange(sizes.size), sizes)
    inside = []
    for t, frame in enumerate(frames[1:]):
        old = tr.particles.copy()
        moved.clear()
        est = tr.step(frame)
        np.testing.assert_allclose(est.extras["mixture_weights"].sum(), 1.0)
        if t == 0:
            continue
        before, objects = moved[0]  # stage 0: ancestors as they were at the end of t − 1
        for r in range(before.shape[0]):
            own = old[group == group[r], objects[r]]
            inside.append(bool((own == before[r]).all(axis=1).any()))
    assert all(inside) if kept else not all(inside)
