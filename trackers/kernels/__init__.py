"""Compiled (numba) kernels: the hot loops of the trackers, one call per frame or stage.

``histogram``: frame quantisation, batched kernel-weighted region histograms and
Bhattacharyya distances. ``meanshift``: batched kernel mean shift. ``sampling``: grouped
inverse-CDF resampling and distinct-state counts of particle sets. ``template``: masked
template matching of every object under every depth ordering.

Threads: the region-distance kernel runs in parallel over references and chunks of boxes
on ``numba.get_num_threads()`` threads (``numba.set_num_threads`` or the
``NUMBA_NUM_THREADS`` variable set it; the lab runs one thread per worker), with results
identical for any count. OpenMP's threads wait passively between calls unless the user
chose otherwise (``OMP_WAIT_POLICY``): measured on the 2-core machine, spinning threads
made a 2-thread call 1.4x slower than one thread as soon as another process held a core
(and up to 20x under heavy load), while passive ones match one thread there and keep the
1.8x gain on an idle machine.
"""

import os

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

__all__ = ["histogram", "meanshift", "sampling", "template"]
