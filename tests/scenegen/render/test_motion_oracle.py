"""AR2 paths and their boundary rules against references written from the docs.

``ar2_path`` is checked against the recurrence of docs/algorithms.md §1.1 written out
with a plain loop, against paths whose shape is known without it (a straight line, its
fold between two walls, a stop at a wall), and against the stream rule of its docstring
(exactly n - 1 normal draws when sigma > 0, none otherwise). ``ar2_stationary_moments``
is checked against the stationary covariance of the companion form, solved as a linear
system, and against the roots of the characteristic polynomial.
"""

from __future__ import annotations

import numpy as np
import pytest

from scenegen.config import AR2, MAX_PATH
from scenegen.errors import ConfigError
from scenegen.render.motion import ar2_path, ar2_stationary_moments


def reference(a1, a2, sigma, mean, start, velocity, n, seed, lo=-np.inf, hi=np.inf,
              boundary="free"):  # fmt: skip
    """c_t = m + a1 (c_{t-1} - m) + a2 (c_{t-2} - m) + sigma eps_t, c_0 = start,
    c_{-1} = start - velocity, m = start without a mean; at a limit (from frame 1):
    ``reflect`` mirrors the value and the previous one about the limit crossed (then
    keeps the value inside), ``clamp`` puts the value on the limit with zero velocity."""
    m = start if mean is None else mean
    draws = np.random.default_rng(seed).standard_normal(n - 1) if sigma > 0 and n > 1 else None
    path = [start]
    before = start - velocity
    for t in range(1, n):
        now = path[-1]
        c = m + a1 * (now - m) + a2 * (before - m)
        if draws is not None:
            c = c + sigma * draws[t - 1]
        if boundary != "free" and (c < lo or c > hi):
            if boundary == "reflect":
                wall = lo if c < lo else hi
                c, now = wall + (wall - c), wall + (wall - now)
                c = hi if c > hi else lo if c < lo else c
            else:
                c = lo if c < lo else hi
                now = c
        before = now
        path.append(c)
    return np.array(path[:n], dtype=np.float64)


def path(a1, a2, sigma, mean, start, velocity, n, seed, lo=-np.inf, hi=np.inf,
         boundary="free"):  # fmt: skip
    ar = AR2(boundary=boundary, a1=a1, a2=a2, sigma=sigma, mean=mean)
    return ar2_path(ar, start, velocity, n, rng=np.random.default_rng(seed), lo=lo, hi=hi)


# (a1, a2, sigma, mean, start, velocity): constant velocity, damped, mean-reverting with
# a mean away from the start, oscillating, a1 + a2 != 1 without a mean (the start is the
# mean), small and large noise.
CASES = [
    (2.0, -1.0, 1.5, None, 40.0, 2.5),
    (1.5, -0.5, 0.7, None, 12.0, -1.0),
    (0.6, 0.25, 2.0, 30.0, 5.0, 3.0),
    (-0.4, 0.3, 0.5, -7.0, 2.0, 0.5),
    (1.3, -0.45, 3.0, None, -3.0, 4.0),
    (0.9, 0.0, 0.25, 100.0, 90.0, -6.0),
]


@pytest.mark.parametrize("case", CASES)
def test_a_free_path_is_the_recurrence_with_the_streams_draws(case):
    for n in (1, 2, 3, 40):
        np.testing.assert_allclose(path(*case, n, 7), reference(*case, n, 7), rtol=0,
                                   atol=1e-9, err_msg=str((case, n)))  # fmt: skip


def test_without_noise_a_free_path_is_a_straight_line():
    t = np.arange(25.0)
    # a1 = 2, a2 = -1 is constant velocity: the mean drops out.
    for mean in (None, 0.0, 1000.0):
        np.testing.assert_array_equal(path(2.0, -1.0, 0.0, mean, 4.0, 1.5, 25, 0), 4.0 + 1.5 * t)


def test_with_a1_a2_zero_the_path_is_the_mean_plus_the_noise():
    draws = np.random.default_rng(3).standard_normal(9)
    np.testing.assert_allclose(path(0.0, 0.0, 2.5, 6.0, 1.0, 9.0, 10, 3)[1:], 6.0 + 2.5 * draws)
    # Without a mean, the start is the mean.
    np.testing.assert_allclose(path(0.0, 0.0, 2.5, None, 1.0, 9.0, 10, 3)[1:], 1.0 + 2.5 * draws)


@pytest.mark.parametrize("velocity", [3.0, -3.0, 7.0, -0.5, 20.0])
def test_reflect_folds_a_straight_line_between_the_limits(velocity):
    lo, hi, start, n = 10.0, 30.0, 20.0, 80
    free = start + velocity * np.arange(n)
    width = hi - lo
    y = np.mod(free - lo, 2 * width)
    folded = lo + np.where(y <= width, y, 2 * width - y)
    np.testing.assert_array_equal(
        path(2.0, -1.0, 0.0, None, start, velocity, n, 0, lo, hi, "reflect"), folded
    )


@pytest.mark.parametrize(("a1", "a2", "speed"), [(2.0, -1.0, 3.0), (1.5, -0.5, 12.0)])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_clamp_stops_at_the_limit_with_zero_velocity(a1, a2, speed, sign):
    lo, hi, start, n, velocity = 10.0, 30.0, 20.0, 40, sign * speed
    got = path(a1, a2, 0.0, None, start, velocity, n, 0, lo, hi, "clamp")
    free = path(a1, a2, 0.0, None, start, velocity, n, 0)
    inside = (free >= lo) & (free <= hi)
    first_out = int(np.argmin(inside))
    assert first_out > 0
    np.testing.assert_array_equal(got[:first_out], free[:first_out])
    np.testing.assert_array_equal(got[first_out:], hi if velocity > 0 else lo)


@pytest.mark.parametrize("boundary", ["reflect", "clamp"])
@pytest.mark.parametrize("case", CASES)
def test_a_noisy_bounded_path_follows_the_documented_rules(boundary, case):
    lo, hi = case[4] - 6.0, case[4] + 9.0
    got = path(*case, 300, 11, lo, hi, boundary)
    np.testing.assert_allclose(got, reference(*case, 300, 11, lo, hi, boundary), rtol=0, atol=1e-9)
    assert lo <= got[1:].min() and got[1:].max() <= hi


@pytest.mark.parametrize("boundary", ["reflect", "clamp"])
@pytest.mark.parametrize(("start", "velocity", "on"), [(9.0, -8.0, 10.0), (1.0, 8.0, 0.0)])
def test_a_value_on_a_limit_is_inside(boundary, start, velocity, on):
    # m = 5, a1 = 1/2, a2 = 1/4 (exact in binary): c_1 = 5 + (start - 5) / 2 + (start -
    # velocity - 5) / 4 lands exactly on the limit; the path never leaves [0, 10], so no
    # rule applies and the bounded path is the free one (a rule applied on the limit
    # would change the previous value and so c_2).
    free = path(0.5, 0.25, 0.0, 5.0, start, velocity, 12, 0)
    assert free[1] == on and free.min() >= 0.0 and free.max() <= 10.0
    got = path(0.5, 0.25, 0.0, 5.0, start, velocity, 12, 0, 0.0, 10.0, boundary)
    np.testing.assert_array_equal(got, free)


@pytest.mark.parametrize("boundary", ["reflect", "clamp"])
def test_limits_that_meet_hold_the_path_on_them(boundary):
    # 2 x margin + size = side: one allowed position.
    got = path(2.0, -1.0, 1.0, None, 3.0, 2.0, 20, 5, 8.0, 8.0, boundary)
    assert got[0] == 3.0
    np.testing.assert_array_equal(got[1:], 8.0)


def test_free_ignores_the_limits():
    for case in CASES:
        np.testing.assert_array_equal(
            path(*case, 60, 2, case[4] - 1.0, case[4] + 1.0, "free"), path(*case, 60, 2)
        )


@pytest.mark.parametrize("boundary", ["reflect", "clamp"])
def test_a_step_longer_than_the_interval_stays_inside(boundary):
    got = path(2.0, -1.0, 40.0, None, 5.0, 37.0, 200, 1, 0.0, 10.0, boundary)
    assert got[1:].min() >= 0.0 and got[1:].max() <= 10.0


@pytest.mark.parametrize("sigma", [0.0, 0.5, 3.0])
@pytest.mark.parametrize("n", [0, 1, 2, 9])
def test_the_stream_gives_exactly_n_minus_1_draws_with_noise_and_none_without(sigma, n):
    rng = np.random.default_rng(21)
    got = ar2_path(AR2(boundary="reflect", sigma=sigma), 5.0, 1.0, n, rng=rng, lo=0.0, hi=10.0)
    assert got.shape == (n,)
    if n:
        assert got[0] == 5.0
    used = np.random.default_rng(21)
    used.standard_normal(max(n - 1, 0) if sigma > 0 else 0)
    assert rng.standard_normal() == used.standard_normal()


def companion_moments(a1: float, a2: float, sigma: float) -> tuple[float, float]:
    """Stationary variance and lag-1 autocorrelation from S = A S A' + Q of the state
    (c_t, c_{t-1}), solved as a linear system in vec(S)."""
    a = np.array([[a1, a2], [1.0, 0.0]])
    q = np.array([[sigma**2, 0.0], [0.0, 0.0]])
    s = np.linalg.solve(np.eye(4) - np.kron(a, a), q.ravel()).reshape(2, 2)
    return s[0, 0], s[0, 1] / s[0, 0]


@pytest.mark.parametrize(
    ("a1", "a2", "sigma"),
    [(0.5, 0.2, 1.0), (1.5, -0.6, 3.0), (-0.3, 0.1, 0.5), (1.0, -0.5, 1.7), (0.0, 0.9, 0.3),
     (-1.2, -0.4, 4.0), (0.2, -0.95, 1.1)],
)  # fmt: skip
def test_stationary_moments_are_the_companion_forms(a1, a2, sigma):
    var, rho1 = ar2_stationary_moments(a1, a2, sigma)
    want_var, want_rho1 = companion_moments(a1, a2, sigma)
    assert var == pytest.approx(want_var, rel=1e-10)
    assert rho1 == pytest.approx(want_rho1, rel=1e-10, abs=1e-12)


def test_stationary_exactly_when_both_roots_lie_inside_the_unit_circle():
    # A grid of step 1/4 holds points on each edge of the stationarity triangle (a root
    # of modulus exactly 1): those are not stationary.
    grid = np.arange(-12, 13) / 4
    for a1 in grid:
        for a2 in grid:
            radius = np.abs(np.roots([1.0, -a1, -a2])).max()
            if abs(radius - 1.0) < 1e-6 or radius > 1.0:
                with pytest.raises(ValueError, match="not stationary"):
                    ar2_stationary_moments(float(a1), float(a2), 1.0)
            else:
                var, _ = ar2_stationary_moments(float(a1), float(a2), 1.0)
                assert var > 0, (a1, a2)


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_a_path_may_reach_max_path_but_not_go_beyond_it(sign):
    # Multiples of MAX_PATH / 4 = 2.5e17 are exact in binary: a straight line reaches
    # exactly +-MAX_PATH at frame 4 (allowed: "beyond" it is refused) and passes it at 5.
    ar = AR2(boundary="free")
    line = ar2_path(ar, 0.0, sign * MAX_PATH / 4, 5, rng=np.random.default_rng(0))
    assert line[-1] == sign * MAX_PATH
    with pytest.raises(ConfigError, match=r"^motion: the AR2 path reaches \S+ at frame 5,"):
        ar2_path(ar, 0.0, sign * MAX_PATH / 4, 6, rng=np.random.default_rng(0))
