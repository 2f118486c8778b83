"""Particle filters for multiple objects: Condensation, joint PF, PS and DPS (DPS paper).

All four share the observation model (``trackers.models.observation``: colour histograms, one
compiled call per sampling stage for every particle of every object), the AR2 dynamics of
(u, v, a) (``trackers.models.dynamics``) and the resamplers (``trackers.filters.resampling``); they
differ only in how they sample the joint state (docs/algorithms.md §2):

- ``Condensation`` ("condensation"): one independent single-object filter per target
  (Isard & Blake 1998); the one-object joint filter, run side by side.
- ``JointPF`` ("joint-pf", the paper's "Non-PS"): one filter over the joint state;
  resample, propagate every object, weight by the joint likelihood Π_i p(Z | X_i).
- ``PartitionedSampling`` ("ps", DPS §3): objects one at a time in an ``ordering``;
  weighted resampling by each object's likelihood before the next object moves.
- ``DistributedPartitionedSampling`` ("dps", DPS §4): the set split into ``n_groups``
  mixture components, each running PS with its own circular-shift ordering.

The observation model is swappable: the keyword ``observation`` takes any
``trackers.models.observation.ObservationModel`` (e.g. ``PositionModel``, a Gaussian
likelihood of the box centre around measured positions) in place of the colour model.
Parameters are the fields of ``ParticleParams`` (``PSParams``, ``DPSParams``).

Every step starts by resampling the set by the previous step's weights, so after a step
``self.particles`` (N, K, 3) and ``self.weights`` are the weighted set that represents
the posterior; its weighted mean per object is the estimate. ``Estimate.extras`` carries
``uniqueness`` (K,) and ``effective_dynamics`` (K,) (``trackers.filters.diagnostics``; the
latter averages u and v). A diagnostic hook, ``propagation_hook`` (None by default), is
called as ``hook(before, after, objects)`` after every propagation of ``joint-pf``,
``ps`` and ``dps``: row r moved object ``objects[r]`` (N,) from state ``before[r]`` to
``after[r]`` (both (N, 3); joint-pf moves every object of every row: one call per
object). It tells how many distinct hypotheses each object's dynamics spread from, and
how far (docs/experiments.md, "DPS Table 3"). The arrays are the hook's to keep.
Initialisation: the reference histograms are taken from the
frame-0 boxes and every particle starts on its initial box with zero velocity.

Examples
--------
>>> import numpy as np
>>> rng = np.random.default_rng(0)
>>> frame = rng.integers(0, 256, (60, 80, 3), dtype=np.uint8)
>>> frame[20:40, 30:50] = (255, 40, 40)
>>> pf = DistributedPartitionedSampling(n_particles=100, rng=1)
>>> pf.init(frame, np.array([[30.0, 20.0, 20.0, 20.0]]))
>>> est = pf.step(frame)
>>> bool(np.all(np.abs(est.boxes - [30.0, 20.0, 20.0, 20.0]) < 3.0))
True
"""

from __future__ import annotations

from abc import abstractmethod
from collections.abc import Callable
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from trackers.base import Estimate, Tracker
from trackers.filters.resampling import (
    RESAMPLE_MODES,
    RESAMPLERS,
    resample,
    resample_groups,
    weighted_resample_groups,
)
from trackers.filters.weights import normalised_weights
from trackers.kernels.histogram import DEFAULT_BOX_LEVELS, KERNELS
from trackers.kernels.sampling import SYSTEMATIC, count_distinct
from trackers.kernels.stages import (
    add_row_sums,
    effective_uv,
    gather_pair,
    group_weights,
    normalise_rows,
    propagate_objects,
    reassemble,
    resample_propagate,
    row_max_shift,
    stage_log_weights,
    state_boxes,
    weighted_mean_states,
)
from trackers.models.dynamics import AR2, boxes_from_states, check_ar2, states_from_boxes
from trackers.models.observation import (
    MAX_HISTOGRAM_LENGTH,
    MAX_PARTS,
    MODELS,
    ColourModel,
    FrameLikelihood,
    ObservationModel,
)
from trackers.params import (
    RNG_RANDOM,
    FieldDoc,
    TrackerParams,
    check_choice,
    check_integer,
    check_number,
    check_particle_count,
    choices,
    documented,
    is_integral,
)

__all__ = [
    "ASSIGNMENTS",
    "MIXTURES",
    "Condensation",
    "DPSParams",
    "DistributedPartitionedSampling",
    "JointPF",
    "PSParams",
    "ParticleParams",
    "PartitionedParams",
    "PartitionedSampling",
    "RESAMPLE_SCOPES",
    "WEIGHTINGS",
    "circular_shift",
]

#: Rules that assign particles to the DPS mixture components (``assignment``).
ASSIGNMENTS: tuple[str, ...] = ("random", "interleaved", "persistent")

#: How DPS weighs its components when it reassembles them (``mixture``).
MIXTURES: tuple[str, ...] = ("evidence", "prior")

#: Weighting functions of PS's weighted resampling stages (``weighting``).
WEIGHTINGS: tuple[str, ...] = ("stage", "placed", "g-only")

#: What a PS stage's weighted resampling copies from the drawn ancestors
#: (``resample_scope``).
RESAMPLE_SCOPES: tuple[str, ...] = ("joint", "placed")


def circular_shift(n_objects: int, k: int) -> NDArray[np.int64]:
    """The k-th circular shift (k, k+1, …, M−1, 0, …, k−1) of the objects 0…M−1.

    Parameters
    ----------
    n_objects : int
        M, the number of objects (>= 1).
    k : int
        The shift; taken modulo M.

    Returns
    -------
    ndarray of int64, shape (M,)
        The ordering, (k + i) mod M for i = 0 … M−1.

    Examples
    --------
    >>> circular_shift(4, 1).tolist()
    [1, 2, 3, 0]
    """
    return (np.arange(n_objects) + k) % n_objects


@documented()
@dataclass(frozen=True)
class ParticleParams(TrackerParams):
    """Parameters of the four particle filters (condensation, joint-pf; PS and DPS add theirs).

    Parameters
    ----------
    {parameters}
    """

    FIELD_DOCS: ClassVar[dict[str, FieldDoc]] = {
        "n_particles": ("int", "N, particles of the whole joint set (``joint-pf``, ``ps``, "
                               "``dps``) or of each target's filter (``condensation``), in "
                               "[1, ``trackers.params.MAX_PARTICLES``] (DPS: 300 synthetic, "
                               "200 real)."),
        "lam": ("float", "λ of the likelihood exp(−λ d²), finite and > 0."),
        "model": (choices(MODELS), "Colour-histogram observation model "
                                   "(``trackers.models.observation``)."),
        "bins": ("int", "Histogram bins per colour channel, in [1, 256]."),
        "n_parts": ("int or None", "Spatial components (horizontal bands) of a region, in "
                                   f"[1, {MAX_PARTS}] (the colour model's histogram, "
                                   "``n_parts`` × its bins per part, at most "
                                   f"{MAX_HISTOGRAM_LENGTH} long: "
                                   "``trackers.models.observation.ColourModel``); None: the "
                                   "model's default ("
                                   + ", ".join(f'{n} for "{m}"' for m, (n, _) in MODELS.items())
                                   + ")."),
        "kernel": (choices(KERNELS) + " or None",
                   "Kernel weighting the pixels of a region; None: the model's default ("
                   + ", ".join(f'"{k}" for "{m}"' for m, (_, k) in MODELS.items()) + ")."),
        "box_levels": ("int", 'Levels of the "box" kernel (nested rectangles), in [1, 16].'),
        "sigma": ("tuple of 3 float",
                  "(σ_u, σ_v, σ_a) of the AR2 tracking dynamics: px, px and log scale per "
                  "frame (DPS: 2, 2, 0.001); σ_u, σ_v in [0, "
                  "``trackers.models.dynamics.MAX_SIGMA_UV``], σ_a in [0, "
                  "``trackers.models.dynamics.MAX_SIGMA_A``] (about 20.7) "
                  "(``trackers.models.dynamics.check_ar2``)."),
        "a1": ("float", "AR2 coefficient A1 (A1 = 2, A2 = −1: constant velocity); with "
                        "``a2``, not explosive: |a2| <= 1 and |a1| <= 1 − a2 "
                        "(``trackers.models.dynamics.check_ar2``)."),
        "a2": ("float", "AR2 coefficient A2 (see ``a1``)."),
        "resampler": (choices(RESAMPLERS), "Resampling scheme of every (weighted) resampling "
                                           "step (``trackers.filters.resampling``)."),
        "observation": ("ObservationModel or None",
                        "The observation model, replacing the colour-histogram model built "
                        "from ``lam``, ``model``, ``bins``, ``n_parts``, ``kernel`` and "
                        "``box_levels`` (which are then unused): any object with "
                        "``set_references(frame, boxes)`` and ``observe(frame)`` returning "
                        "per-box log-likelihoods (the protocol "
                        "``trackers.models.observation.ObservationModel``); None: the colour "
                        "model."),
    }

    n_particles: int = 300
    lam: float = 20.0
    model: str = "hsv"
    bins: int = 10
    n_parts: int | None = None
    kernel: str | None = None
    box_levels: int = DEFAULT_BOX_LEVELS
    sigma: tuple[float, float, float] = (2.0, 2.0, 0.001)
    a1: float = 2.0
    a2: float = -1.0
    resampler: str = "systematic"
    observation: ObservationModel | None = None

    def __post_init__(self) -> None:
        check_particle_count(self)
        check_number(self, "lam", low=0.0, low_open=True)
        check_choice(self, "model", MODELS, what="observation model")
        check_integer(self, "bins", low=1, high=256)
        check_integer(self, "n_parts", low=1, high=MAX_PARTS, optional=True)
        if self.kernel is not None:
            check_choice(self, "kernel", KERNELS)
        check_integer(self, "box_levels", low=1, high=16)
        sigma, a1, a2 = check_ar2(self.sigma, self.a1, self.a2)
        self._set("sigma", sigma)
        self._set("a1", a1)
        self._set("a2", a2)
        check_choice(self, "resampler", RESAMPLERS, what="resampler")
        check_observation(self, "observation")


@documented()
@dataclass(frozen=True)
class PartitionedParams(ParticleParams):
    """Parameters shared by PS and DPS: ``ParticleParams``, ``weighting`` and
    ``resample_scope``.

    Parameters
    ----------
    {parameters}
    """

    FIELD_DOCS: ClassVar[dict[str, FieldDoc]] = {
        "weighting": (
            choices(WEIGHTINGS),
            "**(open)** The weighting function g_j of stage j's weighted resampling, which "
            "draws ancestors ∝ π g_j with π the weights carried from stage j − 1 "
            "(∝ 1 / g_{j−1}) and gives them the weight π / ρ. \"stage\": g_j = p(Z | X_{o_j}), "
            "the stage's object alone, as DPS §3 and MacCormick & Blake write it; ancestors "
            "are then drawn ∝ p(Z | X_{o_j}) / p(Z | X_{o_{j−1}}), which thins the previous "
            "object's good hypotheses, and the final weights keep p(Z | X_{o_i}) of every "
            "object but o_{M−1}, so the ordering decides how many distinct hypotheses an "
            "object moves from. \"placed\": g_j = Π_{i<=j} p(Z | X_{o_i}), the objects placed "
            "so far, so ancestors are drawn ∝ p(Z | X_{o_j}) and every object gets the same "
            "selections per step whatever its place. \"g-only\": ρ ∝ g_j = "
            "Π_{i<=j} p(Z | X_{o_i}) without π (the first object is selected at every stage, "
            "then penalised by the final weights). All three keep the set a correct "
            "weighted sample of the same posterior (docs/algorithms.md §2.5)."),
        "resample_scope": (
            choices(RESAMPLE_SCOPES),
            "**(open)** What a stage's weighted resampling copies from the drawn ancestor. "
            "\"joint\": the whole joint state, so the objects not yet placed in the step are "
            "thinned by the placed objects' selections. \"placed\": only the sub-states of "
            "the objects placed so far in the particle's ordering (o_1 … o_j at stage j, "
            "\"weighted resampling in each partition\", DPS §3); the others keep their own. "
            "Valid because the objects are independent a priori and in the likelihood, and "
            "every step starts from an equally weighted set; then the object sampled last "
            "is resampled once per step and the first M times."),
    }

    weighting: str = "stage"
    resample_scope: str = "joint"

    def __post_init__(self) -> None:
        super().__post_init__()
        check_choice(self, "weighting", WEIGHTINGS, what="weighting")
        check_choice(self, "resample_scope", RESAMPLE_SCOPES)


@documented()
@dataclass(frozen=True)
class PSParams(PartitionedParams):
    """Parameters of partitioned sampling: ``PartitionedParams`` and ``ordering``.

    Parameters
    ----------
    {parameters}
    """

    FIELD_DOCS: ClassVar[dict[str, FieldDoc]] = {
        "ordering": ("int or tuple of int",
                     "The order in which objects are sampled: an int k is the k-th circular "
                     "shift (k, k+1, …, K−1, 0, …, k−1) of the targets (0 ≤ k < K; the "
                     "paper's orderings), a sequence is an explicit permutation of 0…K−1 "
                     "(stored as a tuple). Checked against K at ``init``."),
    }

    ordering: int | tuple[int, ...] = 0

    def __post_init__(self) -> None:
        super().__post_init__()
        order = self.ordering
        if is_integral(order):
            if order < 0:
                raise ValueError(f"ordering must be a circular shift >= 0 or a permutation, "
                                 f"got {order!r}")
            self._set("ordering", int(order))
            return
        # A string was read digit by digit ("10" -> (1, 0)) and 1.5 as 1: refused.
        try:
            items = [] if isinstance(order, (str, bytes)) else list(order)
        except TypeError:
            items = []
        if not items or not all(is_integral(o) for o in items):
            raise ValueError(f"ordering must be an int (circular shift) or a sequence of "
                             f"target indices, got {order!r}")
        self._set("ordering", tuple(int(o) for o in items))


@documented()
@dataclass(frozen=True)
class DPSParams(PartitionedParams):
    """Parameters of distributed partitioned sampling: ``PartitionedParams`` and the groups.

    Parameters
    ----------
    {parameters}
    """

    FIELD_DOCS: ClassVar[dict[str, FieldDoc]] = {
        "n_groups": ("int or None", "C, the number of mixture components, in [1, "
                                    "n_particles]; None: one per target (the paper's C = M)."),
        "assignment": (
            choices(ASSIGNMENTS),
            "**(open)** How particles are assigned to the components. \"random\" (the paper) "
            "draws a uniformly random partition each step; \"interleaved\" sends particle n "
            "of the resampled set to component n mod C: systematic resampling leaves copies "
            "of one ancestor next to each other, so this spreads them over the components "
            "(stratified assignment) and uses no randomness. \"persistent\" keeps the "
            "components: each is resampled within itself by its own weights, and its mixture "
            "weight is carried from step to step (π_c,t ∝ π_c,t−1 Σ_{n∈c} w̃_n with the "
            "previous π_c,t−1, the general form of the paper's Eq. 3, as in Vermaak, Doucet "
            "& Pérez's mixture tracking, without their re-clustering). DPS is then a mixture "
            "of C PS filters, one per ordering, weighted by their evidence. The components "
            "start as contiguous blocks of the initial set (all its particles are equal)."),
        "mixture": (
            choices(MIXTURES),
            "**(open)** The components' mixture weights at reassembly: \"evidence\", "
            "π_c,t ∝ π_c,t−1 Σ_{n∈c} w̃_n (π_c,t−1 times the component's evidence, Vermaak "
            "et al.), or \"prior\", π_c,t = π_c,t−1: each component keeps its share whatever "
            "its evidence (the other reading of the paper's \"multiplied by the prior factor "
            "π_C,t to ensure a fair representation\"; docs/algorithms.md §2.6)."),
    }

    n_groups: int | None = None
    assignment: str = "random"
    mixture: str = "evidence"

    def __post_init__(self) -> None:
        super().__post_init__()
        check_integer(self, "n_groups", low=1, high=self.n_particles, optional=True)
        check_choice(self, "assignment", ASSIGNMENTS)
        check_choice(self, "mixture", MIXTURES)


def check_observation(params: TrackerParams, name: str) -> None:
    """Field ``name``: None or an object with ``set_references`` and ``observe``."""
    value = getattr(params, name)
    if value is not None and not isinstance(value, ObservationModel):
        raise ValueError(f"{name} must be None or an observation model with methods "
                         f"set_references(frame, boxes) and observe(frame), got "
                         f"{type(value).__name__}")


class _ParticleTracker(Tracker):
    """Shared initialisation, estimate and diagnostics of the four filters.

    Parameters: ``ParticleParams`` (fields as keywords), and ``rng``: the source of
    randomness; the same seed gives the same track.
    """

    Params = ParticleParams

    def _configure(self, params: ParticleParams) -> None:
        if params.observation is not None:
            self.model = params.observation
        else:
            self.model = ColourModel(params.model, bins=params.bins, n_parts=params.n_parts,
                                     kernel=params.kernel, lam=params.lam,
                                     box_levels=params.box_levels)
        self.dynamics = AR2(sigma=params.sigma, a1=params.a1, a2=params.a2)
        self.particles = np.empty((0, 0, 3))
        self.weights = np.empty(0)
        self.propagation_hook: Callable[[NDArray, NDArray, NDArray], None] | None
        self.propagation_hook = None

    def _init(self, frame: NDArray[np.uint8], boxes: NDArray[np.float64]) -> None:
        self.model.set_references(frame, boxes)
        states, self._sizes = states_from_boxes(boxes)
        self._mean = states
        n = self.params.n_particles
        self.particles = np.repeat(states[None], n, axis=0)
        self._prev = self.particles.copy()
        self.weights = np.full(n, 1.0 / n)
        self._objects = np.arange(boxes.shape[0])

    def _boxes(self, states: NDArray[np.float64], objects: NDArray[np.int64]
               ) -> NDArray[np.float64]:
        """Boxes (P, 4) of states (P, 3) of the given objects (P,)."""
        return boxes_from_states(states, self._sizes[objects])

    def _estimate(self, weights: NDArray[np.float64], extras: dict | None = None
                  ) -> Estimate:
        """Weighted mean state per object (weights (N, K)) as boxes, with diagnostics."""
        mean_state, var = weighted_mean_states(weights, self.particles)
        out = {"uniqueness": count_distinct(self.particles) / self.particles.shape[0],
               "effective_dynamics": effective_uv(var, self.dynamics._sigma)}
        out.update(extras or {})
        boxes = state_boxes(mean_state, np.exp(mean_state[:, 2]), self._sizes, self._objects)
        return Estimate(boxes=boxes, extras=out)

    def _estimate_shared(self, weights: NDArray[np.float64]) -> Estimate:
        """``_estimate`` for weights (N,) shared by every object."""
        return self._estimate(weights[:, None])


@documented(extra=RNG_RANDOM)
class Condensation(_ParticleTracker):
    """Condensation (Isard & Blake 1998): one independent filter of N particles per target.

    Each target's filter resamples by its own weights, propagates by AR2 and weights by
    its own likelihood; all targets' candidates of a frame are scored in one kernel call.
    With one target it is PS with one object, draw for draw.

    After a step ``weights`` has shape (N, K): column k weights target k's filter.
    Parameters: ``ParticleParams`` as keywords, and ``rng``.

    Parameters
    ----------
    {parameters}

    Attributes
    ----------
    particles : ndarray of shape (N, K, 3)
        Particle states (u, v, a) after the last step.
    weights : ndarray of shape (N, K)
        Normalised weights; each column sums to 1.
    """

    name = "condensation"

    def _init(self, frame: NDArray[np.uint8], boxes: NDArray[np.float64]) -> None:
        super()._init(frame, boxes)
        n = self.params.n_particles
        self.weights = np.full((n, self.n_targets), 1.0 / n)

    def _step(self, frame: NDArray[np.uint8]) -> Estimate:
        obs = self.model.observe(frame)
        n, k = self.params.n_particles, self.n_targets
        # Every target's filter resampled by its own column of weights: the targets as
        # the groups of one resampling call (the same draws as one call per target, in
        # target order), the ancestors back to rows of the target's column.
        groups = resample_groups(np.ascontiguousarray(self.weights.T).ravel(), np.full(k, n),
                                 method=self.params.resampler, rng=self.rng)
        idx = (groups.reshape(k, n) - (np.arange(k) * n)[:, None]).T
        cols = np.arange(k)
        x = self.particles[idx, cols]
        prev = self._prev[idx, cols]
        new = self.dynamics.propagate(x, prev, self._mean, rng=self.rng)
        objects = np.tile(cols, n)
        ll = obs.log_likelihoods(self._boxes(new.reshape(-1, 3), objects), objects)
        self._prev = x
        self.particles = new
        # normalised_weights of each column, in compiled glue around numpy's exp.
        self.weights = normalise_rows(np.exp(row_max_shift(ll.reshape(n, k).T))).T
        return self._estimate(self.weights)


@documented(extra=RNG_RANDOM)
class JointPF(_ParticleTracker):
    """Joint particle filter over all targets ("Non-PS", docs/algorithms.md §2.3).

    Resample the joint set, propagate every object, weight by Π_i p(Z | X_i). The
    likelihoods of all N × K candidate boxes come from one kernel call.
    Parameters: ``ParticleParams`` as keywords, and ``rng``.

    Parameters
    ----------
    {parameters}

    Attributes
    ----------
    particles : ndarray of shape (N, K, 3)
        Particle states (u, v, a) of the joint set after the last step.
    weights : ndarray of shape (N,)
        Normalised weights of the joint set; they sum to 1.
    """

    name = "joint-pf"

    def _step(self, frame: NDArray[np.uint8]) -> Estimate:
        obs = self.model.observe(frame)
        n, k = self.params.n_particles, self.n_targets
        idx = resample(self.weights, method=self.params.resampler, rng=self.rng)
        x, prev = gather_pair(self.particles, self._prev, idx)
        new = self.dynamics.propagate(x, prev, self._mean, rng=self.rng)
        if self.propagation_hook is not None:
            for i in range(k):
                self.propagation_hook(x[:, i].copy(), new[:, i].copy(),
                                      np.full(n, i, dtype=np.int64))
        objects = np.tile(np.arange(k), n)
        ll = obs.log_likelihoods(self._boxes(new.reshape(-1, 3), objects), objects)
        self._prev = x
        self.particles = new
        self.weights = normalised_weights(ll.reshape(n, k).sum(axis=1))
        return self._estimate_shared(self.weights)


class _Partitioned(_ParticleTracker):
    """The partitioned-sampling step shared by PS (one group) and DPS (several)."""

    @abstractmethod
    def _groups(self, idx: NDArray[np.int64]
                ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
        """Split the resampled set (ancestors ``idx`` (N,)) into groups: the ancestors
        reordered so that the groups are contiguous, the group sizes (C,) and each
        group's ordering (C, M)."""

    def _mixture_by_evidence(self) -> bool:
        """Whether the reassembly weighs the groups by their evidence (PS: one group)."""
        return True

    def _ancestors(self) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64],
                                  NDArray[np.float64] | None]:
        """The step's ancestors (N,), group sizes (C,), orderings (C, M) and log π_c,t−1
        (C,; None: groups drawn afresh, π_c,t−1 = N_c / N): the whole set resampled by
        its weights, then split by ``_groups``."""
        idx = resample(self.weights, method=self.params.resampler, rng=self.rng)
        return (*self._groups(idx), None)

    def _init(self, frame: NDArray[np.uint8], boxes: NDArray[np.float64]) -> None:
        self._kept_layout: tuple | None = None
        super()._init(frame, boxes)

    def _layout(self, sizes: NDArray[np.int64], orderings: NDArray[np.int64]
                ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
        """The step's stage layout for group sizes (C,) and orderings (C, M): the object
        each particle moves at each stage (M, N), the groups' first indices (C,) and the
        particle indices (N,). PS and DPS pass the same two arrays every step: the layout
        is kept for them and rebuilt only when either array is another one."""
        kept = self._kept_layout
        if kept is not None and kept[0] is sizes and kept[1] is orderings:
            return kept[2]
        group = np.repeat(np.arange(sizes.size), sizes)
        # objects[j, r]: the object particle r moves at stage j (its group's ordering).
        objects = np.ascontiguousarray(orderings[group].T, dtype=np.int64)
        layout = (objects, np.cumsum(sizes) - sizes, np.arange(int(sizes.sum())))
        self._kept_layout = (sizes, orderings, layout)
        return layout

    def _partitioned_step(self, frame: NDArray[np.uint8]) -> tuple[Estimate, NDArray]:
        obs: FrameLikelihood = self.model.observe(frame)
        n, m = self.params.n_particles, self.n_targets
        method = self.params.resampler
        idx, sizes, orderings, log_prior = self._ancestors()
        x, prev = gather_pair(self.particles, self._prev, idx)
        objects, starts, rows = self._layout(sizes, orderings)
        mode = RESAMPLE_MODES.get(method)
        dyn = self.dynamics
        logpi = np.zeros(n)
        ll = np.zeros((n, m))
        log_g = np.zeros(n)
        hook = self.propagation_hook
        stage_only = self.params.weighting == "stage"
        g_only = self.params.weighting == "g-only"
        # resample_scope "placed": placed[r, o] marks the objects row r has placed so far;
        # only those come from the drawn ancestor (None: all of them).
        placed = (np.zeros((n, m), dtype=np.bool_)
                  if self.params.resample_scope == "placed" else None)
        # Stage 0's AR2 (the (N, 3) normals of ``AR2.propagate``); every later stage's
        # comes with the previous stage's weighted resampling, in one kernel call.
        new = propagate_objects(x, prev, objects[0], self.rng.standard_normal((n, 3)),
                                self._mean, dyn._sigma, dyn.a1, dyn.a2)
        if hook is not None:
            # Propagation is in place: the moved objects' old states are now in prev.
            hook(prev[rows, objects[0]], new.copy(), objects[0].copy())
        for j in range(m):
            obj = objects[j]
            boxes = state_boxes(new, np.exp(new[:, 2]), self._sizes, obj)
            stage = np.ascontiguousarray(obs.log_likelihoods(boxes, obj), dtype=np.float64)
            if j == m - 1:
                ll[rows, obj] = stage
                break
            if placed is not None:
                placed[rows, obj] = True
            # Weighted resampling (DPS §3) inside each group: ancestors ∝ π g_j, weights
            # π / ρ. "stage": g_j = p(Z | X_{o_j}); "placed": g_j = Π_{i<=j} p(Z | X_{o_i}),
            # the objects placed so far (with π ∝ 1 / g_{j-1}, ancestors ∝ p(Z | X_{o_j}));
            # "g-only": ρ ∝ g_j of the placed objects, π ignored.
            # Constant factors of π and g cancel in each group: scale by the group's
            # largest for range (a group far below the others is still resampled).
            if stage_only:
                log_g.fill(0.0)
            shifted, finite = stage_log_weights(stage, ll, log_g, logpi, obj, sizes)
            if g_only:
                # ρ ∝ g_j alone (π π'/π = g): pass g / π as the weighting function.
                d = shifted[1] - shifted[0]
                shifted[1] = d - np.repeat(np.maximum.reduceat(d, starts), sizes)
            pi_g = np.exp(shifted)
            out = None
            if mode is not None and finite:
                uniforms = self.rng.random(sizes.size if mode == SYSTEMATIC else n)
                # The next stage's normals come after the uniforms, as in the numpy step.
                noise = self.rng.standard_normal((n, 3))
                out = resample_propagate(pi_g[0], pi_g[1], sizes, uniforms, mode, x, prev,
                                         ll, log_g, objects[j + 1], noise, self._mean,
                                         dyn._sigma, dyn.a1, dyn.a2, placed)
            if out is None:
                # Residual resampling, or weights the checked path rejects (it raises).
                k, w = weighted_resample_groups(pi_g[0], pi_g[1], sizes, method=method,
                                                rng=self.rng)
                if placed is None:
                    x, prev, ll = x[k], prev[k], ll[k]
                else:
                    x = np.where(placed[:, :, None], x[k], x)
                    prev = np.where(placed[:, :, None], prev[k], prev)
                    ll = np.where(placed, ll[k], ll)
                log_g = log_g[k]
                noise = self.rng.standard_normal((n, 3))
                new = propagate_objects(x, prev, objects[j + 1], noise, self._mean,
                                        dyn._sigma, dyn.a1, dyn.a2)
            else:
                w, x, prev, ll, log_g, new = out
            if hook is not None:
                hook(prev[rows, objects[j + 1]], new.copy(), objects[j + 1].copy())
            logpi = np.log(w)
        # The set {x, π'} still represents the predicted joint state (weighted resampling
        # preserves it), so π' Π_i p(Z | X_i) are the unnormalised posterior weights w̃.
        logw = add_row_sums(logpi, ll)
        weights, mixture, self._log_mixture = self._reassemble(
            logw, logpi, sizes, log_prior, evidence=self._mixture_by_evidence())
        self._logw = logw
        self.particles = x
        self._prev = prev
        self.weights = weights
        est = self._estimate_shared(weights)
        return est, mixture

    @staticmethod
    def _reassemble(logw: NDArray[np.float64], logpi: NDArray[np.float64],
                    sizes: NDArray[np.int64], log_prior: NDArray[np.float64] | None = None,
                    evidence: bool = True
                    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Mixture reassembly (DPS §4, after Vermaak, Doucet & Pérez 2003).

        π_c,t ∝ π_c,t−1 Σ_{n∈c} w̃_n, and particle n of group c gets π_c,t w̃_n / Σ_c w̃,
        with w̃_n = π'_n Π_i p(Z | X_i) (log ``logw``) and π' the group's proposal weights
        (log ``logpi``) normalised in the group, so that Σ_c w̃ estimates the group's
        evidence. Groups drawn afresh from an equally weighted (resampled) set start with
        π_c,t−1 = N_c / N (``log_prior`` None); groups that keep their particles pass the
        previous step's log π_c (``log_prior`` (C,)). With one group this is plain
        normalisation. ``evidence`` False (DPS ``mixture="prior"``): π_c,t = π_c,t−1, so
        every group keeps its share of the mass whatever its evidence. Returns the
        weights (N,), the mixture weights (C,) and their logs.
        """
        if sizes.size == 1:
            return normalised_weights(logw), np.ones(1), np.zeros(1)
        # log_total = LSE_c(logw), log_evidence = log_total − LSE_c(logpi), mixture =
        # normalised(log π_c,t−1 + log_evidence), weights = normalised(logw + log
        # mixture_c − log_total_c), in compiled glue between numpy's exp and log.
        if log_prior is None:
            log_prior = np.log(sizes / sizes.sum())
        return reassemble(logw, logpi, sizes, log_prior, evidence)


@documented(extra=RNG_RANDOM)
class PartitionedSampling(_Partitioned):
    """Partitioned sampling (MacCormick & Blake 2000; docs/algorithms.md §2.5).

    Parameters: ``PSParams`` (``ordering`` and the ``ParticleParams``) as keywords, and
    ``rng``.

    Parameters
    ----------
    {parameters}

    Attributes
    ----------
    particles : ndarray of shape (N, K, 3)
        Particle states (u, v, a) of the joint set after the last step.
    weights : ndarray of shape (N,)
        Normalised weights of the joint set; they sum to 1.

    Raises
    ------
    ValueError
        For a bad parameter value; at ``init``, for an ``ordering`` that is not a
        circular shift in [0, K) or a permutation of the K targets.
    """

    name = "ps"
    Params = PSParams

    def _init(self, frame: NDArray[np.uint8], boxes: NDArray[np.float64]) -> None:
        k = boxes.shape[0]
        if isinstance(self.params.ordering, tuple):
            order = np.asarray(self.params.ordering, dtype=np.int64)
            if sorted(order.tolist()) != list(range(k)):
                raise ValueError(f"ordering {list(self.params.ordering)} is not a permutation "
                                 f"of the {k} targets 0..{k - 1}")
        else:
            if self.params.ordering >= k:
                raise ValueError(f"ordering (circular shift) must lie in [0, {k}) for {k} "
                                 f"targets, got {self.params.ordering}")
            order = circular_shift(k, int(self.params.ordering))
        self._order = order[None, :]
        self._sizes_c = np.array([self.params.n_particles])
        super()._init(frame, boxes)

    def _groups(self, idx):
        return idx, self._sizes_c, self._order

    def _step(self, frame: NDArray[np.uint8]) -> Estimate:
        est, _ = self._partitioned_step(frame)
        return est


@documented(extra=RNG_RANDOM)
class DistributedPartitionedSampling(_Partitioned):
    """Distributed partitioned sampling (Smith & Gatica-Perez 2004; docs/algorithms.md §2.6).

    Each step the resampled set is divided into ``n_groups`` mixture components of
    N / C particles (the remainder spread over the first groups); component c runs PS
    with the (c mod K)-th circular-shift ordering; the components are reassembled with
    mixture weights π_c,t ∝ π_c,t−1 Σ_{n∈c} w̃_n. All components of a sampling stage are
    scored in one kernel call. ``Estimate.extras["mixture_weights"]`` is (C,).

    Parameters: ``DPSParams`` (``n_groups``, ``assignment``, ``mixture`` and the
    ``PartitionedParams``) as keywords, and ``rng``. ``n_groups=1`` gives PS with the
    identity ordering, draw for draw.

    Parameters
    ----------
    {parameters}

    Attributes
    ----------
    particles : ndarray of shape (N, K, 3)
        Particle states (u, v, a) of the joint set after the last step.
    weights : ndarray of shape (N,)
        Normalised weights of the joint set (all components); they sum to 1.

    Raises
    ------
    ValueError
        For a bad parameter value; at ``init``, when ``n_groups`` is None and the
        number of targets exceeds ``n_particles``.
    """

    name = "dps"
    Params = DPSParams

    def _init(self, frame: NDArray[np.uint8], boxes: NDArray[np.float64]) -> None:
        k = boxes.shape[0]
        c = k if self.params.n_groups is None else self.params.n_groups
        if c > self.params.n_particles:
            raise ValueError(f"n_groups = {c} (one per target) exceeds n_particles = "
                             f"{self.params.n_particles}")
        n = self.params.n_particles
        self._sizes_c = np.array([n // c + (i < n % c) for i in range(c)], dtype=np.int64)
        self._orders = np.stack([circular_shift(k, i % k) for i in range(c)])
        if self.params.assignment == "interleaved":
            self._interleave = np.concatenate([np.arange(i, n, c) for i in range(c)])
        self._logw: NDArray[np.float64] | None = None
        super()._init(frame, boxes)

    def _ancestors(self):
        if self.params.assignment != "persistent" or self._sizes_c.size == 1:
            return super()._ancestors()
        sizes = self._sizes_c
        if self._logw is None:  # first step: every particle is the initial state
            idx = np.arange(self.params.n_particles)
            log_prior = np.log(sizes / sizes.sum())
        else:
            idx = resample_groups(group_weights(self._logw, sizes), sizes,
                                  method=self.params.resampler, rng=self.rng)
            log_prior = self._log_mixture
        return idx, sizes, self._orders, log_prior

    def _mixture_by_evidence(self) -> bool:
        return self.params.mixture == "evidence"

    def _groups(self, idx):
        if self._sizes_c.size > 1:
            if self.params.assignment == "random":
                order = self.rng.permutation(self.params.n_particles)
            else:
                order = self._interleave
            idx = idx[order]
        return idx, self._sizes_c, self._orders

    def _step(self, frame: NDArray[np.uint8]) -> Estimate:
        est, mixture = self._partitioned_step(frame)
        est.extras["mixture_weights"] = mixture
        return est
