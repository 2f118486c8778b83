"""Benchmark rows of ``scenegen dataset``: sequences/s on 1 and 2 local workers and Dask.

The family is ``kams`` (the four KAMS levels, 320x240) cut to :data:`FRAMES` frames,
:data:`COUNT` sequences in shards of :data:`SHARD`. Each variant builds the dataset into
a fresh folder once (these runs take seconds; repeats would multiply that). Two rates per
variant: end to end (the wall time of ``build_dataset``, worker start-up included) and
steady state (per worker, the shards after its first one over the time between its first
and last result, summed over workers: what a long run approaches). The goal, >= 1.8x
from 1 to 2 workers, is checked on the steady-state ratio; on a machine with other load
both ratios fall. A last row gives the largest peak resident memory of a worker.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path
from typing import Any

from scenegen.lab.bench.core import BenchRow

__all__ = ["COUNT", "FRAMES", "SHARD", "measure", "run"]

FRAMES = 60
COUNT = 24
SHARD = 2


def _steady(results: list[tuple[float, dict[str, Any]]]) -> float:
    by_pid: dict[int, list[tuple[float, int]]] = {}
    for t, res in results:
        by_pid.setdefault(int(res["pid"]), []).append((t, len(res["entries"])))
    rate = 0.0
    for items in by_pid.values():
        items.sort()
        if len(items) >= 2 and items[-1][0] > items[0][0]:
            rate += sum(n for _, n in items[1:]) / (items[-1][0] - items[0][0])
    return rate if rate > 0 else float("nan")  # no worker made two shards


def _inv(rate: float) -> float:
    return 1.0 / rate if rate > 0 else float("nan")


def measure(variant: str, folder: Path, **executor: Any) -> dict[str, float]:
    """Build the bench dataset once; its end-to-end and steady-state rates (sequences/min).

    Parameters
    ----------
    variant : str
        Name of the variant: the dataset is built into ``folder / variant``.
    folder : pathlib.Path
        Parent folder of the build (a fresh, temporary one).
    **executor : Any
        Passed to ``build_dataset`` (``jobs=``, ``scheduler=``).

    Returns
    -------
    dict of str to float
        ``"wall"``: the build's wall time (s); ``"rate"``: end-to-end sequences per
        minute; ``"steady"``: steady-state sequences per minute (NaN when no worker made
        two shards); ``"rss"``: the largest peak resident memory of a worker (MiB);
        ``"cpu"``: CPU seconds per sequence.
    """
    from scenegen.datasets import build_dataset

    results: list[tuple[float, dict[str, Any]]] = []
    t0 = time.perf_counter()
    build_dataset(
        "kams", folder / variant, count=COUNT, frames=FRAMES, shard_size=SHARD,
        on_shard=lambda res: results.append((time.perf_counter(), res)), **executor,
    )  # fmt: skip
    wall = time.perf_counter() - t0
    rss = max(float(r["peak_rss_mb"]) for _, r in results)
    cpu = sum(float(r["cpu_seconds"]) for _, r in results) / COUNT
    return {"wall": wall, "rate": 60 * COUNT / wall, "steady": 60 * _steady(results),
            "rss": rss, "cpu": cpu}  # fmt: skip


def run(repeats: int = 5) -> list[BenchRow]:
    """All rows of this module: one build per variant (1 and 2 local workers, Dask).

    Parameters
    ----------
    repeats : int, default 5
        Ignored: each variant is built once (a build takes seconds).

    Returns
    -------
    list of BenchRow
        End-to-end and steady-state rates (seq/min) of each variant, with ratios against
        one local worker; CPU time per sequence of each variant; the peak memory of a
        worker (MiB).
    """
    import distributed

    with tempfile.TemporaryDirectory() as d:
        folder = Path(d)
        one = measure("jobs1", folder, jobs=1)
        two = measure("jobs2", folder, jobs=2)
        with distributed.LocalCluster(
            n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None
        ) as cluster:
            dask = measure("dask", folder, scheduler=cluster.scheduler_address)
    group = f"dataset kams ({COUNT} x {FRAMES} frames 320x240, shards of {SHARD}, gzip)"
    rows = []
    for kind, key in (("end to end", "rate"), ("steady state", "steady")):
        base = f"1 local worker, {kind}"
        rows.append(BenchRow(group, base, 60 * _inv(one[key]), one[key], "seq/min"))
        for label, m in (("2 local workers", two), ("2-worker LocalCluster", dask)):
            ratio = m[key] / one[key]
            goal = ">= 1.8x 1 worker" if key == "steady" else ""
            rows.append(
                BenchRow(group, f"{label}, {kind}", 60 * _inv(m[key]), m[key], "seq/min",
                         baseline=base, ratio=ratio, goal=goal,
                         met=(ratio >= 1.8) if goal else None)
            )  # fmt: skip
    for label, m in (("1 local worker", one), ("2 local workers", two),
                     ("2-worker LocalCluster", dask)):  # fmt: skip
        rows.append(BenchRow(group, f"{label}, CPU time per sequence", m["cpu"],
                             60 / m["cpu"], "seq/min per core"))  # fmt: skip
    peak = max(one["rss"], two["rss"], dask["rss"])
    rows.append(BenchRow(group, "peak memory of a worker (MiB)", 0.0, peak, "MiB"))
    return rows
