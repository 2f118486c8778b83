"""Protocol-level behaviour shared by the mean-shift family: meanshift, annealed, hybrid,
sok, kams."""

import numpy as np
import pytest

import trackers

FAMILY = ["meanshift", "annealed", "hybrid", "sok", "kams"]

COLOURS = np.array([(230, 30, 30), (30, 170, 30), (30, 60, 230), (240, 210, 0)],
                   dtype=np.uint8)


def moving_disc(centres, radius=12.0, shape=(90, 120)):
    """Frames (T, H, W, 3) of a four-sector disc on white, centred at ``centres`` (T, 2)."""
    h, w = shape
    yy, xx = np.mgrid[0:h, 0:w] + 0.5
    frames = np.full((len(centres), h, w, 3), 255, dtype=np.uint8)
    for t, (cx, cy) in enumerate(centres):
        inside = (xx - cx) ** 2 + (yy - cy) ** 2 < radius**2
        quadrant = 2 * (yy >= cy).astype(int) + (xx >= cx).astype(int)
        for q in range(4):
            frames[t][inside & (quadrant == q)] = COLOURS[q]
    return frames


def box_at(centre, radius=12.0):
    return np.array([[centre[0] - radius, centre[1] - radius, 2 * radius, 2 * radius]])


@pytest.mark.parametrize("name", FAMILY)
def test_follows_a_slow_disc_on_white(name):
    path = np.stack([np.linspace(40, 80, 15), np.linspace(40, 50, 15)], axis=1)
    frames = moving_disc(path)
    result = trackers.track(trackers.make(name, rng=1), frames, box_at(path[0]))
    centres = result.boxes[:, 0, :2] + 12.0
    assert np.max(np.hypot(*(centres - path).T)) < 2.0
    # Confidence is 1 - the Bhattacharyya distance of the estimated window: in [0, 1].
    assert np.all(result.extras["confidence"][1:] > 0.8)
    assert np.all(result.extras["confidence"][1:] <= 1.0)


@pytest.mark.parametrize("name", FAMILY)
def test_target_leaving_the_frame_keeps_estimates_inside(name):
    # The disc walks off the right border and is gone for the last frames.
    path = np.stack([np.linspace(80, 150, 12), np.full(12, 45.0)], axis=1)
    frames = moving_disc(path)
    result = trackers.track(trackers.make(name, rng=2), frames, box_at(path[0]))
    centres = result.boxes[:, 0, :2] + result.boxes[:, 0, 2:] / 2
    assert np.all(np.isfinite(result.boxes))
    assert np.all((centres >= 0) & (centres <= [120, 90]))
    assert np.all(np.isfinite(result.extras["confidence"][1:]))


def rectangle(x, y, w=36, h=14, shape=(90, 120)):
    """A frame with a four-colour w x h rectangle at top-left (x, y) on white."""
    frame = np.full((*shape, 3), 255, dtype=np.uint8)
    for q, colour in enumerate(COLOURS):
        qx, qy = x + (q % 2) * w // 2, y + (q // 2) * h // 2
        frame[qy:qy + h // 2, qx:qx + w // 2] = colour
    return frame


@pytest.mark.parametrize("name, params", [
    ("meanshift", {}), ("sok", {}), ("hybrid", {"sigma": 0.0}),
])
def test_a_window_that_does_not_move_is_the_box_it_started_from(name, params):
    # Without mean-shift iterations a window stays where it started: at the centre of a
    # box that is not square. Its confidence is 1 on the frame it was modelled on, and
    # between 0 and 1 on a frame where the rectangle moved by 3 px.
    box = np.array([[40.0, 30.0, 36.0, 14.0]])
    for frame, moved in ((rectangle(40, 30), False), (rectangle(43, 30), True)):
        tracker = trackers.make(name, max_iter=0, rng=0, **params)
        tracker.init(rectangle(40, 30), box)
        est = tracker.step(frame)
        np.testing.assert_allclose(est.boxes, box, atol=1e-9)
        confidence = est.extras["confidence"][0]
        assert (0.0 < confidence < 0.999) if moved else confidence == pytest.approx(1.0)


def test_keep_inside_clips_centres_to_the_frame_in_place():
    from trackers.meanshift import keep_inside

    centres = np.array([[[-3.0, 5.0], [130.0, -0.5]], [[60.0, 95.0], [0.0, 90.0]]])
    keep_inside(centres, (90, 120, 3))
    np.testing.assert_array_equal(
        centres, [[[0.0, 5.0], [120.0, 0.0]], [[60.0, 90.0], [0.0, 90.0]]])


@pytest.mark.parametrize("name", FAMILY)
def test_same_seed_gives_the_same_track_for_several_targets(name):
    rng = np.random.default_rng(0)
    path = np.stack([np.linspace(30, 60, 8), np.linspace(30, 40, 8)], axis=1)
    frames = moving_disc(path)
    frames[:, 60:80, 80:110] = rng.integers(0, 256, (20, 30, 3), dtype=np.uint8)
    boxes = np.concatenate([box_at(path[0]), [[82.0, 62.0, 25.0, 16.0]]])
    runs = [trackers.track(trackers.make(name, rng=9), frames, boxes) for _ in range(2)]
    assert runs[0].boxes.shape == (8, 2, 4)
    np.testing.assert_array_equal(runs[0].boxes, runs[1].boxes)
    for key, value in runs[0].extras.items():
        np.testing.assert_array_equal(value, runs[1].extras[key])


def test_sok_spawns_only_when_confidence_falls_below_threshold():
    # A jittery disc: mean shift alone sometimes loses confidence, an easy run never does.
    rng = np.random.default_rng(3)
    path = np.stack([np.linspace(40, 80, 30), np.full(30, 45.0)], axis=1)
    jumpy = path + rng.normal(0.0, 5.0, path.shape)
    frames = moving_disc(jumpy)
    frames[:, 10:40, 90:118] = moving_disc([(104.0, 25.0)])[0, 10:40, 90:118]
    sok = trackers.make("sok", threshold=0.97, max_iter=3)
    result = trackers.track(sok, frames, box_at(jumpy[0]))
    spawned = result.extras["spawned"][1:, 0]
    confidence = result.extras["confidence"][1:, 0]
    assert spawned.any() and not spawned.all()
    # Without a spawn the kept estimate is the primary one, which must be confident.
    assert np.all(confidence[~spawned] >= 0.97)

    calm = trackers.track(trackers.make("sok", threshold=0.5), moving_disc(path),
                          box_at(path[0]))
    assert np.all(calm.extras["confidence"][1:] >= 0.5)
    assert not calm.extras["spawned"][1:].any()


def test_sok_keeps_the_most_confident_of_nine():
    # The tracker's window starts two cells away from the disc: only a grid tracker finds
    # it.
    frames = moving_disc([(40.0, 45.0), (80.0, 45.0)])
    sok = trackers.make("sok", threshold=0.9, spacing=1.0)
    sok.init(frames[0], box_at((40.0, 45.0)))
    frames[1, :, :] = moving_disc([(64.0, 45.0)])[0]
    est = sok.step(frames[1])
    assert est.extras["spawned"][0]
    assert np.hypot(*(est.boxes[0, :2] + 12.0 - (64.0, 45.0))) < 1.0
    assert est.extras["confidence"][0] > 0.95


@pytest.mark.parametrize(
    ("name", "params", "message"),
    [
        ("meanshift", {"max_iter": -1}, "max_iter"),
        ("meanshift", {"eps": -1.0}, "eps"),
        ("meanshift", {"kernel": "uniform"}, "epanechnikov, cone"),
        ("meanshift", {"bins": 64}, "bins"),
        ("sok", {"threshold": 1.5}, "threshold"),
        ("sok", {"spacing": 0.0}, "spacing"),
        ("hybrid", {"sigma": -2.0}, "sigma"),
        ("hybrid", {"n_particles": 2.5}, "n_particles"),
        ("hybrid", {"resampler": "nope"}, "multinomial"),
        ("kams", {"max_iter": 1.5}, "max_iter"),
        ("kams", {"n_layers": -1}, "n_layers"),
        ("kams", {"radius": 3}, "unknown parameter 'radius'"),
    ],
)
def test_bad_parameters_raise_value_error(name, params, message):
    with pytest.raises(ValueError, match=message):
        trackers.make(name, **params)


@pytest.mark.parametrize("name", FAMILY)
def test_bad_boxes_and_frames_raise_value_error(name):
    frames = moving_disc([(40.0, 45.0)] * 2)
    with pytest.raises(ValueError, match="outside"):
        trackers.make(name).init(frames[0], [[200.0, 10.0, 10.0, 10.0]])
    tracker = trackers.make(name)
    tracker.init(frames[0], box_at((40.0, 45.0)))
    with pytest.raises(ValueError, match="shape"):
        tracker.step(frames[1, :50])


def test_sok_spawns_below_the_threshold_not_at_it():
    box = np.array([[40.0, 30.0, 36.0, 14.0]])

    def step(threshold):
        sok = trackers.make("sok", threshold=threshold, max_iter=0)
        sok.init(rectangle(40, 30), box)
        return sok.step(rectangle(42, 30)).extras

    confidence = step(0.0)["confidence"][0]
    assert 0.0 < confidence < 1.0
    assert not step(confidence)["spawned"][0]
    assert step(np.nextafter(confidence, 1.0))["spawned"][0]


def test_sok_breaks_a_tie_by_the_candidate_nearest_the_primary_window():
    # The rectangle has left its window; two exact copies sit where two of the eight
    # extra windows start (spacing 1: offsets of one box size): one 36 px to the right,
    # one 36 px left and 14 px up (38.6 px away). Both match perfectly: the nearer wins.
    box = np.array([[50.0, 40.0, 36.0, 14.0]])
    frame = rectangle(86, 40, shape=(90, 160))
    frame[26:40, 14:50] = rectangle(14, 26, shape=(90, 160))[26:40, 14:50]
    sok = trackers.make("sok", threshold=0.9, max_iter=0, spacing=1.0)
    sok.init(rectangle(50, 40, shape=(90, 160)), box)
    est = sok.step(frame)
    assert est.extras["spawned"][0]
    assert est.extras["confidence"][0] == pytest.approx(1.0)
    np.testing.assert_allclose(est.boxes, [[86.0, 40.0, 36.0, 14.0]])


def test_sok_on_two_targets_that_spawn_at_once_is_sok_on_each_alone():
    shape = (90, 200)
    boxes = np.array([[20.0, 30.0, 36.0, 14.0], [120.0, 30.0, 36.0, 14.0]])
    before = np.minimum(rectangle(20, 30, shape=shape), rectangle(120, 30, shape=shape))
    after = np.minimum(rectangle(24, 31, shape=shape), rectangle(117, 33, shape=shape))

    def step(which):
        sok = trackers.make("sok", threshold=0.999, max_iter=3)
        sok.init(before, boxes[which])
        return sok.step(after)

    both = step([0, 1])
    assert both.extras["spawned"].all()
    for m in range(2):
        alone = step([m])
        np.testing.assert_array_equal(both.boxes[m], alone.boxes[0])
        np.testing.assert_array_equal(both.extras["confidence"][m], alone.extras["confidence"][0])


def test_hybrid_particles_move_by_their_velocity_then_climb():
    # Noise-free and without mean-shift iterations, every particle moves by its own
    # velocity (x + v) and stays there; the weights start equal.
    box = np.array([[40.0, 30.0, 36.0, 14.0]])
    frame = rectangle(40, 30)
    hybrid = trackers.make("hybrid", n_particles=5, sigma=0.0, max_iter=0, rng=0)
    hybrid.init(frame, box)
    np.testing.assert_allclose(hybrid.weights, np.full((5, 1), 0.2))
    hybrid.velocities[...] = (3.0, -2.0)
    hybrid.step(frame)
    np.testing.assert_allclose(hybrid.particles, np.broadcast_to([[[61.0, 35.0]]], (5, 1, 2)))
    np.testing.assert_allclose(hybrid.velocities, np.broadcast_to([[[3.0, -2.0]]], (5, 1, 2)))
    np.testing.assert_allclose(hybrid.weights.sum(axis=0), 1.0)


def test_hybrid_weights_are_the_likelihoods_where_the_particles_land():
    # Without mean-shift iterations the particles land at x + v + σ n (σ = 2 px per axis)
    # and are weighted by exp(−λ d²) of the Bhattacharyya distance there, per object.
    from trackers.meanshift import set_distances

    boxes = np.array([[20.0, 30.0, 36.0, 14.0], [70.0, 60.0, 36.0, 14.0]])
    frame = np.minimum(rectangle(20, 30), rectangle(70, 60))
    hybrid = trackers.make("hybrid", n_particles=400, sigma=2.0, max_iter=0, lam=20.0, rng=4)
    hybrid.init(frame, boxes)
    hybrid.step(frame)
    moved = hybrid.particles - (boxes[:, :2] + boxes[:, 2:] / 2)  # (N, K, 2)
    np.testing.assert_allclose(moved.std(axis=0), 2.0, rtol=0.15)
    np.testing.assert_allclose(moved.mean(axis=0), 0.0, atol=0.3)
    d = set_distances(hybrid.model.observe(frame), hybrid.particles.swapaxes(0, 1),
                      boxes[:, 2:])  # (K, N)
    w = np.exp(-20.0 * d**2)
    np.testing.assert_allclose(hybrid.weights, (w / w.sum(axis=1, keepdims=True)).T,
                               rtol=1e-9)
    assert np.ptp(d) > 0.05  # the particles see different windows
