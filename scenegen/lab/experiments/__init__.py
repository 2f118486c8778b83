"""The papers' experiments: seeded sweeps on local processes or Dask, with tables and figures.

``run_experiment(name, out_dir)`` runs S scenes x R seeded tracker runs per method, preset
(and swept value), storing
each finished run under ``out_dir/runs/`` so that an interrupted sweep resumes where it
stopped, then writes ``results.json`` (deterministic: sorted keys, no timestamps, floats
rounded to fixed decimals), ``table.md`` (the paper's table with its figures beside ours)
and PNG figures. Results do not depend on the executor or the number of workers.

From the command line::

    scenegen experiment dps-synthetic -o out/dps              # all local cores
    scenegen experiment dps-synthetic --jobs 4 -o out/dps     # rerun: resumes, same bytes
    dask scheduler &                                          # or an existing cluster
    dask worker tcp://HOST:8786 --nthreads 1 &                # on each machine
    scenegen experiment dps-synthetic --scheduler tcp://HOST:8786 -o out/dps

Dask workers need this package installed; each run generates its own sequence, so only
the small task key and the run's record travel over the network. Numba kernels run on one
thread per task, so one worker thread per core is the right setting. Local workers run a
scene's tasks in batches (the sequence is generated once and kept for the next batch);
``scenegen experiment all`` starts its workers once and hands them every experiment's tasks
at once, so they run the next experiment while this process summarises the previous one.

Examples
--------
>>> from scenegen.lab.experiments import run_experiment
>>> res = run_experiment("shm-depth", "out/shm", runs=2, quick=True)   # doctest: +SKIP
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from scenegen.datasets.build import (
    holds_benchmark_outputs,
    holds_experiment_outputs,
    holds_report,
    make_output_folder,
)
from scenegen.errors import ConfigError
from scenegen.io.atomic import describe_special_file, refuse_special_files
from scenegen.lab.experiments.definitions import EXPERIMENTS, PAPER, Experiment, Method, get, names
from scenegen.lab.experiments.outputs import (
    RECORDS,
    WRITTEN_BY,
    listing,
    sweep_of,
    write_results,
    written_by,
)
from scenegen.lab.experiments.runner import (
    Task,
    derive_seed,
    execute,
    plan_tasks,
    run_task,
)
from scenegen.lab.experiments.summary import summarize
from scenegen.lab.experiments.tables import render_table, verdict_counts
from scenegen.lab.experiments.why import WHY

__all__ = [
    "EXPERIMENTS",
    "PAPER",
    "RESULT_DECIMALS",
    "Experiment",
    "Method",
    "Task",
    "derive_seed",
    "get",
    "holds_experiment_outputs",
    "names",
    "refuse_special_outputs",
    "results_document",
    "run_experiment",
    "run_task",
    "verdict_counts",
]

RESULT_DECIMALS = 4
"""Decimals of every float in ``results.json``."""


def _round(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): _round(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_round(v) for v in x]
    if isinstance(x, float):
        return round(x, RESULT_DECIMALS) if x == x and abs(x) != float("inf") else None
    return x


def _write_text(path: Path, text: str) -> None:
    from scenegen.io.atomic import write_text

    write_text(path, text)


def results_document(exp: Experiment, records: list[dict[str, Any]]) -> dict[str, Any]:
    """The content of ``results.json`` for ``records`` (the runs of one sweep, in run order).

    Everything in it derives from the records: S, R, the base seed and the quick flag from
    their keys, the summary from their measures, and the ``records`` listing (every run
    file with its digest), so ``scenegen validate DIR`` can compute it again.

    Parameters
    ----------
    exp : Experiment
        The experiment the runs belong to.
    records : list of dict
        The run records of one sweep (non-empty), in run order, without digest.

    Returns
    -------
    dict
        ``experiment``, ``title``, ``runs``, ``scenes``, ``indicative`` (quick mode or
        fewer runs x scenes than the experiment's), ``seed``, ``quick``, ``presets``,
        ``sweep``, ``methods`` (those run), the summary's keys
        (:func:`~scenegen.lab.experiments.summary.summarize`), :data:`RECORDS`,
        :data:`WRITTEN_BY`, and ``overrides`` when the runs had any; floats rounded to
        :data:`RESULT_DECIMALS` decimals, NaN and inf as None.
    """
    keys = [r["key"] for r in records]
    r, s, seed, quick = sweep_of(keys)
    chosen = {k["method"] for k in keys}
    results: dict[str, Any] = {
        "experiment": exp.name,
        "title": exp.title,
        "runs": r,
        "scenes": s,
        "indicative": bool(quick or r * s < exp.runs * exp.scenes),
        "seed": seed,
        "quick": quick,
        "presets": list(exp.presets),
        "sweep": [[k, [float(v) for v in vals]] for k, vals in exp.sweep],
        "methods": [
            {"label": m.label, "slug": m.slug, "tracker": m.tracker, "params": m.param_dict()}
            for m in exp.methods
            if m.slug in chosen
        ],
        **summarize(exp, records),
        RECORDS: listing(records),
        WRITTEN_BY: written_by(),
    }
    over = keys[0].get("overrides")
    if over:
        results["overrides"] = dict(sorted(map(tuple, over)))
    return _round(json.loads(json.dumps(results)))


def _refuse_other_outputs(out: Path, name: str) -> None:
    """Refuse an output folder holding a dataset, another experiment's results, a
    benchmark's outputs, or a report of ``experiment all``: its figures and runs would be
    mixed with this one's.

    Raises
    ------
    ConfigError
        Naming the folder and what it holds.
    """
    if (out / "manifest.json").exists():
        raise ConfigError(f"-o {out}: is a dataset folder (manifest.json); choose another folder")
    if holds_report(out):
        raise ConfigError(
            f"-o {out}: holds a report of `scenegen experiment all`; choose another folder"
        )
    if holds_benchmark_outputs(out):
        raise ConfigError(
            f"-o {out}: holds the outputs of `scenegen benchmark`; choose another folder"
        )
    if describe_special_file(out / "results.json") is not None:
        return  # not a file: writing the results refuses it
    try:
        held = json.loads((out / "results.json").read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):
        return  # none, or damaged: the run rewrites it
    other = held.get("experiment") if isinstance(held, dict) else None
    if isinstance(other, str) and other != name:
        raise ConfigError(
            f"-o {out}: holds the results of experiment {other!r}; choose another folder"
        )


def refuse_special_outputs(out: Path) -> None:
    """Refuse, before any run, a FIFO, a device or a socket where an experiment writes a
    file into ``out`` (``results.json``, ``table.md``, a ``*.png`` figure): writing it would
    fail only after the runs, and reading it (``validate``) would wait.

    Parameters
    ----------
    out : pathlib.Path
        The experiment's output folder.

    Raises
    ------
    ConfigError
        ``"PATH: is not a regular file (a FIFO)"``.
    """
    refuse_special_files([out / "results.json", out / "table.md", *sorted(out.glob("*.png"))])


def run_experiment(
    name: str,
    out_dir: str | Path,
    *,
    runs: int | None = None,
    scenes: int | None = None,
    jobs: int | None = None,
    scheduler: str | None = None,
    seed: int = 0,
    quick: bool = False,
    methods: Iterable[str] | None = None,
    values: Iterable[float] | None = None,
    progress: bool = True,
    figures: bool = True,
    overrides: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Run experiment ``name`` and write its results into ``out_dir``.

    Parameters
    ----------
    name : str
        One of :func:`names` (``dps-synthetic``, ``dps-occlusion``, ``kams-accuracy``,
        ``kams-robustness``, ``shm-depth``, ``dps-dancers``).
    out_dir : str or Path
        Output folder: ``results.json``, ``table.md``, ``*.png`` and ``runs/``.
    runs : int, optional
        Tracker runs R per scene; default the experiment's.
    scenes : int, optional
        Scenes S per preset; default the experiment's. Fewer than the defaults marks the
        results "indicative".
    jobs : int, optional
        Local worker processes; default all cores. Ignored with ``scheduler``.
    scheduler : str, optional
        Address of a ``dask.distributed`` scheduler to run the tasks on.
    seed : int
        Base seed; every run's seeds derive from it and the run's key.
    quick : bool
        Scaled-down settings (fewer frames, particles and swept values) for tests and demos.
    methods : iterable of str, optional
        Method slugs or labels to run (default all).
    values : iterable of float, optional
        Values of the swept parameter to run (default all; in quick mode the quick ones).
    progress : bool
        Show a progress bar.
    figures : bool
        Write the PNG figures.
    overrides : dict, optional
        Tracker parameters set on every chosen method over its own (for example
        ``{"kernel": "box"}``). The runs keep the seeds of the default runs (paired with
        them), store the parameters in their records, and ``results.json`` lists them
        under ``"overrides"`` (absent without overrides).

    Returns
    -------
    dict
        The content of ``results.json``.

    Raises
    ------
    ConfigError
        Unknown experiment or method (listing the valid ones), bad runs/scenes/jobs/seed, an
        override a chosen method does not accept, an unreachable scheduler, an
        ``out_dir`` holding a dataset, a benchmark's outputs, another experiment's results
        or a report of ``scenegen experiment all``, or a FIFO, device or socket where a file
        is written (:func:`refuse_special_outputs`).
    """
    exp = get(name)
    if jobs is not None and jobs < 1:
        raise ConfigError(f"jobs must be >= 1, got {jobs}")
    r = exp.runs if runs is None else int(runs)
    s = exp.scenes if scenes is None else int(scenes)
    tasks = plan_tasks(exp, runs=r, scenes=s, seed=int(seed), quick=quick, methods=methods,
                       values=values, overrides=overrides)
    out = Path(out_dir)
    _refuse_other_outputs(out, exp.name)
    refuse_special_outputs(out)
    make_output_folder(out)
    records = execute(tasks, out / "runs", jobs=jobs, scheduler=scheduler, progress=progress)
    results = results_document(exp, records)
    write_results(out / "results.json", results)
    _write_text(out / "table.md", render_table(exp, results, WHY.get(exp.name, "")))
    if figures:
        from scenegen.lab.experiments.figures import write_figures

        write_figures(exp.name, results, records, out)
    return results
