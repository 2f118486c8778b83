"""Reference trackers of the DPS, KAMS and SHM papers, validated against scenegen scenes.

Use ``trackers.make(name, **params)`` to build one and ``trackers.track`` to run it over a
sequence; ``trackers.names()`` lists the names. ``trackers.Tracker`` is the protocol any
tracker follows (``init(frame, boxes)``, ``step(frame) -> .boxes``), ours or not;
``trackers.adapters.opencv(name)`` puts OpenCV's trackers behind it.
"""

from trackers.base import BaseTracker, Estimate
from trackers.protocol import Tracker
from trackers.registry import get_class, make, names
from trackers.run import TrackResult, track

__all__ = [
    "BaseTracker",
    "Estimate",
    "TrackResult",
    "Tracker",
    "get_class",
    "make",
    "names",
    "track",
]
