"""Compiled (numba) kernels: the hot loops of the trackers, one call per frame.

``histogram``: frame quantisation, batched kernel-weighted region histograms and
Bhattacharyya distances. ``meanshift``: batched kernel mean shift.
"""

__all__ = ["histogram", "meanshift"]
