"""Compiled (numba) kernels: the hot loops of the trackers, one call per frame or stage.

``histogram``: batched kernel-weighted region histograms and Bhattacharyya distances (the
entry points and the choice of path), re-exporting ``quantize`` (frame quantisation) and
``profiles`` (kernel profiles and their fixed-point weights); ``direct`` and ``integral``:
the two evaluation paths. ``meanshift``: batched kernel mean shift. ``sampling``: grouped
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

Numba's cache: ``numba_cache.drop_stale`` runs here, before any kernel loads, so that a
kernel compiled with another module's kernel inside it recompiles when that module
changes (numba keys a cache entry on its own file only).
"""

import os
from pathlib import Path

from trackers.kernels.numba_cache import drop_stale

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
drop_stale(Path(__file__).parent)

__all__ = [
    "direct",
    "histogram",
    "integral",
    "meanshift",
    "numba_cache",
    "profiles",
    "quantize",
    "sampling",
    "template",
]
