"""Our trackers' base class (the protocol itself: trackers.protocol), particle sets, validation.

A tracker is constructed with keyword parameters (``trackers.make(name, **params)``),
initialised on the first frame with one box per target, then stepped frame by frame::

    tracker = trackers.make("dps", n_particles=300, rng=0)
    tracker.init(frames[0], boxes0)          # boxes0: (K, 4) [x, y, w, h]
    for frame in frames[1:]:
        estimate = tracker.step(frame)       # estimate.boxes: (K, 4)

Trackers keep their randomness in ``self.rng`` (a ``numpy.random.Generator`` made once
from the ``rng`` argument) and never touch global random state. Their parameters are one
frozen dataclass per family (``Tracker.Params``, ``trackers.params``), validated on
construction and kept as ``self.params``.

Particle sets
-------------
Every particle tracker exposes its set after a step in one convention:

``particles`` : ndarray of shape (N, K, D)
    Particle n's state of object k: D = 3, (u, v, a) = centre and log scale, for the DPS
    filters (``trackers.models.dynamics``); D = 2, the centre (x, y), for the KAMS family
    (sizes stay those of ``init``). Pixels, x = column.
``weights`` : ndarray of shape (N,) or (N, K), normalised, linear (not log)
    (N,) for one joint set, whose particle n carries all K objects (``joint-pf``, ``ps``,
    ``dps``): sums to 1. (N, K) for K independent per-object sets (``condensation``,
    ``annealed``, ``hybrid``, ``kams``): each column sums to 1.

Likelihoods are exchanged as natural logs (``trackers.models.observation``: the
observation protocol scores boxes (P, 4), one object index per row, and returns (P,)
log-likelihoods); log-weights become weights through the one normaliser,
``trackers.filters.weights.normalised_weights`` (largest log-weight subtracted, so exp
never overflows), which the SHM trackers also use for their ordering probabilities.
Estimates are weighted means of ``particles`` by ``weights`` (of the main mode, where a
tracker offers it).

One boundary (named): the KAMS family computes on object-major arrays, sets (K, N, D) and
weights (K, N), because its reductions over the particles (survival rate, β search,
estimate) and its noise draws run in that memory order and re-laying them out would
change the results' last bits. Its ``particles`` and ``weights`` are views of those arrays
with the first two axes swapped, and ``trackers.meanshift.set_*`` flatten them to the
observation model's rows.

A tracker composes parts
------------------------
Observation (``trackers.models.observation``: ``ColourModel`` or any ``ObservationModel``),
dynamics (``trackers.models.dynamics.AR2``, or noise on the centres), sampler
(``trackers.filters.resampling`` by name, partitioned / annealed stages, mean shift
``FrameObservation.mean_shift``) and the weight normaliser. A new tracker is a short
file; a joint bootstrap filter over all targets, complete:

>>> from dataclasses import dataclass
>>> from trackers.filters.resampling import resample
>>> from trackers.filters.weights import normalised_weights
>>> from trackers.models.dynamics import AR2, boxes_from_states, states_from_boxes
>>> from trackers.models.observation import ColourModel
>>> from trackers.params import TrackerParams, check_integer
>>> @dataclass(frozen=True)
... class BootstrapParams(TrackerParams):
...     n_particles: int = 100
...     def __post_init__(self):
...         check_integer(self, "n_particles", low=1)
>>> class Bootstrap(Tracker):
...     name = "bootstrap"
...     Params = BootstrapParams
...     def _configure(self, params):
...         self.observation = ColourModel("hsv", lam=20.0)        # observation
...         self.dynamics = AR2(sigma=(2.0, 2.0, 0.001))           # dynamics
...     def _init(self, frame, boxes):
...         self.observation.set_references(frame, boxes)
...         self.start, self.sizes = states_from_boxes(boxes)     # (K, 3), (K, 2)
...         n = self.params.n_particles
...         self.particles = np.repeat(self.start[None], n, axis=0)  # (N, K, 3)
...         self.previous = self.particles.copy()
...         self.weights = np.full(n, 1.0 / n)                     # (N,): one joint set
...     def _step(self, frame):
...         obs = self.observation.observe(frame)
...         idx = resample(self.weights, method="systematic", rng=self.rng)  # sampler
...         x, prev = self.particles[idx], self.previous[idx]
...         new = self.dynamics.propagate(x, prev, self.start, rng=self.rng)
...         n, k = new.shape[:2]
...         boxes = boxes_from_states(new, self.sizes).reshape(n * k, 4)
...         ll = obs.log_likelihoods(boxes, np.tile(np.arange(k), n)).reshape(n, k)
...         self.particles, self.previous = new, x
...         self.weights = normalised_weights(ll.sum(axis=1))
...         mean = np.einsum("n,nkd->kd", self.weights, new)
...         return Estimate(boxes_from_states(mean, self.sizes))
>>> frame = np.zeros((60, 80, 3), np.uint8); frame[20:40, 30:50] = (255, 40, 40)
>>> tracker = Bootstrap(n_particles=50, rng=0)
>>> tracker.init(frame, np.array([[30.0, 20.0, 20.0, 20.0]]))
>>> bool(np.abs(tracker.step(frame).boxes - [30.0, 20.0, 20.0, 20.0]).max() < 3.0)
True
"""

from __future__ import annotations

import inspect
from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from trackers.kernels.stages import clip_centres
from trackers.params import TrackerParams

__all__ = [
    "MAX_BOX_VALUE",
    "BaseTracker",
    "Estimate",
    "Tracker",
    "as_generator",
    "box_array",
    "check_generator",
    "check_boxes",
    "check_frame",
]

RngLike = np.random.Generator | int | None

MAX_BOX_VALUE = 1e9
"""Largest |x|, |y|, w and h of an initial box, in pixels (``check_boxes``). Larger boxes
overflowed: a 1e308 box failed in the colour kernels with "boxes must be finite", and
beyond 9.2e18 the template trackers cast coordinates to int64 with undefined results."""


def as_generator(rng: RngLike) -> np.random.Generator:
    """Turn an ``rng`` argument into a Generator (a Generator is used as is).

    Parameters
    ----------
    rng : numpy.random.Generator, int or None
        A Generator (returned as is), a non-negative seed, or None (fresh OS entropy).

    Returns
    -------
    numpy.random.Generator
        ``rng`` itself, or ``numpy.random.default_rng(rng)``.

    Raises
    ------
    ValueError
        For anything else (a negative int, a bool, a float, a string, a SeedSequence).
    """
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None or (isinstance(rng, (int, np.integer)) and not isinstance(rng, bool)
                       and rng >= 0):
        return np.random.default_rng(rng)
    # True was seed 1; a SeedSequence's repr took three lines.
    what = repr(rng) if isinstance(rng, (int, np.integer, float, str)) else type(rng).__name__
    raise ValueError(f"rng must be a numpy Generator, a non-negative int or None, not {what}")


def check_generator(rng: Any) -> None:
    """Refuse an ``rng`` that is not a ``numpy.random.Generator``, in one line.

    For the functions that draw from a Generator they are given (resamplers, dynamics):
    unlike a tracker's ``rng`` (:func:`as_generator`), a seed there would restart the
    same draws at every call, so it is refused rather than turned into a Generator.

    Parameters
    ----------
    rng : Any
        The argument to check.

    Raises
    ------
    ValueError
        If ``rng`` is not a Generator (a seed, None, a ``RandomState``), naming its type.
    """
    if not isinstance(rng, np.random.Generator):
        # An int was "'int' object has no attribute 'random'" (AttributeError).
        raise ValueError(f"rng must be a numpy Generator (numpy.random.default_rng(seed)), "
                         f"got {type(rng).__name__}")


@dataclass
class Estimate:
    """What ``Tracker.step`` returns for one frame.

    Attributes
    ----------
    boxes : ndarray of shape (K, 4)
        Estimated box [x, y, w, h] per target, in the order of ``init``.
    extras : dict
        Per-frame diagnostics of the tracker (e.g. ``order_prob`` of shape (L,) for the
        SHM trackers, ``confidence`` of shape (K,) for mean shift).
    """

    boxes: NDArray[np.float64]
    extras: dict[str, Any] = field(default_factory=dict)


def check_frame(frame: Any, expected_shape: tuple[int, ...] | None = None) -> NDArray[np.uint8]:
    """Validate one RGB frame and return it as a C-contiguous uint8 array (H, W, 3).

    Parameters
    ----------
    frame : array_like of uint8, shape (H, W, 3)
        The frame, H, W >= 1. Other dtypes are refused, not converted.
    expected_shape : tuple of int or None, optional
        The shape the frame must have (that of the sequence's first frame); None (the
        default): any (H, W, 3).

    Returns
    -------
    ndarray of uint8, shape (H, W, 3)
        ``frame`` as a C-contiguous array (no copy when it already is one).

    Raises
    ------
    ValueError
        If the frame is not (H, W, 3) uint8, or its shape differs from ``expected_shape``.
    """
    arr = np.asarray(frame)
    if arr.ndim != 3 or arr.shape[2] != 3 or arr.shape[0] < 1 or arr.shape[1] < 1:
        raise ValueError(f"frame must have shape (H, W, 3), got {arr.shape}")
    if expected_shape is not None and arr.shape != tuple(expected_shape):
        raise ValueError(
            f"frame shape changed mid-sequence: got {arr.shape}, expected {tuple(expected_shape)}"
        )
    if arr.dtype != np.uint8:
        # Converting here was garbage in: a 16-bit image clipped to 0/255, NaN to 0, and a
        # float frame rescaled or not by its own maximum, so frames of one sequence
        # differently. The protocol's frame is uint8: the caller knows its scale.
        raise ValueError(
            f"frame must be uint8 RGB, got dtype {arr.dtype} (convert it first, e.g. "
            "(img * 255).round().astype(np.uint8) for floats in [0, 1])"
        )
    return np.ascontiguousarray(arr)


def box_array(boxes: Any, name: str = "boxes") -> NDArray[np.float64]:
    """``boxes`` as a new float64 array (K, 4), K >= 1; one box (4,) is one row.

    Parameters
    ----------
    boxes : array_like of float, shape (K, 4) or (4,)
        Boxes [x, y, w, h] in px.
    name : str, default "boxes"
        What the error messages call ``boxes``.

    Returns
    -------
    ndarray of float64, shape (K, 4)
        A new array (never a view of ``boxes``); no check of the values.

    Raises
    ------
    ValueError
        Naming ``name``, if ``boxes`` is not numbers of that shape (strings, ragged
        lists, ``None``).
    """
    try:
        arr = np.array(boxes, dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise ValueError(f"{name} must be numbers [x, y, w, h] of shape (K, 4), got "
                         f"{type(boxes).__name__}: {str(err).splitlines()[0]}") from None
    if arr.ndim == 1 and arr.shape[0] == 4:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != 4 or arr.shape[0] < 1:
        raise ValueError(f"{name} must have shape (K, 4) with K >= 1, got {np.shape(boxes)}")
    return arr


def check_boxes(boxes: Any, frame_shape: tuple[int, ...]) -> NDArray[np.float64]:
    """Validate initial boxes (K, 4) against a frame of shape (H, W, ...).

    A box must have positive width and height, overlap the frame and have no coordinate
    or size beyond :data:`MAX_BOX_VALUE` pixels.

    Parameters
    ----------
    boxes : array_like of float, shape (K, 4) or (4,)
        Boxes [x, y, w, h] in px, K >= 1.
    frame_shape : tuple of int
        Shape of the frame, (H, W, ...), in px.

    Returns
    -------
    ndarray of float64, shape (K, 4)
        The boxes as a new array (see :func:`box_array`).

    Raises
    ------
    ValueError
        Naming the first offending box and what is wrong with it.
    """
    arr = box_array(boxes, "boxes")
    h, w = frame_shape[0], frame_shape[1]
    for k, (x, y, bw, bh) in enumerate(arr):
        if not np.all(np.isfinite([x, y, bw, bh])):
            raise ValueError(f"box {k} is not finite: {arr[k].tolist()}")
        if bw <= 0 or bh <= 0:
            raise ValueError(f"box {k} has zero or negative size: {arr[k].tolist()}")
        if max(abs(x), abs(y), bw, bh) > MAX_BOX_VALUE:
            raise ValueError(f"box {k} {arr[k].tolist()} is too large: |x|, |y|, w and h "
                             f"must be <= {MAX_BOX_VALUE:g} px")
        if x >= w or y >= h or x + bw <= 0 or y + bh <= 0:
            raise ValueError(f"box {k} {arr[k].tolist()} lies outside the {w}x{h} frame")
    return arr


class BaseTracker(ABC):
    """Base class of every tracker: ``init`` on the first frame, then ``step``.

    Subclasses set ``name`` and implement ``_init`` and ``_step``; this class validates
    frames and boxes so that every tracker rejects bad input the same way.

    A subclass with parameters sets ``Params`` to its frozen parameter dataclass
    (``trackers.params``) and builds its parts from ``self.params`` in ``_configure``;
    the class's signature (``help``, ``inspect.signature``) lists the fields with their
    defaults. Fields can be read as attributes of the tracker (``tracker.n_particles``).

    Parameters
    ----------
    params : TrackerParams, optional (positional only)
        A ready instance of the class's ``Params``; keyword ``**kwargs`` then override
        its fields (``dataclasses.replace``).
    rng : numpy.random.Generator, int or None, optional
        Source of randomness, kept as ``self.rng``.
    **kwargs : Any
        The fields of ``Params`` (see the tracker's parameter dataclass).

    Raises
    ------
    TypeError
        For a keyword that is not a field of ``Params``, naming it; for ``params`` that
        is not an instance of ``Params``; for any parameter but ``rng`` when ``Params``
        is None.
    ValueError
        From ``Params`` for a bad value, naming the parameter; for a bad ``rng``
        (:func:`as_generator`).
    """

    name: ClassVar[str] = ""
    #: The parameter dataclass of the tracker family (None: no parameters but ``rng``).
    Params: ClassVar[type[TrackerParams] | None] = None

    def __init__(self, params: TrackerParams | None = None, /, *, rng: RngLike = None,
                 **kwargs: Any) -> None:
        self.rng = as_generator(rng)
        self._frame_shape: tuple[int, ...] | None = None
        self.n_targets = 0
        cls = type(self)
        if cls.Params is None:
            if params is not None or kwargs:
                bad = next(iter(kwargs), "params")
                raise TypeError(f"{cls.__name__} takes no parameter {bad!r}; only rng")
            return
        valid = cls.Params.names()
        for key in kwargs:
            if key not in valid:
                raise TypeError(f"{cls.__name__}: unknown parameter {key!r}; valid: "
                                f"{', '.join([*valid, 'rng'])}")
        if params is None:
            params = cls.Params(**kwargs)
        elif not isinstance(params, cls.Params):
            raise TypeError(f"{cls.__name__}: params must be a {cls.Params.__name__}, got "
                            f"{type(params).__name__}")
        elif kwargs:
            params = params.replace(**kwargs)
        self.params = params
        self._configure(params)

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if cls.Params is not None and "__init__" not in cls.__dict__:
            cls.__signature__ = _signature(cls.Params)  # type: ignore[attr-defined]

    def __getattr__(self, name: str) -> Any:
        # Only called when normal lookup fails: expose the parameter fields.
        params = self.__dict__.get("params")
        if params is not None and name in params.__dataclass_fields__:
            return getattr(params, name)
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def _configure(self, params: TrackerParams) -> None:  # noqa: B027 (optional hook)
        """Build the tracker's parts from its validated ``params`` (called by ``__init__``)."""

    def init(self, frame: Any, boxes: Any) -> None:
        """Initialise on ``frame`` (H, W, 3) with one box per target, ``boxes`` (K, 4).

        An ``init`` that raises leaves the tracker uninitialised (``step`` refuses to run
        until an ``init`` succeeds), never half-set-up for the new boxes nor still on the
        state of a previous ``init``, whether the frame, the boxes or the tracker's own
        ``_init`` refused them.

        Parameters
        ----------
        frame : array_like of uint8, shape (H, W, 3)
            The first frame, RGB (:func:`check_frame`); its shape is the one every
            ``step`` frame must have.
        boxes : array_like of float, shape (K, 4) or (4,)
            Initial box [x, y, w, h] per target, in px, K >= 1 (:func:`check_boxes`);
            sets ``self.n_targets`` = K.

        Raises
        ------
        ValueError
            For a bad frame (:func:`check_frame`) or bad boxes (:func:`check_boxes`), and
            whatever the tracker's ``_init`` refuses (e.g. too many targets).
        """
        # Unset first: a refused init (a box outside the frame; SHM's 5 targets, DPS's
        # groups in _init) had left step running on the old state or failing with an
        # IndexError.
        self._frame_shape = None
        frame = check_frame(frame)
        boxes = check_boxes(boxes, frame.shape)
        self.n_targets = boxes.shape[0]
        self._init(frame, boxes)
        self._frame_shape = frame.shape

    def step(self, frame: Any) -> Estimate:
        """Advance one frame (H, W, 3) and return the estimate.

        Parameters
        ----------
        frame : array_like of uint8, shape (H, W, 3)
            The next frame, RGB, of the shape of the ``init`` frame (:func:`check_frame`).

        Returns
        -------
        Estimate
            ``boxes`` of shape (K, 4), [x, y, w, h] in px in the order of ``init``, each
            box moved (size unchanged) so that its centre lies inside the frame, in
            [0, W] x [0, H]; ``extras``, the tracker's diagnostics.

        Raises
        ------
        ValueError
            If ``init`` has not succeeded yet, or for a bad frame or one whose shape
            differs from the ``init`` frame's.
        """
        if self._frame_shape is None:
            raise ValueError(f"tracker {self.name!r}: call init() before step()")
        frame = check_frame(frame, self._frame_shape)
        est = self._step(frame)
        est.boxes = clip_boxes(est.boxes, self._frame_shape)
        return est

    @abstractmethod
    def _init(self, frame: NDArray[np.uint8], boxes: NDArray[np.float64]) -> None: ...

    @abstractmethod
    def _step(self, frame: NDArray[np.uint8]) -> Estimate: ...


#: The name the tracker modules subclass; ``trackers.Tracker`` is the protocol
#: (``trackers.protocol``) that any tracker, subclass or not, satisfies.
Tracker = BaseTracker


def _signature(params: type[TrackerParams]) -> inspect.Signature:
    """Constructor signature of a tracker with parameters ``params``: fields, then rng."""
    fields = [inspect.Parameter(n, inspect.Parameter.KEYWORD_ONLY, default=d)
              for n, d in params.defaults().items()]
    rng = inspect.Parameter("rng", inspect.Parameter.KEYWORD_ONLY, default=None)
    return inspect.Signature([*fields, rng])


def clip_boxes(boxes: NDArray[np.float64], frame_shape: tuple[int, ...]) -> NDArray[np.float64]:
    """Keep every box's centre inside the frame (sizes unchanged), shape (K, 4)."""
    return clip_centres(boxes, frame_shape[1], frame_shape[0])
