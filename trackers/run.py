"""Running a tracker over a whole sequence.

Works with any object that follows the protocol (:class:`trackers.Tracker`): only
``init(frame, boxes)`` and ``step(frame) -> estimate with .boxes`` are used; an
estimate's ``extras`` (a dict of per-frame arrays) is collected when present.
"""

from __future__ import annotations

from collections.abc import Sequence as SequenceABC
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from trackers.base import box_array
from trackers.protocol import Tracker

__all__ = ["TrackResult", "estimate_boxes", "track"]


@dataclass
class TrackResult:
    """The output of ``track``.

    Attributes
    ----------
    boxes : ndarray of shape (T, K, 4)
        Estimated boxes; frame 0 holds the initial boxes.
    extras : dict of str to ndarray
        Per-frame diagnostics stacked over frames, shape (T, ...), one entry per key any
        step gave. A key first given at frame t0 is filled with NaN (floats; 0 for other
        dtypes) at frames 0 to t0 − 1 (frame 0: the tracker reports nothing before its
        first step), and must then be given, with the same shape, at every later frame.
        Empty for a tracker whose estimates have no ``extras``.
    """

    boxes: NDArray[np.float64]
    extras: dict[str, NDArray[Any]] = field(default_factory=dict)


def _label(tracker: Any) -> str:
    return type(tracker).__name__


def estimate_boxes(tracker: Any, estimate: Any, n_targets: int, frame: int) -> NDArray[np.float64]:
    """The ``boxes`` of what ``tracker.step`` returned, checked: float64 (K, 4).

    A row must be finite with w, h >= 0, or all NaN (a lost target).

    Parameters
    ----------
    tracker : Any
        The tracker that made ``estimate`` (its class name goes into the messages).
    estimate : Any
        What ``tracker.step`` returned: an object with ``boxes``.
    n_targets : int
        K, the number of initial boxes.
    frame : int
        Index of the frame stepped (for the messages).

    Returns
    -------
    ndarray of float64, shape (K, 4)
        ``estimate.boxes`` [x, y, w, h] in px (no copy when already float64).

    Raises
    ------
    ValueError
        Naming the tracker, the frame and what is wrong (no ``boxes``, wrong shape,
        infinite values, a partly NaN row, a negative size).
    """
    if not hasattr(estimate, "boxes"):
        raise ValueError(
            f"{_label(tracker)}.step() at frame {frame} returned {type(estimate).__name__}, "
            "which has no .boxes (the protocol: step(frame) -> estimate with .boxes (K, 4))"
        )
    try:
        boxes = np.asarray(estimate.boxes, dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise ValueError(
            f"{_label(tracker)}.step() at frame {frame}: .boxes is not numeric: {err}"
        ) from None
    if boxes.shape != (n_targets, 4):
        raise ValueError(
            f"{_label(tracker)}.step() at frame {frame}: .boxes has shape {boxes.shape}, "
            f"expected ({n_targets}, 4) (one [x, y, w, h] row per initial box)"
        )
    if np.isinf(boxes).any():
        raise ValueError(
            f"{_label(tracker)}.step() at frame {frame}: .boxes holds inf "
            "(the protocol: finite, or NaN for a lost target)"
        )
    nan = np.isnan(boxes)
    bad = (nan.any(axis=1) & ~nan.all(axis=1)) | (boxes[:, 2:] < 0).any(axis=1)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"{_label(tracker)}.step() at frame {frame}: box {j} is {boxes[j].tolist()} "
            "(the protocol: a row is finite with w, h >= 0, or all NaN for a lost target)"
        )
    return boxes


def _stack_extras(tracker: Any, per_frame: list[dict[str, Any]], n: int) -> dict[str, Any]:
    extras: dict[str, NDArray[Any]] = {}
    # Every key, in the order first given; one given from frame t0 on is kept, filled for
    # the frames before it as frame 0 is (it was dropped when t0 > 1).
    keys = dict.fromkeys(key for frame_extras in per_frame for key in frame_extras)
    for key in keys:
        t0 = next(t for t in range(1, n) if key in per_frame[t])
        first = np.asarray(per_frame[t0][key])
        is_float = first.dtype.kind == "f"
        stacked = np.empty((n, *first.shape), dtype=np.float64 if is_float else first.dtype)
        stacked[:t0] = np.nan if is_float else 0
        for t in range(t0, n):
            if key not in per_frame[t]:
                raise ValueError(
                    f"{_label(tracker)}.step() at frame {t}: extras lacks {key!r}, "
                    f"given at frame {t0} (a key, once given, must be given every later frame)"
                )
            value = np.asarray(per_frame[t][key])
            if value.shape != first.shape:
                raise ValueError(
                    f"{_label(tracker)}.step() at frame {t}: extras[{key!r}] has shape "
                    f"{value.shape}, {first.shape} at frame {t0}"
                )
            stacked[t] = value
        extras[key] = stacked
    return extras


def track(
    tracker: Tracker,
    frames: SequenceABC[Any] | NDArray[np.uint8],
    init_boxes: Any,
    *,
    progress: Any = None,
) -> TrackResult:
    """Run ``tracker`` over ``frames`` (T, H, W, 3), initialised with ``init_boxes`` (K, 4).

    ``tracker`` is anything with ``init(frame, boxes)`` and ``step(frame)`` returning an
    object with ``boxes`` (K, 4) (:class:`trackers.Tracker`). ``frames`` may be a lazy
    array (anything indexable with a length); frames are read one at a time.
    ``progress``, if given, is called with the number of frames done.

    Parameters
    ----------
    tracker : Tracker
        An instance following the protocol (:class:`trackers.protocol.Tracker`).
    frames : sequence of ndarray of uint8 or ndarray of uint8, shape (T, H, W, 3)
        The frames, T >= 1; ``frames[0]`` initialises the tracker.
    init_boxes : array_like of float, shape (K, 4)
        The boxes [x, y, w, h] of the K targets on frame 0, in px (one box (4,) is one
        target).
    progress : callable or None, optional
        Called as ``progress(t)`` after step t, t = 1, ..., T - 1; None (the default):
        not called.

    Returns
    -------
    TrackResult
        ``boxes`` (T, K, 4), ``init_boxes`` at frame 0, and the stacked ``extras``: every
        key any step gave, NaN (0 for a non-float dtype) at the frames before its first
        (:class:`TrackResult`).

    Raises
    ------
    ValueError
        If ``frames`` is empty, ``init_boxes`` is not (K, 4), or an estimate breaks the
        protocol (naming the frame): its ``boxes`` are wrong, or its ``extras`` lack a key
        given at an earlier frame or change a key's shape (naming the key).
    TypeError
        If ``tracker`` lacks ``init`` or ``step``, or is a class rather than an instance,
        or ``frames`` has no length (a generator: pass ``list(frames)``).

    Examples
    --------
    >>> import numpy as np
    >>> from trackers.base import Estimate
    >>> from trackers.run import track
    >>> class Still:  # the smallest tracker: never moves its boxes
    ...     def init(self, frame, boxes):
    ...         self.boxes = boxes
    ...     def step(self, frame):
    ...         return Estimate(self.boxes)
    >>> frames = np.zeros((3, 20, 30, 3), np.uint8)
    >>> result = track(Still(), frames, [2.0, 3.0, 8.0, 6.0])
    >>> result.boxes.shape
    (3, 1, 4)
    """
    if isinstance(tracker, type):  # a class has init and step too, unbound
        raise TypeError(
            f"{tracker.__name__} is a class, not a tracker: pass an instance, "
            f"{tracker.__name__}(...)"
        )
    if not isinstance(tracker, Tracker):
        missing = [m for m in ("init", "step") if not callable(getattr(tracker, m, None))]
        raise TypeError(
            f"{_label(tracker)} is not a tracker: it has no {' or '.join(missing)} method "
            "(the protocol: init(frame, boxes), step(frame) -> estimate with .boxes)"
        )
    if not (hasattr(frames, "__len__") and hasattr(frames, "__getitem__")):
        # len() said "object of type 'generator' has no len()", naming no argument.
        raise TypeError(
            f"frames must be an array (T, H, W, 3) or a sequence of frames with a length, "
            f"got {type(frames).__name__} (for a generator or iterator: list(frames))"
        )
    n = len(frames)
    if n < 1:
        raise ValueError("frames is empty: need at least one frame")
    start = box_array(init_boxes, "init_boxes")
    k = start.shape[0]
    tracker.init(frames[0], start.copy())
    boxes = np.empty((n, k, 4), dtype=np.float64)
    boxes[0] = start
    per_frame: list[dict[str, Any]] = [{}]
    for t in range(1, n):
        est = tracker.step(frames[t])
        boxes[t] = estimate_boxes(tracker, est, k, t)
        extras = getattr(est, "extras", None)
        # Copied now: a tracker may hand back the same buffer every frame.
        per_frame.append(
            {k: np.array(v, copy=True) for k, v in extras.items()}
            if isinstance(extras, dict)
            else {}
        )
        if progress is not None:
            progress(t)
    return TrackResult(boxes=boxes, extras=_stack_extras(tracker, per_frame, n))
