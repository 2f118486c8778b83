"""Other libraries' trackers behind the protocol (:class:`trackers.Tracker`)."""

from trackers.adapters.opencv import OpenCVTracker, opencv, opencv_names

__all__ = ["OpenCVTracker", "opencv", "opencv_names"]
