"""Running a tracker over a whole sequence."""

from __future__ import annotations

from collections.abc import Sequence as SequenceABC
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from trackers.base import Tracker

__all__ = ["TrackResult", "track"]


@dataclass
class TrackResult:
    """The output of ``track``.

    Attributes
    ----------
    boxes : ndarray of shape (T, K, 4)
        Estimated boxes; frame 0 holds the initial boxes.
    extras : dict of str to ndarray
        Per-frame diagnostics stacked over frames, shape (T, ...); frame 0 repeats frame 1's
        shape with NaN (floats) where the tracker reports nothing before its first step.
    """

    boxes: NDArray[np.float64]
    extras: dict[str, NDArray[Any]] = field(default_factory=dict)


def track(
    tracker: Tracker,
    frames: SequenceABC[Any] | NDArray[np.uint8],
    init_boxes: Any,
    *,
    progress: Any = None,
) -> TrackResult:
    """Run ``tracker`` over ``frames`` (T, H, W, 3), initialised with ``init_boxes`` (K, 4).

    ``frames`` may be a lazy array (anything indexable with a length); frames are read one
    at a time. ``progress``, if given, is called with the number of frames done.
    """
    n = len(frames)
    if n < 1:
        raise ValueError("frames is empty: need at least one frame")
    tracker.init(frames[0], init_boxes)
    k = tracker.n_targets
    boxes = np.empty((n, k, 4), dtype=np.float64)
    boxes[0] = np.asarray(init_boxes, dtype=np.float64).reshape(k, 4)
    per_frame: list[dict[str, Any]] = [{}]
    for t in range(1, n):
        est = tracker.step(frames[t])
        boxes[t] = est.boxes
        per_frame.append(est.extras)
        if progress is not None:
            progress(t)
    extras: dict[str, NDArray[Any]] = {}
    keys = per_frame[1].keys() if n > 1 else ()
    for key in keys:
        first = np.asarray(per_frame[1][key])
        stacked = np.empty(
            (n, *first.shape), dtype=first.dtype if first.dtype.kind != "f" else np.float64
        )
        if first.dtype.kind == "f":
            stacked[0] = np.nan
        else:
            stacked[0] = 0
        for t in range(1, n):
            stacked[t] = np.asarray(per_frame[t][key])
        extras[key] = stacked
    return TrackResult(boxes=boxes, extras=extras)
