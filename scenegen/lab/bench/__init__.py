"""``scenegen bench``: every benchmark row, measured side by side in one run.

Each module contributes ``run(repeats) -> list[BenchRow]``; figures are medians over
repeats, and every goal is checked against the row's own rate or its ratio to a baseline
measured in the same run (shared machines are noisy: absolute times vary, ratios less).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable

from scenegen.lab.bench.core import BenchRow, median_time

__all__ = ["MODULES", "BenchRow", "median_time", "run_all"]

# Modules that contribute rows, in the order they are printed.
MODULES = (
    "scenegen.lab.bench.generation",
    "scenegen.lab.bench.particle",
    "scenegen.lab.bench.stepshare",
    "scenegen.lab.bench.meanshift",
    "scenegen.lab.bench.shm",
    "scenegen.lab.bench.reliability",
    "scenegen.lab.bench.guarded",
    "scenegen.lab.bench.scaling",
    "scenegen.lab.bench.datasets",
)


def run_all(
    repeats: int = 5, *, only: str | None = None, log: Callable[[str], None] | None = None
) -> list[BenchRow]:
    """Run every module's rows (or those whose module name contains ``only``).

    Parameters
    ----------
    repeats : int, default 5
        Timings per figure, passed to each module's ``run``.
    only : str, optional
        Run only the modules of :data:`MODULES` whose name contains this substring
        (None or "": all of them).
    log : callable, optional
        Called with one progress line (``"bench: <module> ..."``) before each module.

    Returns
    -------
    list of BenchRow
        The rows of the modules run, in the order of :data:`MODULES`.
    """
    rows: list[BenchRow] = []
    for name in MODULES:
        if only and only not in name:
            continue
        if log is not None:
            log(f"bench: {name.rsplit('.', 1)[-1]} ...")
        rows += importlib.import_module(name).run(repeats)
    return rows


def format_table(rows: list[BenchRow]) -> str:
    """A Markdown table of the rows (as pasted in the README)."""
    lines = [
        "| group | variant | median | rate | vs baseline | goal | met |",
        "|---|---|---:|---:|---:|---|---|",
    ]
    for r in rows:
        ratio = f"{r.ratio:.2f}x" if r.baseline else ""
        met = "" if r.met is None else ("yes" if r.met else "NO")
        rate = f"{r.rate:.2f}" if r.unit == "exponent" else f"{r.rate:,.0f}"
        lines.append(
            f"| {r.group} | {r.name} | {r.seconds * 1e3:.3f} ms | {rate} {r.unit} "
            f"| {ratio} | {r.goal} | {met} |"
        )
    return "\n".join(lines)
