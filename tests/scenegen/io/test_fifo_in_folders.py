"""A FIFO in place of any file of an output folder: one line, never a wait.

Every file of an experiment folder, a benchmark folder with kept tracks and a dataset
folder is replaced in turn by a FIFO; in a report folder, one file of each kind (the fast
suite: 11 of its 90 files) or every file (``slow``: 50-90 s on 2 cores).
``scenegen validate`` must name it in one line (exit 1) and the command that wrote the
folder, run again, must refuse it in one line (exit 2), both at once: opening a FIFO waits
for a writer that never comes.
Before this test, ``validate`` waited for ever on an experiment's ``table.md``, a
benchmark's pages and a report's ``index.html``, said "valid" for a FIFO figure, called a
FIFO "missing"; and the benchmark, run again, waited for ever on a FIFO in its kept tracks.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest

from scenegen.cli import main

pytestmark = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")

FAMILY = {
    "name": "one",
    "base": {"width": 64, "height": 48, "n_frames": 5, "entities": [
        {"name": "a", "role": "target", "position": [18, 20], "depth": 0,
         "appearance": {"shape": "ellipse", "size": [12, 12], "pattern": "sectors",
                        "colors": [[230, 30, 30], [30, 60, 230]]}}]},
    "count": 2,
}  # fmt: skip
EXPERIMENT = ["experiment", "shm-depth", "--runs", "1", "--scenes", "1", "--quick",
              "--method", "shm-fast", "--jobs", "1"]  # fmt: skip


def _files(folder: Path) -> list[Path]:
    return sorted(p.relative_to(folder) for p in folder.rglob("*") if p.is_file())


def _kind(rel: Path) -> tuple[str, ...]:
    """A report file's kind: its path with the experiment's name left out, and a run
    record's name too (every experiment folder is read by the same code)."""
    parts = rel.parts
    if parts[0] != "experiments":
        return parts
    rest = parts[2:]
    return ("experiments", "runs", rel.suffix) if rest[0] == "runs" else ("experiments", *rest)


def _one_of_each_kind(names: list[Path]) -> list[Path]:
    first: dict[tuple[str, ...], Path] = {}
    for rel in names:
        first.setdefault(_kind(rel), rel)
    return list(first.values())


def _each_file_a_fifo(
    src: Path, work: Path, again: list[str], capsys, deadline, names: list[Path] | None = None
) -> int:
    """Replace each file of ``src`` (or each of ``names``; in a copy at ``work``) by a FIFO
    in turn; validate and the command ``again`` (``-o work`` appended) must each give one
    line naming it."""
    names = _files(src) if names is None else names
    for rel in names:
        shutil.rmtree(work, ignore_errors=True)
        shutil.copytree(src, work)
        fifo = work / rel
        fifo.unlink()
        os.mkfifo(fifo)
        capsys.readouterr()
        for argv, code in ((["validate", str(work)], 1), ([*again, "-o", str(work)], 2)):
            with deadline(60):
                got = main(argv)
            err = capsys.readouterr().err.splitlines()
            assert (got, len(err)) == (code, 1), (rel, argv[0], err)
            assert f"{fifo}: is not a regular file (a FIFO)" in err[0], (rel, argv[0], err)
        assert fifo.is_fifo(), rel  # refused, not replaced
    return len(names)


def test_every_file_of_an_experiment_folder(tmp_path, capsys, deadline):
    src = tmp_path / "exp"
    assert main([*EXPERIMENT, "-o", str(src)]) == 0
    n = _each_file_a_fifo(src, tmp_path / "w", EXPERIMENT, capsys, deadline)
    assert n == 5  # results.json, table.md, a figure, two run records


def test_every_file_of_a_benchmark_folder_and_its_dataset(tmp_path, capsys, deadline):
    family = tmp_path / "family.json"
    family.write_text(json.dumps(FAMILY))
    data = tmp_path / "ds"
    assert main(["dataset", str(family), "-o", str(data), "--jobs", "1"]) == 0
    bench = ["benchmark", str(data), "--tracker", "kalman", "--jobs", "1", "--keep-tracks"]
    src = tmp_path / "bench"
    assert main([*bench, "-o", str(src)]) == 0
    n = _each_file_a_fifo(src, tmp_path / "w", bench, capsys, deadline)
    assert n == 14 and any(p.parts[0] == "trackeval" for p in _files(src))
    n = _each_file_a_fifo(data, tmp_path / "w", ["dataset", str(family), "--jobs", "1"],
                          capsys, deadline)  # fmt: skip
    assert n == 2  # manifest.json and a shard


REPORT = ["experiment", "all", "--runs", "1", "--scenes", "1", "--quick", "--jobs", "1"]


@pytest.fixture(scope="module")
def report(tmp_path_factory) -> Path:
    src = tmp_path_factory.mktemp("report") / "report"
    assert main([*REPORT, "-o", str(src)]) == 0
    return src


def test_one_file_of_each_kind_of_a_report_folder(report, tmp_path, capsys, deadline):
    names = _one_of_each_kind(_files(report))
    kinds = {"/".join(_kind(rel)) for rel in names}
    # the index, the report's results, and each experiment's results, table, figures
    # (five names among the six experiments) and run records
    assert {"index.html", "results.json", "experiments/results.json", "experiments/table.md",
            "experiments/runs/.json", "experiments/ordering_probability.png",
            "experiments/centre_error.png"} <= kinds, kinds  # fmt: skip
    assert len(names) == 11, names
    _each_file_a_fifo(report, tmp_path / "w", REPORT, capsys, deadline, names)


@pytest.mark.slow
def test_every_file_of_a_report_folder(report, tmp_path, capsys, deadline):
    n = _each_file_a_fifo(report, tmp_path / "w", REPORT, capsys, deadline)
    assert n > 80
