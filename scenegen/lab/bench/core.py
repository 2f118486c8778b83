"""Timing helpers shared by every benchmark row.

Machines are shared and noisy: every figure is the median over repeats, and speed goals
are stated as ratios against a baseline measured in the same run.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field

__all__ = ["BenchRow", "median_time"]


@dataclass
class BenchRow:
    """One line of the benchmark table.

    Attributes
    ----------
    group : str
        What is measured (e.g. ``"likelihood 7x300 @360x288"``).
    name : str
        The variant (e.g. ``"numba kernel"``).
    seconds : float
        Median wall time of one unit of work, in seconds.
    rate : float
        Units per second (1 / seconds, times the units in one call).
    unit : str
        What ``rate`` counts (``"frames/s"``, ``"calls/s"``).
    baseline : str
        The ``name`` in the same group that ratios are taken against ("" for none).
    ratio : float
        ``baseline seconds / seconds``: how many times faster than the baseline.
    goal : str
        The goal in words ("" if none), e.g. ``">= 10x baseline"``.
    met : bool | None
        Whether the goal is met (None if no goal).
    params : dict
        What the row was measured at, for rows that sweep a parameter (e.g.
        ``{"axis": "n", "x": 300, "kernel": "box"}``).
    """

    group: str
    name: str
    seconds: float
    rate: float
    unit: str
    baseline: str = ""
    ratio: float = 1.0
    goal: str = ""
    met: bool | None = None
    params: dict[str, object] = field(default_factory=dict)

    def to_dict(self) -> dict[str, object]:
        """The row as a dict (``dataclasses.asdict``).

        Returns
        -------
        dict of str to object
            One key per attribute, in field order (``group`` ... ``params``); ``params``
            is a copy of the row's dict.
        """
        return asdict(self)


def median_time(fn: Callable[[], object], repeats: int, *, warmup: int = 1) -> float:
    """Median wall time of ``fn()`` over ``repeats`` calls, after ``warmup`` untimed calls.

    Parameters
    ----------
    fn : callable
        The work to time, called with no arguments; its result is discarded.
    repeats : int
        Number of timed calls (at least one is made whatever the value).
    warmup : int, default 1
        Untimed calls made first (compilation, caches).

    Returns
    -------
    float
        The median of the timed calls, in seconds (``time.perf_counter``); the mean of
        the two middle ones for an even count.
    """
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(max(1, repeats)):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    times.sort()
    n = len(times)
    return times[n // 2] if n % 2 else 0.5 * (times[n // 2 - 1] + times[n // 2])
