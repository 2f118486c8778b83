"""Other libraries' trackers behind the protocol (:class:`trackers.Tracker`)."""

from trackers.adapters.opencv import OpenCVTracker, cv2_seed, opencv, opencv_names

__all__ = ["OpenCVTracker", "cv2_seed", "opencv", "opencv_names"]
