"""Compiled (numba) kernels: the hot loops of the trackers, one call per frame or stage.

``histogram``: frame quantisation, batched kernel-weighted region histograms and
Bhattacharyya distances. ``meanshift``: batched kernel mean shift. ``sampling``: grouped
inverse-CDF resampling and distinct-state counts of particle sets. ``template``: masked
template matching of every object under every depth ordering.
"""

__all__ = ["histogram", "meanshift", "sampling", "template"]
