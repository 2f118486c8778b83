"""The one bridge from a sequence to a tracker: which targets, how it runs, what is recorded.

``scenegen track``, the experiments and fixture regeneration all go through :func:`run`,
so the tracked targets (those present at frame 0, :meth:`Sequence.initial_targets`), the
initial boxes and the recorded result are decided here and nowhere else.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from scenegen.errors import ConfigError, DataError
from scenegen.io import TrackerResult

__all__ = ["Run", "run", "run_tracker"]


@dataclass(frozen=True)
class Run:
    """A tracker run over a sequence.

    Attributes
    ----------
    result : TrackerResult
        What a result file holds (boxes (T, M, 4) float32, target ids, SHM orderings).
    targets : ndarray of shape (M,)
        Indices into the sequence's entities of the tracked targets, in result order.
    extras : dict of str to ndarray
        The tracker's per-frame diagnostics, shape (T, ...) (see ``trackers.track``).
    tracker : object
        The tracker after the run (for attributes such as ``orderings``).
    """

    result: TrackerResult
    targets: NDArray[np.intp]
    extras: dict[str, NDArray[Any]] = field(default_factory=dict)
    tracker: Any = None


def run(
    seq: Any,
    name: str,
    params: dict[str, Any] | None = None,
    seed: int = 0,
    *,
    progress: Callable[[int], None] | None = None,
    single_thread: bool = False,
) -> Run:
    """Track the targets of ``seq`` present at frame 0 with tracker ``name``.

    Parameters
    ----------
    seq : Sequence
        The sequence (frames may be lazy).
    name : str
        A tracker name (``trackers.names()``).
    params : dict, optional
        Tracker parameters (``trackers.make(name, **params)``).
    seed : int
        The tracker's ``rng``.
    progress : callable, optional
        Called with the number of frames done.
    single_thread : bool
        Run compiled kernels on one thread (what experiment workers do), restoring the
        thread count afterwards.

    Raises
    ------
    DataError
        If no target is present at frame 0, or the file is damaged.
    ConfigError
        If the tracker rejects its parameters or the scene (a ``ValueError``).
    """
    import numba

    import trackers

    params = dict(params or {})
    targets = seq.initial_targets(0)
    if targets.size == 0:
        raise DataError(f"sequence {seq.name!r} has no target present at frame 0")
    init = seq.init_boxes(0)
    previous = numba.get_num_threads()
    if single_thread:
        numba.set_num_threads(1)
    try:
        tracker = trackers.make(name, rng=seed, **params)
        out = trackers.track(tracker, seq.frames, init, progress=progress)
    except DataError:
        raise  # a damaged file (DataError is a ValueError): exit 1, not 2
    except ValueError as err:
        raise ConfigError(str(err)) from None
    finally:
        numba.set_num_threads(previous)
    orderings = getattr(tracker, "orderings", None)
    order_prob = out.extras.get("order_prob")
    if order_prob is not None:
        order_prob = order_prob.copy()
        # Frame 0 is the initialisation: every ordering equally likely.
        order_prob[0] = 1.0 / order_prob.shape[1]
    result = TrackerResult(
        tracker=name,
        params=params,
        seed=seed,
        sequence=seq.name,
        target_ids=seq.entities.id[targets],
        boxes=out.boxes.astype(np.float32),
        orderings=None if orderings is None else np.asarray(orderings, dtype=np.int16),
        order_prob=None if order_prob is None else order_prob.astype(np.float32),
    )
    return Run(result=result, targets=targets, extras=out.extras, tracker=tracker)


def run_tracker(
    seq: Any,
    name: str,
    params: dict[str, Any] | None = None,
    seed: int = 0,
    progress: Callable[[int], None] | None = None,
) -> TrackerResult:
    """:func:`run`, returning only the :class:`~scenegen.io.TrackerResult`."""
    return run(seq, name, params, seed, progress=progress).result
