"""The tracker protocol: what any tracker must offer to be run, scored and checked.

A tracker is any object with two methods::

    tracker.init(frame, boxes)        # frame (H, W, 3) uint8 RGB, boxes (K, 4) [x, y, w, h]
    estimate = tracker.step(frame)    # estimate.boxes: (K, 4), NaN rows where it has lost a target

Nothing else is required; ``trackers.track``, ``scenegen track --tracker module:factory``
and ``scenegen.testing.check_tracker`` discover the optional parts when present:

``estimate.extras``
    dict of per-frame diagnostics (arrays of a fixed shape), stacked over frames by
    ``trackers.track``.
``tracker.orderings``
    (L, K) depth orderings, for trackers that report ``order_prob`` in ``extras``.
``tracker.deterministic``
    bool, default True: the same ``rng`` seed gives the same boxes.
``tracker.handles_occlusion``
    bool, default False: the tracker claims to recover a target after a short full
    occlusion (the conformance suite checks it only then).

Our own trackers subclass :class:`trackers.base.BaseTracker`, which also validates frames
and boxes; a tracker does not have to.
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

__all__ = ["EstimateLike", "Tracker"]


@runtime_checkable
class EstimateLike(Protocol):
    """What ``step`` returns: anything with ``boxes``, array-like of shape (K, 4).

    A protocol: checked with ``isinstance``, never instantiated.

    Parameters
    ----------
    *args, **kwargs : Any
        None accepted: ``typing.Protocol`` refuses to instantiate a protocol (TypeError).

    Attributes
    ----------
    boxes : array_like of float, shape (K, 4)
        Estimated box [x, y, w, h] per target, in px; NaN rows where the tracker has lost
        a target.
    """

    boxes: Any


@runtime_checkable
class Tracker(Protocol):
    """A tracker: ``init(frame, boxes)`` on the first frame, then ``step(frame)``.

    ``isinstance(obj, trackers.Tracker)`` is True for any object with both methods (a
    tracker *class* too: ``trackers.track`` and ``scenegen track`` refuse a class, naming
    it).

    Parameters
    ----------
    *args, **kwargs : Any
        None accepted: ``typing.Protocol`` refuses to instantiate a protocol (TypeError).
    """

    def init(self, frame: Any, boxes: Any) -> None:
        """Start on ``frame`` (H, W, 3) with one box per target, ``boxes`` (K, 4).

        Parameters
        ----------
        frame : array_like of uint8, shape (H, W, 3)
            The first frame, RGB.
        boxes : array_like of float, shape (K, 4)
            Initial box [x, y, w, h] per target, in px.
        """

    def step(self, frame: Any) -> EstimateLike:
        """Advance one frame (H, W, 3); return an estimate whose ``boxes`` is (K, 4).

        Parameters
        ----------
        frame : array_like of uint8, shape (H, W, 3)
            The next frame, RGB, of the shape of the first.

        Returns
        -------
        EstimateLike
            Its ``boxes``, array-like of shape (K, 4): box [x, y, w, h] per target in px,
            in the order of ``init``, NaN rows where the tracker has lost a target.
        """
