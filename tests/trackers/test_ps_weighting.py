"""The weighting functions of partitioned sampling (``weighting``: placed, stage, g-only).

Stage j of PS draws its ancestors ∝ ρ and gives them the weight π / ρ, so after the last
stage the weights are exactly a product of powers of the objects' likelihoods, known per
weighting (trackers.particle.PartitionedParams). With the Gaussian position likelihood of
the oracle tests those can be recomputed from the final particles alone, so each
weighting's formula is checked to rounding error, on every step and for every ordering.
"""

from __future__ import annotations

import linear_gaussian
import numpy as np
import pytest

import trackers
from trackers.models.observation import PositionModel

T, N, SIGMA, R_STD = 12, 200, 2.0, 2.0
START = np.array([[60.0, 50.0], [120.0, 70.0], [90.0, 130.0], [150.0, 140.0]])
K = START.shape[0]


def exponents(weighting: str, order: tuple[int, ...]) -> np.ndarray:
    """c (K,): log w = Σ_k c_k log p(Z | X_k) + const after a PS step with ``order``."""
    m = len(order)
    c = np.zeros(m)
    c[order[-1]] = 1.0                      # the last object is weighted, not resampled
    if weighting == "stage":                # final w = Π_{i != o_{M-1}} p_i
        c[list(order[:-2])] = 1.0
    elif weighting == "g-only":             # final w = p_{o_M} Π_{i<M-1} p_{o_i}^{-(M-1-i)}
        for i, obj in enumerate(order[:-1], start=1):
            c[obj] = -(m - 1 - i)
    return c


def final_log_weights(weighting: str, order: tuple[int, ...], seed: int,
                      scope: str = "joint") -> list[tuple[np.ndarray, np.ndarray]]:
    """(tracker's log-weights, the formula's) (N,) per step, both shifted to max 0."""
    z = linear_gaussian.measurements(2, START, T, SIGMA, R_STD, salt=91)
    pf = trackers.make("ps", n_particles=N, sigma=(SIGMA, SIGMA, 0.0), ordering=order,
                       weighting=weighting, resample_scope=scope,
                       observation=PositionModel(z, np.eye(2) * R_STD**2), rng=seed)
    frames = np.zeros((T, 220, 220, 3), np.uint8)
    pf.init(frames[0], np.column_stack([z[0] - 5.0, np.full((K, 2), 10.0)]))
    c = exponents(weighting, order)
    out = []
    for t in range(1, T):
        pf.step(frames[t])
        # log p(Z | X_k) up to a constant: the centres (u, v) against z_t, covariance r² I.
        ll = -0.5 * ((pf.particles[:, :, :2] - z[t]) ** 2).sum(axis=2) / R_STD**2  # (N, K)
        want = ll @ c
        got = np.log(pf.weights)
        out.append((got - got.max(), want - want.max()))
    return out


@pytest.mark.parametrize("scope", ["joint", "placed"])
@pytest.mark.parametrize("weighting", ["placed", "stage", "g-only"])
@pytest.mark.parametrize("order", [(0, 1, 2, 3), (2, 0, 3, 1)])
def test_final_weights_are_the_weightings_product_of_likelihoods(weighting, order, scope):
    # resample_scope "placed" copies only the placed objects' sub-states: the weights
    # still belong to the particles' own placed states, so the formula is the same.
    for got, want in final_log_weights(weighting, order, seed=5, scope=scope):
        np.testing.assert_allclose(got, want, atol=1e-8)


def test_the_three_weightings_draw_differently():
    # Same seed, same first stage: the draws part from the second stage on.
    z = linear_gaussian.measurements(2, START, T, SIGMA, R_STD, salt=91)
    frames = np.zeros((2, 220, 220, 3), np.uint8)
    sets = []
    for weighting in ("placed", "stage", "g-only"):
        pf = trackers.make("ps", n_particles=N, sigma=(SIGMA, SIGMA, 0.0), weighting=weighting,
                           observation=PositionModel(z, np.eye(2) * R_STD**2), rng=3)
        pf.init(frames[0], np.column_stack([z[0] - 5.0, np.full((K, 2), 10.0)]))
        pf.step(frames[1])
        sets.append(pf.particles)
    a, b, c = sets
    assert not np.array_equal(a, b) and not np.array_equal(a, c) and not np.array_equal(b, c)


@pytest.mark.parametrize("name", ["ps", "dps", "joint-pf"])
def test_estimate_is_the_weighted_mean_box_of_each_of_many_objects(name):
    # Six objects (more than the four columns of a box): each estimate is the box of its
    # object's weighted mean state, with that object's own size.
    start = np.array([[30.0, 30.0], [80, 40], [130, 50], [60, 120], [120, 130], [170, 170]])
    z = linear_gaussian.measurements(4, start, 4, SIGMA, R_STD, salt=5)
    sizes = np.array([[10.0, 12.0], [14, 10], [8, 8], [12, 16], [10, 10], [16, 12]])
    pf = trackers.make(name, n_particles=120, sigma=(SIGMA, SIGMA, 0.0),
                       observation=PositionModel(z, np.eye(2) * R_STD**2), rng=2)
    frames = np.zeros((4, 220, 220, 3), np.uint8)
    pf.init(frames[0], np.column_stack([z[0] - sizes / 2, sizes]))
    for t in range(1, 4):
        est = pf.step(frames[t])
        w = np.asarray(pf.weights)
        mean = np.einsum("n,nkc->kc", w, pf.particles)
        want = np.column_stack([mean[:, :2] - sizes * np.exp(mean[:, 2:3]) / 2,
                                sizes * np.exp(mean[:, 2:3])])
        np.testing.assert_allclose(est.boxes, want, atol=1e-9)


@pytest.mark.parametrize("name", ["ps", "dps", "joint-pf"])
def test_the_hook_gets_each_moved_objects_own_state(name):
    # Without noise and at rest, AR2 leaves every state where it is: the hook's "before"
    # must be the moved object's own state, equal to "after" row for row.
    z = linear_gaussian.measurements(2, START, T, SIGMA, R_STD, salt=91)
    pf = trackers.make(name, n_particles=N, sigma=(0.0, 0.0, 0.0),
                       observation=PositionModel(z, np.eye(2) * R_STD**2), rng=1)
    frames = np.zeros((3, 220, 220, 3), np.uint8)
    pf.init(frames[0], np.column_stack([z[0] - 5.0, np.full((K, 2), 10.0)]))
    calls = []
    pf.propagation_hook = lambda before, after, objects: calls.append((before, after, objects))
    pf.step(frames[1])
    pf.step(frames[2])
    assert len(calls) == 2 * K
    for before, after, objects in calls:
        np.testing.assert_array_equal(before, after)
        np.testing.assert_array_equal(before[:, :2], START[objects])
