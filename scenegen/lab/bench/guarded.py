"""Benchmark rows of guarded reads (:mod:`scenegen.io.guard`): what it costs to look at a
file not yet known to be sound in a child process under a deadline, against the same
work in this process.

Two checks are timed on a ``dps-synthetic`` sequence file, each on a fresh copy so that
no verdict is cached:

- the check that ``track``, ``evaluate``, ``export`` and ``preview`` run first
  (:func:`scenegen.io.validate.require_valid`: layout, shapes, digests; no pixel pass),
  in this process and in a guarded child;
- the metadata preflight of :func:`scenegen.io.read` (:func:`scenegen.io.guard.survey`),
  in this process, in a guarded child of a running fork server, and as the first guarded
  read of a new Python process (which starts the fork server: measured inside a
  subprocess, interpreter start-up and imports excluded).
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

from scenegen import presets
from scenegen.io import guard, write_scenario
from scenegen.io.validate import check_file
from scenegen.lab.bench.core import BenchRow, median_time
from scenegen.render.plan import plan

__all__ = ["FIRST_READ", "PRESET", "run"]

PRESET = "dps-synthetic"

# Run in a fresh interpreter: the first guarded read of the process, timed after imports.
FIRST_READ = """
import sys, time
from scenegen.io import guard
t0 = time.perf_counter()
guard.preflight(sys.argv[1])
print(time.perf_counter() - t0)
"""


class _Copies:
    """A new copy of ``src`` per call (a file version no cache has seen)."""

    def __init__(self, src: Path, folder: Path) -> None:
        self.src, self.folder, self.n = src, folder, 0

    def __call__(self) -> str:
        self.n += 1
        dst = self.folder / f"copy{self.n}.h5"
        shutil.copyfile(self.src, dst)
        return str(dst)


def _first_read(path: Path) -> float:
    out = subprocess.run(
        [sys.executable, "-c", FIRST_READ, str(path)],
        check=True, capture_output=True, text=True,
    )  # fmt: skip
    return float(out.stdout.strip().splitlines()[-1])


def _timed_on_copies(fn: Callable[[str], object], copies: _Copies, repeats: int) -> float:
    """Median seconds of ``fn(path)`` on fresh copies, the copying not timed."""
    paths: list[str] = []

    def once() -> None:
        fn(paths.pop())

    total = max(1, repeats) + 1  # one warm-up call
    paths += [copies() for _ in range(total)]
    return median_time(once, repeats)


def run(repeats: int = 5) -> list[BenchRow]:
    """Rows: the cost of the guard on the checks that readers and verbs run first.

    Parameters
    ----------
    repeats : int
        Timings per figure (each on a fresh copy of the file).

    Returns
    -------
    list of BenchRow
        Two groups. ``require_valid``'s check in this process (the baseline) and in a
        guarded child; the metadata survey of ``read()`` in this process (the baseline),
        in a guarded child of a running fork server, and as the first guarded read of a
        process. Ratios are baseline time / row time (below 1: slower than the baseline).
    """
    rows: list[BenchRow] = []
    with tempfile.TemporaryDirectory() as d:
        src = Path(d) / "src.h5"
        write_scenario(src, plan(presets.get(PRESET), 1), compression="gzip")
        mb = src.stat().st_size / 2**20
        copies = _Copies(src, Path(d))

        group = f"require_valid's check of {PRESET} seed 1 ({mb:.1f} MB)"
        base = "in this process (baseline)"
        t_in = _timed_on_copies(lambda p: check_file(p, check_pixels=False), copies, repeats)
        t_child = _timed_on_copies(
            lambda p: check_file(p, check_pixels=False, isolate=True), copies, repeats
        )
        rows.append(BenchRow(group, base, t_in, 1 / t_in, "files/s"))
        rows.append(
            BenchRow(
                group, "in a guarded child (running fork server)", t_child, 1 / t_child,
                "files/s", baseline=base, ratio=t_in / t_child,
            )
        )  # fmt: skip

        group = f"read()'s metadata preflight of {PRESET} seed 1 ({mb:.1f} MB)"
        base = "survey in this process, unguarded (baseline)"
        t_survey = _timed_on_copies(guard.survey, copies, repeats)

        def preflight(p: str) -> None:
            guard.clear_cache()
            guard.preflight(p)

        t_pre = _timed_on_copies(preflight, copies, repeats)
        firsts = sorted(_first_read(Path(copies())) for _ in range(max(1, repeats)))
        t_first = firsts[len(firsts) // 2]
        rows.append(BenchRow(group, base, t_survey, 1 / t_survey, "files/s"))
        for name, t in (
            ("preflight, a new file (running fork server)", t_pre),
            ("preflight, first of a process (starts the fork server)", t_first),
        ):
            rows.append(
                BenchRow(group, name, t, 1 / t, "files/s", baseline=base, ratio=t_survey / t)
            )
    return rows
