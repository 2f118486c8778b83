"""Reference trackers of the DPS, KAMS and SHM papers, validated against scenegen scenes.

Use ``trackers.make(name, **params)`` to build one and ``trackers.track`` to run it over a
sequence; ``trackers.names()`` lists the names.
"""

from trackers.base import Estimate, Tracker
from trackers.registry import get_class, make, names
from trackers.run import TrackResult, track

__all__ = ["Estimate", "TrackResult", "Tracker", "get_class", "make", "names", "track"]
