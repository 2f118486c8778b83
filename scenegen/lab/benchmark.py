"""Benchmarking trackers over a dataset: per-sequence scores, a leaderboard, difficulty curves.

Every (tracker, sequence) pair is one task. The worker reads the sequence lazily from its
shard, runs the tracker through :func:`scenegen.lab.run.run` (the one bridge, compiled
kernels on one thread) with a seed derived from (tracker, parameters, sequence seed), and
scores it with :func:`scenegen.evaluation.evaluate`. Scores are rounded to fixed decimals
and stored as one sealed JSON file per pair under ``OUT/runs/TRACKER/NNNNN.json``
(atomically), so a rerun skips finished pairs, and the results are the same whichever
executor ran them.

``OUT`` then holds ``scores.csv`` (one row per tracker and sequence, with the sequence's
parameters), ``results.json`` (sealed: leaderboard, per-axis curves, every score and the
listing of the run files it was computed from), ``leaderboard.md``, one PNG per metric
and difficulty axis (``curve-METRIC-NN-AXIS.png``: the metric's mean per axis value, one
line per tracker) and ``index.html``. Everything but the PNGs is a function of the run
records and the dataset's description (:func:`results_document`, :func:`texts`), which is
how ``scenegen validate OUT`` checks the folder
(:func:`scenegen.lab.benchmark_outputs.check_benchmark`).

Metrics (per sequence, from :func:`scenegen.evaluation.evaluate`): OTB ``auc`` and
``precision_20`` (the mean over the sequence's targets), ``success`` and ``recovery`` (% of
targets tracked in every frame / tracked again at the end, DPS §3), ``tracked`` (% of
frames), ``mean_iou``; on sequences with several targets also the multi-target metrics
``mota``, ``idf1`` and ``hota`` (TrackEval's definitions, :mod:`scenegen.evaluation.mot`).
"""

from __future__ import annotations

import csv
import html
import io
import json
import math
import re
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from scenegen.errors import ConfigError, DataError
from scenegen.io.sealed import SEAL, content_digest, seal, write_sealed_json
from scenegen.lab.experiments.runner import _round, derive_seed

__all__ = [
    "METRICS",
    "NONE_SCORED",
    "BenchTask",
    "curves",
    "dataset_meta",
    "figure_list",
    "leaderboard",
    "plan_benchmark",
    "results_document",
    "run_benchmark",
    "run_file",
    "run_pair",
    "run_pair_tracks",
    "scored",
    "texts",
    "write_outputs",
]

METRICS: dict[str, str] = {
    "auc": "OTB success AUC",
    "precision_20": "precision @ 20 px",
    "success": "success (% targets)",
    "recovery": "recovery (% targets)",
    "tracked": "tracked (% frames)",
    "mean_iou": "mean IoU",
    "mota": "MOTA",
    "idf1": "IDF1",
    "hota": "HOTA",
}
"""Leaderboard columns and their labels, in order (absent metrics are left out)."""

CI_SEED = 0
"""Seed of the leaderboard's bootstrap intervals (the same for every tracker and metric)."""

MULTI_TARGET = ("mota", "idf1", "hota")
"""Metrics reported only on sequences with several targets."""

COMBINED: dict[str, str] = {
    "mota_combined": "MOTA (combined)",
    "idf1_combined": "IDF1 (combined)",
    "hota_combined": "HOTA (combined)",
}
"""Leaderboard columns of the multi-target sequences taken as one, as TrackEval's
``COMBINED_SEQ`` (their counts added up, :func:`scenegen.evaluation.mot.combine`)."""

_CURVE_METRICS = ("auc", "precision_20", "success", "recovery", "mota", "idf1", "hota")
_MAX_LEVELS = 8  # a numeric axis with more distinct values is binned into quantiles
_BINS = 6


@dataclass(frozen=True)
class BenchTask:
    """One tracker on one sequence of a dataset.

    Attributes
    ----------
    root : str
        The dataset folder.
    index : int
        The sequence's index in the dataset.
    name : str
        Sequence name in its shard.
    file : str
        Shard file name.
    seed : int
        The sequence's seed.
    frames_digest : str
        The manifest's digest of its frames (a changed dataset invalidates stored runs).
    tracker : str
        A tracker name or a user's factory spec.
    params : tuple of (str, value)
        Tracker parameters (without ``rng``), sorted.
    sequence_params : str
        The sequence's parameters in the manifest (its axis values), as sorted JSON. Not
        part of the key: the record carries them so that the results need only the records.
    """

    root: str
    index: int
    name: str
    file: str
    seed: int
    frames_digest: str
    tracker: str
    params: tuple[tuple[str, Any], ...]
    sequence_params: str = "{}"

    def tracker_seed(self) -> int:
        """Seed of the tracker's random stream on this sequence.

        Derived (:func:`scenegen.lab.experiments.runner.derive_seed`) from ``"benchmark"``,
        the tracker, its parameters as sorted JSON and the sequence's seed: the same for
        every run of the pair, whatever the dataset folder or the sequence's position.

        Returns
        -------
        int
            A seed in [0, 2**63).
        """
        return derive_seed("benchmark", self.tracker, json.dumps(dict(self.params),
                           sort_keys=True), self.seed)  # fmt: skip

    def filename(self) -> str:
        """The pair's record file, relative to the output folder (:func:`run_file`).

        Returns
        -------
        str
            ``"runs/TRACKER/NNNNN.json"``, ``NNNNN`` the sequence's index.
        """
        return run_file(self.tracker, self.index)

    def key(self) -> dict[str, Any]:
        """What identifies the pair's record: a stored record of another key is stale.

        Returns
        -------
        dict of str to object
            ``index``, ``name``, ``file``, ``seed``, ``frames_digest``, ``tracker`` and
            ``params`` (a dict), as JSON types with floats rounded to 6 decimals (NaN and
            infinities as None); without ``root`` and ``sequence_params``.
        """
        d = asdict(self)
        del d["root"], d["sequence_params"]
        d["params"] = dict(self.params)
        return _round(d)


def run_file(tracker: str, index: int) -> str:
    """The record file of ``tracker`` on sequence ``index``, relative to the output folder
    (a ``path/to/file.py:make`` factory by its file name: ``runs/file.py_make/``).

    Parameters
    ----------
    tracker : str
        A registered tracker name or a user's ``MODULE:FACTORY`` / ``path/file.py:FACTORY``
        (:func:`scenegen.lab.run.tracker_label`); characters other than letters, digits,
        ``.``, ``_`` and ``-`` become ``_``.
    index : int
        The sequence's index in the dataset.

    Returns
    -------
    str
        ``"runs/TRACKER/NNNNN.json"`` (index zero-padded to five digits).

    Examples
    --------
    >>> run_file("dps", 7)
    'runs/dps/00007.json'
    """
    from scenegen.lab.run import tracker_label

    return f"runs/{_slug(tracker_label(tracker))}/{index:05d}.json"


def _slug(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]+", "_", name)


def run_pair(task: BenchTask) -> dict[str, Any]:
    """Run one tracker on one sequence and score it (a JSON-ready record, floats rounded).

    Parameters
    ----------
    task : BenchTask
        The tracker, its parameters and the sequence (read lazily from its shard).

    Returns
    -------
    dict
        ``key`` (:meth:`BenchTask.key`), ``tracker_seed``, ``targets`` (count),
        ``n_frames``, ``scores`` (one value or None per metric of :data:`METRICS`; every
        one None, and ``targets`` 0, when no target is present at frame 0),
        ``sequence_params`` and ``deterministic``; on a sequence with several targets
        also ``mot_counts`` (:func:`scenegen.evaluation.mot.mot_counts`, floats rounded).
    """
    return run_pair_tracks(task)[0]


def run_pair_tracks(task: BenchTask) -> tuple[dict[str, Any], Any]:
    """:func:`run_pair`, with the tracker's result (what ``--keep-tracks`` writes).

    Parameters
    ----------
    task : BenchTask
        The tracker, its parameters and the sequence (read lazily from its shard).

    Returns
    -------
    record : dict
        :func:`run_pair`'s record.
    result : scenegen.io.TrackerResult or None
        The tracker's boxes (``boxes``, ``target_ids``); None when no target is present at
        frame 0 (the tracker is not run).
    """
    from scenegen.evaluation import evaluate
    from scenegen.evaluation.mot import mot_counts
    from scenegen.io import read
    from scenegen.lab.run import run

    seq = read(Path(task.root) / task.file, task.name)
    if seq.initial_targets().size == 0:
        # Nothing to track (every target enters later): a record without scores, so that
        # one such sequence does not stop the benchmark; the leaderboard skips it.
        return _round({"key": task.key(), "tracker_seed": task.tracker_seed(), "targets": 0,
                       "n_frames": int(seq.n_frames), "scores": dict.fromkeys(METRICS),
                       "sequence_params": json.loads(task.sequence_params),
                       "deterministic": True}), None  # fmt: skip
    done = run(seq, task.tracker, dict(task.params), task.tracker_seed(), single_thread=True)
    res = done.result
    report = evaluate(
        seq, res.boxes, res.target_ids, tracker=task.tracker,
        order_prob=res.order_prob, orderings=res.orderings,
    )  # fmt: skip
    rep = report.to_dict()
    targets = rep["targets"]
    multi = len(targets) > 1

    def pct(key: str) -> float | None:
        vals = [t[key] for t in targets if t[key] is not None]
        return 100.0 * float(np.mean(vals)) if vals else None

    tracked = [t["tracked"] for t in targets if t["tracked"] is not None]
    scores: dict[str, Any] = {
        "auc": rep["overall"].get("auc"),
        "precision_20": rep["overall"].get("precision_20"),
        "success": pct("success"),
        "recovery": pct("recovered"),
        "tracked": float(np.mean(tracked)) if tracked else None,
        "mean_iou": rep["overall"].get("mean_iou"),
    }
    for m in MULTI_TARGET:
        if m in rep["overall"]:
            scores[m] = rep["overall"][m] if multi else None
    # What TrackEval adds up over sequences, for the leaderboard's combined columns.
    counts = {"mot_counts": mot_counts(report.overall.mot.scores)} if multi else {}
    return _round(
        {
            "key": task.key(),
            "tracker_seed": task.tracker_seed(),
            "targets": len(targets),
            "n_frames": int(rep["n_frames"]),
            "scores": scores,
            "sequence_params": json.loads(task.sequence_params),
            # False for a tracker that says its runs are not reproducible (OpenCV's MIL):
            # ``validate --deep`` does not run it again.
            "deterministic": bool(getattr(done.tracker, "deterministic", True)),
            **counts,
        }
    ), res


def _accepted(tracker: str, params: dict[str, Any]) -> set[str]:
    """The keys of ``params`` that ``tracker`` (one of ours, or a user's ``MODULE:FACTORY``
    or ``path/file.py:FACTORY``) takes as keyword parameters (``rng`` aside).

    Raises
    ------
    ConfigError
        An unknown tracker name, or a factory that cannot be imported.
    """
    import inspect

    from scenegen.lab.run import resolve_factory
    from trackers.registry import parameters

    if ":" not in tracker:
        try:
            return set(parameters(tracker)) - {"rng"}
        except ValueError as err:
            raise ConfigError(str(err)) from None
    factory = resolve_factory(tracker)
    try:
        sig = inspect.signature(factory)
    except (TypeError, ValueError):  # no signature to read: it gets every parameter
        return set(params)
    kinds = (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)
    if any(p.kind is inspect.Parameter.VAR_KEYWORD for p in sig.parameters.values()):
        return set(params)
    return {p.name for p in sig.parameters.values() if p.kind in kinds} - {"rng"}


def _check_params(trackers: list[str], params: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """Per tracker, the ``params`` it accepts; each key must be accepted by one at least."""
    out: dict[str, dict[str, Any]] = {}
    used: set[str] = set()
    for t in trackers:
        valid = _accepted(t, params)
        out[t] = {k: v for k, v in params.items() if k in valid}
        used |= set(out[t])
    unused = sorted(set(params) - used)
    if unused:
        raise ConfigError(
            f"--param {unused[0]}: no tracker of {', '.join(trackers)} takes this parameter"
        )
    return out


def plan_benchmark(
    root: Path, trackers: list[str], params: dict[str, Any] | None = None
) -> tuple[dict[str, Any], list[BenchTask]]:
    """(dataset manifest, every task in a fixed order: trackers x sequences).

    A user's factory (``MODULE:FACTORY``) is built once here with its parameters, so that
    bad parameters fail before any run.

    Parameters
    ----------
    root : pathlib.Path
        The dataset folder (``scenegen dataset``), complete.
    trackers : list of str
        Tracker names or factories, without duplicates.
    params : dict, optional
        Tracker parameters; each tracker gets those it accepts, and each must be accepted
        by at least one tracker.

    Returns
    -------
    manifest : dict
        The dataset's manifest.
    tasks : list of BenchTask
        For each tracker in order, every sequence by index.

    Raises
    ------
    ConfigError
        No tracker, a duplicate or unknown tracker, two trackers whose run folders would
        be the same, a parameter no tracker takes, or an incomplete dataset.
    DataError
        If ``root`` is not a dataset folder.
    """
    from scenegen.datasets.build import read_manifest

    if not trackers:
        raise ConfigError("give at least one --tracker")
    if len(set(trackers)) != len(trackers):
        raise ConfigError(f"a tracker is listed twice: {', '.join(trackers)}")
    folders: dict[str, str] = {}
    for t in trackers:
        other = folders.setdefault(run_file(t, 0).split("/")[1], t)
        if other != t:
            raise ConfigError(f"trackers {other!r} and {t!r} would share the run folder "
                              f"runs/{run_file(t, 0).split('/')[1]}: rename one")  # fmt: skip
    per = _check_params(trackers, dict(params or {}))
    for t in trackers:
        if ":" in t:  # a user's factory: built once here, so bad parameters fail first
            from scenegen.lab.run import make_tracker

            make_tracker(t, per[t], 0)
    man = read_manifest(root)
    if not man.get("complete"):
        raise ConfigError(f"{root}: the dataset is incomplete; finish it with scenegen dataset")
    return man, _tasks(root, man, per)


def _tasks(root: Path, man: dict[str, Any], per: dict[str, dict[str, Any]]) -> list[BenchTask]:
    """Every task of the trackers of ``per`` (tracker -> its parameters, in order) on the
    sequences of the dataset at ``root`` (its manifest ``man``): trackers x sequences.

    Raises
    ------
    DataError
        A manifest whose axes cannot be read.
    """
    from scenegen.datasets.build import manifest_axes

    # A named axis (a mapping in sweep) is recorded by its grid position in the manifest
    # (what ds.select takes); the records, scores and curves take its value.
    named = [a for a in manifest_axes(man, root / "manifest.json") if a.named]
    tasks = []
    for t in per:
        p = tuple(sorted(per[t].items()))
        for e in sorted(man["sequences"], key=lambda e: e["index"]):
            fd = str((e.get("digests") or {}).get("frames", ""))
            values = dict(e["params"])
            for a in named:
                j = values.get(a.name)
                if isinstance(j, int) and not isinstance(j, bool) and 0 <= j < len(a):
                    values[a.name] = a.level(j)
            sp = json.dumps(values, sort_keys=True)
            tasks.append(
                BenchTask(str(root), int(e["index"]), e["name"], e["file"], int(e["seed"]),
                          fd, t, p, sp)
            )  # fmt: skip
    return tasks


# --------------------------------------------------------------------------------------
# Aggregation


def _mean(vals: list[Any]) -> float | None:
    v = [float(x) for x in vals if x is not None]
    return float(np.mean(v)) if v else None


def leaderboard(rows: list[dict[str, Any]], trackers: list[str]) -> list[dict[str, Any]]:
    """Mean of each metric per tracker over the sequences where it is defined, ranked by AUC.

    Parameters
    ----------
    rows : list of dict
        One per (tracker, sequence): ``tracker`` and the metric keys.
    trackers : list of str
        The trackers to rank (ties in AUC, and no AUC, are ordered by name).

    Returns
    -------
    list of dict
        ``rank``, ``tracker``, ``sequences`` (those with a target at frame 0, the scored
        ones), one mean per metric (None if undefined) and its 95 % percentile bootstrap
        interval over the sequences, ``METRIC_ci`` = [low, high] (None with fewer than
        two values).
    """
    from scenegen.lab.experiments.stats import LEVEL, bootstrap_mean

    board = []
    for t in trackers:
        # Sequences with no target at frame 0 have no scores and are not counted.
        mine = [r for r in rows if r["tracker"] == t and r.get("targets", 1) > 0]
        entry: dict[str, Any] = {"tracker": t, "sequences": len(mine)}
        for m in METRICS:
            vals = [float(r[m]) for r in mine if r.get(m) is not None]
            entry[m] = _mean(vals)
            # Percentile bootstrap over sequences; one seed for every tracker and metric,
            # so trackers on the same sequences are resampled alike.
            entry[f"{m}_ci"] = (list(bootstrap_mean(vals, CI_SEED, level=LEVEL))
                                if len(vals) >= 2 else None)  # fmt: skip
        board.append(entry)
    board.sort(key=lambda e: (-(e["auc"] if e["auc"] is not None else -1.0), e["tracker"]))
    for i, e in enumerate(board):
        e["rank"] = i + 1
    return _round(board)


def _axis_levels(values: list[Any]) -> tuple[list[Any], list[str], list[int]]:
    """(level keys, labels, level index per value) of an axis: as is, or quantile bins."""
    numeric = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)
    distinct = sorted({json.dumps(v, sort_keys=True) for v in values})
    if numeric and len(distinct) > _MAX_LEVELS:
        arr = np.asarray(values, dtype=float)
        edges = np.unique(np.quantile(arr, np.linspace(0, 1, _BINS + 1)))
        idx = np.clip(np.searchsorted(edges, arr, side="right") - 1, 0, len(edges) - 2)
        centres = [float(arr[idx == b].mean()) if np.any(idx == b) else math.nan
                   for b in range(len(edges) - 1)]  # fmt: skip
        labels = [f"{edges[b]:.3g}-{edges[b + 1]:.3g}" for b in range(len(edges) - 1)]
        return centres, labels, idx.tolist()
    if numeric:
        keys = sorted({float(v) for v in values})
        return keys, [f"{k:g}" for k in keys], [keys.index(float(v)) for v in values]
    # Categorical (preset names, lists): in order of first appearance in the index order.
    order: list[str] = []
    for v in values:
        s = json.dumps(v, sort_keys=True)
        if s not in order:
            order.append(s)
    labels = [json.loads(s) if isinstance(json.loads(s), str) else s for s in order]
    return list(range(len(order))), [str(x) for x in labels], [
        order.index(json.dumps(v, sort_keys=True)) for v in values
    ]


def _axes(man: dict[str, Any]) -> list[str]:
    """Difficulty axes to plot: sweep axis names (a named axis by its name), drawn paths."""
    out = [a["name"] for a in man.get("axes", []) if len(a["values"]) > 1]
    out += [d["path"] for d in man.get("vary", [])]
    return out


def curves(
    rows: list[dict[str, Any]], axes: list[str], trackers: list[str]
) -> list[dict[str, Any]]:
    """Per difficulty axis (names, :func:`dataset_meta`) and metric: the metric's mean per
    axis level, per tracker.

    A numeric axis with more than 8 distinct values is binned into 6 quantile bins (the
    level is the mean value in the bin); a non-numeric one takes its values in order of
    first appearance.

    Parameters
    ----------
    rows : list of dict
        One per (tracker, sequence): ``tracker``, ``index``, ``params`` (the sequence's
        axis values) and the metric keys.
    axes : list of str
        Axis names, looked up in each row's ``params``.
    trackers : list of str
        The trackers to draw, one series each.

    Returns
    -------
    list of dict
        One per axis and curve metric with a value: ``axis``, ``metric``, ``x`` (the level
        keys), ``labels`` and ``series`` (tracker -> mean per level, None where
        undefined); floats rounded.
    """
    out = []
    for axis in axes:
        mine = [r for r in rows if axis in r["params"]]
        if not mine:
            continue
        per_seq: dict[int, Any] = {}
        for r in mine:
            per_seq.setdefault(r["index"], r["params"][axis])
        order = sorted(per_seq)
        keys, labels, idx = _axis_levels([per_seq[i] for i in order])
        level_of = dict(zip(order, idx, strict=True))
        for metric in _CURVE_METRICS:
            series = {}
            for t in trackers:
                vals = []
                for lv in range(len(keys)):
                    vals.append(_mean([r.get(metric) for r in mine
                                       if r["tracker"] == t and level_of[r["index"]] == lv]))
                series[t] = vals  # fmt: skip
            if all(v is None for s in series.values() for v in s):
                continue
            out.append({"axis": axis, "metric": metric, "x": keys, "labels": labels,
                        "series": series})  # fmt: skip
    return _round(out)


def _figure(curve: dict[str, Any], path: Path) -> str:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from scenegen.io import atomic_path

    fig = Figure(figsize=(5.2, 3.4))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    x = np.arange(len(curve["labels"]))
    for t, vals in curve["series"].items():
        v = np.array([np.nan if a is None else a for a in vals], dtype=float)
        ax.plot(x, v, marker="o", label=t)
    ax.set_xticks(x, curve["labels"], rotation=30 if len(x) > 4 else 0, fontsize=8)
    ax.set_xlabel(curve["axis"])
    ax.set_ylabel(METRICS.get(curve["metric"], curve["metric"]))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    with atomic_path(path, ".png") as tmp:
        fig.savefig(tmp, dpi=100, format="png", metadata={"Software": None})
    return path.name


def _fmt(v: Any) -> str:
    if v is None:
        return "—"
    if isinstance(v, float):
        return f"{v:.3f}" if abs(v) <= 1.0 else f"{v:.1f}"
    return str(v)


_CI_NOTE = ("Each cell: the mean over the scored sequences [its 95 % percentile bootstrap "
            "interval over the sequences]; a ranking between overlapping intervals is not "
            "settled.")
_COMBINED_NOTE = ("(combined): the sequences with several targets taken as one, as "
                  "TrackEval's COMBINED_SEQ row: their counts added up, so each sequence "
                  "weighs by its detections; no interval.")
NONE_SCORED = "no sequence was scored (none has a target at frame 0)"
"""What the report says when no sequence of the dataset has a target at frame 0."""
_NONE_SCORED_NOTE = (f"{NONE_SCORED[0].upper()}{NONE_SCORED[1:]}: no tracker has a score, "
                     "and the ranks are only the order of the trackers' names.")


def scored(board: list[dict[str, Any]]) -> bool:
    """True when some tracker of the leaderboard ``board`` was scored on some sequence.

    Parameters
    ----------
    board : list of dict
        A leaderboard (:func:`leaderboard`), each entry with ``sequences``.

    Returns
    -------
    bool
        Whether an entry has ``sequences`` > 0.
    """
    return any(e["sequences"] > 0 for e in board)


def _md_text(text: str) -> str:
    """``text`` in a markdown table cell: ``|`` escaped and line breaks made spaces, so that
    a tracker's name (a user's factory may hold either) keeps to its cell."""
    return " ".join(str(text).splitlines()).replace("|", "\\|")


def _cell(e: dict[str, Any], metric: str) -> str:
    """A leaderboard cell: the mean and its 95 % interval, ``0.952 [0.901, 0.980]``."""
    ci = e.get(f"{metric}_ci")
    if e[metric] is None or ci is None:
        return _fmt(e[metric])
    return f"{_fmt(e[metric])} [{_fmt(ci[0])}, {_fmt(ci[1])}]"


def _label(metric: str) -> str:
    return METRICS.get(metric) or COMBINED[metric]


def _columns(board: list[dict[str, Any]]) -> list[str]:
    return [m for m in (*METRICS, *COMBINED) if any(e.get(m) is not None for e in board)]


def _markdown(board: list[dict[str, Any]]) -> str:
    cols = _columns(board)

    def row(cells: list[str]) -> str:
        return "| " + " | ".join(cells) + " |"

    lines = [row(["rank", "tracker", "sequences", *(_label(c) for c in cols)]),
             "|---:|---|---:|" + "---:|" * len(cols)]  # fmt: skip
    for e in board:
        lines.append(row([str(e["rank"]), _md_text(e["tracker"]), str(e["sequences"]),
                          *(_cell(e, c) for c in cols)]))  # fmt: skip
    note = _CI_NOTE if scored(board) else _NONE_SCORED_NOTE
    if scored(board) and any(c in cols for c in COMBINED):
        note += "\n\n" + _COMBINED_NOTE
    return "\n".join(lines) + "\n\n" + note + "\n"


def _html(meta: dict[str, Any], board: list[dict[str, Any]], figures: list[tuple[str, str]],
          params: dict[str, dict[str, Any]]) -> str:  # fmt: skip
    e = html.escape
    cols = _columns(board)
    head = "".join(f"<th>{e(_label(c))}</th>" for c in cols)
    body = ""
    for r in board:
        cells = "".join(f"<td>{_cell(r, c)}</td>" for c in cols)
        body += f"<tr><td>{r['rank']}</td><td>{e(r['tracker'])}</td><td>{r['sequences']}</td>"
        body += cells + "</tr>\n"
    figs = "\n".join(
        f'<figure><img src="{e(f)}" alt="{e(cap)}"><figcaption>{e(cap)}</figcaption></figure>'
        for f, cap in figures
    )
    tp = "".join(f"<li>{e(t)}: {e(json.dumps(p, sort_keys=True))}</li>" for t, p in params.items())
    axes = ", ".join(e(a) for a in meta["axes"]) or "none"
    multi = [m for m in MULTI_TARGET if m in cols]
    note = f"<p>{e(_CI_NOTE)}</p>" + (
        f"<p>{', '.join(METRICS[m] for m in multi)}: means over the sequences with several "
        "targets only.</p>" + (f"<p>{e(_COMBINED_NOTE)}</p>" if any(
            c in cols for c in COMBINED) else "") if multi else
        "<p>No multi-target metric: every sequence has one target (or none was computed).</p>"
    )  # fmt: skip
    if not scored(board):
        note = f"<p>{e(_NONE_SCORED_NOTE)}</p>"
    if not figs:  # say why there is none
        figs = ("<p>No swept or drawn axis with more than one value.</p>" if not meta["axes"]
                else f"<p>No figure: {e(NONE_SCORED)}.</p>" if not scored(board)
                else "<p>No figure: no metric has a value along the difficulty axes.</p>")
    return f"""<!doctype html>
<html><head><meta charset="utf-8"><title>Benchmark: {e(str(meta["family"]))}</title>
<style>body{{font-family:sans-serif;max-width:1100px;margin:2em auto}}
table{{border-collapse:collapse}}td,th{{border:1px solid #ccc;padding:4px 8px;text-align:right}}
td:nth-child(2){{text-align:left}}figure{{display:inline-block;margin:8px}}
img{{max-width:520px}}</style></head><body>
<h1>Benchmark on dataset {e(str(meta["family"]))}</h1>
<p>{e(str(meta["description"]))} — {meta["count"]} sequences, seed {meta["seed"]},
difficulty axes: {axes}. Dataset folder {e(str(meta["path"]))}, family digest
{e(str(meta["family_digest"]))}.</p>
<h2>Leaderboard</h2>
<table><tr><th>rank</th><th>tracker</th><th>sequences</th>{head}</tr>
{body}</table>
{note}
<p>Tracker parameters (besides defaults): <ul>{tp}</ul></p>
<p>Per-sequence scores: <a href="scores.csv">scores.csv</a>; everything:
<a href="results.json">results.json</a>.</p>
<h2>Metrics against the difficulty axes</h2>
{figs}
</body></html>
"""


def run_benchmark(
    dataset: str | Path,
    trackers: list[str],
    out: str | Path,
    *,
    params: dict[str, Any] | None = None,
    jobs: int | None = None,
    scheduler: str | None = None,
    progress: bool = False,
    on_done: Callable[[BenchTask], None] | None = None,
    keep_tracks: bool = False,
) -> dict[str, Any]:
    """Run every tracker on every sequence of ``dataset`` (resumably) and write the report.

    A stored run is kept when it is sound and of the same key (dataset sequence, tracker,
    parameters). One that is damaged, edited, malformed, written before records were
    sealed, or sealed but not the one the folder's ``results.json`` lists for that key, is
    run again with one warning line (:func:`scenegen.lab.benchmark_outputs.load_record`).

    Parameters
    ----------
    dataset : str or Path
        A dataset folder (``scenegen dataset``).
    trackers : list of str
        Tracker names.
    out : str or Path
        Output folder.
    params : dict, optional
        Tracker parameters, given to every tracker that takes them.
    jobs : int, optional
        Local processes (None: all cores; 1 runs in this process).
    scheduler : str, optional
        A Dask scheduler address instead of ``jobs`` (its workers read ``dataset``; results
        come back to this process, which writes ``out``).
    progress : bool, default False
        Show a tqdm bar on stderr.
    on_done : callable, optional
        Called with each task whose record was just stored (or, run again for its tracks
        only, whose tracker file was).
    keep_tracks : bool, default False
        Also write ``out/trackeval/``: the tracker outputs and the dataset's ground truth
        as TrackEval reads them, listed under ``tracks`` in ``results.json``
        (:mod:`scenegen.lab.benchmark_tracks`). A pair whose stored run has no sound
        tracker file is run again; its record must come out the same. An ``out`` that
        holds kept tracks (``results.json`` lists them, or ``out/trackeval/`` is there) keeps
        them up to date without it.

    Returns
    -------
    dict
        What ``results.json`` holds (:func:`results_document`).

    Raises
    ------
    ConfigError
        As :func:`plan_benchmark`; a bad ``jobs`` (< 1, or given with ``scheduler``) or an
        unreachable scheduler; ``out``
        holding a dataset (its ``manifest.json``), an experiment's results or a report of
        ``scenegen experiment all``, or that cannot be created; a FIFO, a device or a
        socket where the benchmark writes a file (refused before any run).
    DataError
        ``dataset`` is not a dataset folder, or a shard is damaged; with kept tracks, a
        deterministic tracker run again for its tracks gave another record than the
        stored one.
    """
    from tqdm import tqdm

    from scenegen.datasets.build import make_output_folder
    from scenegen.datasets.executor import check_executor, probe, run_tasks
    from scenegen.lab.benchmark_outputs import listed_digests, load_record
    from scenegen.lab.experiments.outputs import warn

    check_executor(jobs, scheduler)
    root = Path(dataset)
    man, tasks = plan_benchmark(root, list(trackers), params)
    if scheduler is not None:
        probe(scheduler)  # fail before writing anything
    outp = Path(out)
    if (outp / "manifest.json").exists():
        what = "the dataset folder" if outp.resolve() == root.resolve() else "a dataset folder"
        raise ConfigError(f"-o {outp}: is {what} (manifest.json); write the benchmark into "
                          "another folder")  # fmt: skip
    from scenegen.datasets.build import holds_experiment_outputs, holds_report

    if holds_experiment_outputs(outp):
        what = ("a report of `scenegen experiment all`" if holds_report(outp)
                else "the results of `scenegen experiment`")  # fmt: skip
        raise ConfigError(f"-o {outp}: holds {what}; write the benchmark into another "
                          "folder")  # fmt: skip
    make_output_folder(outp)
    from scenegen.io.atomic import refuse_special_files

    # Refused before any run, not after them all.
    refuse_special_files([outp / n for n in ("results.json", *PAGES)]
                         + sorted(outp.glob("*.png")))  # fmt: skip
    meta = dataset_meta(man, root)
    listed = listed_digests(outp, meta)
    from scenegen.lab import benchmark_tracks as bt

    listed_t = bt.listed_tracks(outp, meta)
    keep = keep_tracks or bool(listed_t) or (outp / bt.FOLDER).is_dir()
    names = bt.sequence_names((e["index"], e["name"]) for e in man["sequences"])
    if keep:
        for link in bt.prepare_folder(outp, bt.kept_files(list(trackers), names)):
            warn(f"{link}: a link removed from the kept tracks (the benchmark writes its "
                 "own files there, not through links)")  # fmt: skip
    records: dict[tuple[str, int], dict[str, Any]] = {}
    todo = []
    for t in tasks:
        rec = load_record(outp / t.filename(), t, listed.get(t.filename()))
        if rec is None:
            todo.append(t)
            continue
        records[(t.tracker, t.index)] = rec
        if not keep:
            continue
        track, digest = bt.track_file(t.tracker, names[t.index]), content_digest(rec)
        listed_ok = (listed.get(t.filename(), ("",))[0] == digest
                     and bt.sound_file(outp, track, listed_t))  # fmt: skip
        if not (listed_ok or bt.pending_sound(outp, t.filename(), track, digest)):
            todo.append(t)  # run again for its tracks only
    bar = tqdm(total=len(tasks), initial=len(records), disable=not progress, unit="run",
               desc="benchmark", leave=False)  # fmt: skip

    def store(t: BenchTask, done: Any) -> None:
        rec = done[0] if keep else done
        old = records.get((t.tracker, t.index))
        if keep:
            if old is not None and old != _content(rec):
                path = outp / t.filename()
                if old["deterministic"]:
                    raise DataError(f"{path}: running it again for its tracks gave another "
                                    "record than the stored one (the tracker did not "
                                    "reproduce its run); nothing was rewritten")  # fmt: skip
                warn(f"{path}: running it again for its tracks gave another record (a "
                     "tracker that is not deterministic); both are rewritten")  # fmt: skip
                old = None
            bt.write_tracks(outp / bt.track_file(t.tracker, names[t.index]), rec["n_frames"],
                            done[1], done[2])  # fmt: skip
        if old is None:
            write_sealed_json(outp / t.filename(), rec, parents=True)
            records[(t.tracker, t.index)] = _content(rec)
            bar.update(1)
        if keep:  # resumable from here without running the pair again
            bt.write_pending(outp, t.filename(), bt.track_file(t.tracker, names[t.index]),
                             content_digest(records[(t.tracker, t.index)]))  # fmt: skip
        if on_done is not None:
            on_done(t)

    try:
        run_tasks(bt.pair_with_tracks if keep else run_pair, todo, store, jobs=jobs,
                  scheduler=scheduler,
                  key=lambda t: f"{_slug(t.tracker)}-{t.index}", name="scenegen-benchmark",
                  label=lambda t: f"running {t.tracker!r} on sequence {t.index} ({t.name})")
    finally:  # fmt: skip
        bar.close()
    ordered = [records[(t.tracker, t.index)] for t in tasks]
    tracks = None
    if keep:
        multi = [t.index for t in tasks if t.tracker == tasks[0].tracker
                 and records[(t.tracker, t.index)]["targets"] > 1]  # fmt: skip
        sound = {n for n in listed_t if bt.sound_file(outp, n, listed_t)}
        bt.write_gt(outp, root, man["sequences"], names, multi, sound)
        kept = bt.kept_files(list(trackers), names)
        for gone in bt.remove_unlisted(outp, set(kept)):
            warn(f"{gone}: removed from the kept tracks (not a tracker or sequence of this "
                 "benchmark; TrackEval would read it)")  # fmt: skip
        tracks = [f"{n} {bt.file_digest(outp / n)}" for n in kept]
    results = write_outputs(outp, meta, list(trackers), ordered, tracks)
    bt.remove_pending(outp)  # results.json lists the kept files now
    return results


def _content(rec: dict[str, Any]) -> dict[str, Any]:
    """``rec`` as a reader of its sealed file sees it (through canonical JSON, no digest)."""
    return {k: v for k, v in seal(rec).items() if k != SEAL}


def dataset_meta(man: dict[str, Any], root: str | Path) -> dict[str, Any]:
    """What the results keep of the dataset: its folder (absolute), family, family digest,
    seed, count and description, its sequence parameters (``scores.csv``'s columns) and its
    difficulty axes (the swept axes with more than one value, then the drawn paths).

    Parameters
    ----------
    man : dict
        The dataset's manifest (``manifest.json``).
    root : str or pathlib.Path
        The dataset folder.

    Returns
    -------
    dict
        ``path``, ``family``, ``family_digest``, ``seed``, ``count``, ``description``,
        ``sequence_params`` and ``axes`` (None for a key the manifest lacks).
    """
    return {
        "path": str(Path(root).resolve()),
        "family": man.get("family"),
        "family_digest": man.get("family_digest"),
        "seed": man.get("seed"),
        "count": man.get("count"),
        "description": str(man.get("description", "")),
        "sequence_params": list(man.get("params", [])),
        "axes": _axes(man),
    }


def combined_scores(records: list[dict[str, Any]]) -> dict[str, dict[str, float | None]]:
    """Per tracker, MOTA, IDF1 and HOTA of its multi-target sequences taken as one.

    The counts of the records (``mot_counts``) are added up in record order and the rates
    computed from the sums, as TrackEval's ``COMBINED_SEQ`` row
    (:func:`scenegen.evaluation.mot.combine`): each sequence weighs by its detections.

    Parameters
    ----------
    records : list of dict
        Run records (:func:`run_pair`), trackers x sequences in task order.

    Returns
    -------
    dict of str to dict
        Per tracker of the records, one value per key of :data:`COMBINED`: None when it
        has no multi-target sequence, or when one of its records has no counts (a run
        recorded by a version before them).
    """
    from scenegen.evaluation.mot import add_counts, from_counts

    multi: dict[str, list[dict[str, Any] | None]] = {}
    for rec in records:
        per = multi.setdefault(rec["key"]["tracker"], [])
        if rec["targets"] > 1:
            per.append(rec.get("mot_counts"))
    out: dict[str, dict[str, float | None]] = {}
    for tracker, counts in multi.items():
        if not counts or any(c is None for c in counts):
            out[tracker] = dict.fromkeys(COMBINED)
            continue
        s = from_counts(add_counts(counts))
        out[tracker] = {"mota_combined": s.clear.mota, "idf1_combined": s.identity.idf1,
                        "hota_combined": s.hota.hota}  # fmt: skip
    return out


def results_document(
    meta: dict[str, Any], trackers: list[str], records: list[dict[str, Any]]
) -> dict[str, Any]:
    """What ``results.json`` holds, from the dataset's description and the run records.

    Parameters
    ----------
    meta : dict
        :func:`dataset_meta`.
    trackers : list of str
        In the order given on the command line.
    records : list of dict
        Every run record (as read back, without digest), trackers x sequences in task order.

    Returns
    -------
    dict
        ``dataset`` (``meta``), ``trackers``, ``params`` (per tracker), ``leaderboard``,
        ``curves``, ``scores`` (one row per record) and ``records`` (``"runs/TRACKER/NNNNN.json
        SHA256"`` per record, in order).
    """
    from scenegen.lab.benchmark_outputs import listing

    rows = []
    for rec in records:
        k = rec["key"]
        rows.append({"tracker": k["tracker"], "index": k["index"], "name": k["name"],
                     "targets": rec["targets"], "params": rec.get("sequence_params", {}),
                     **rec["scores"]})  # fmt: skip
    per_tracker = {t: {} for t in trackers}
    for rec in records:
        per_tracker[rec["key"]["tracker"]] = dict(rec["key"]["params"])
    board = leaderboard(rows, list(trackers))
    if any("mot_counts" in rec for rec in records):
        combined = combined_scores(records)
        for e in board:
            e.update(combined[e["tracker"]])
    return _round({
        "dataset": meta,
        "trackers": list(trackers),
        "params": per_tracker,
        "leaderboard": board,
        "curves": curves(rows, list(meta["axes"]), list(trackers)),
        "scores": rows,
        "records": listing(records),
    })  # fmt: skip


def figure_list(results: dict[str, Any]) -> list[tuple[str, str, dict[str, Any]]]:
    """(file name, caption, curve) of every figure of ``results``' curves.

    Parameters
    ----------
    results : dict
        A results document (:func:`results_document`); its ``curves`` are used.

    Returns
    -------
    list of (str, str, dict)
        Per curve, in order: ``curve-METRIC-NN-AXIS.png`` (NN its position, AXIS made
        file-safe and cut to 40 characters), ``"LABEL vs AXIS"`` and the curve.
    """
    out = []
    for i, c in enumerate(results["curves"]):
        name = f"curve-{c['metric']}-{i:02d}-{_slug(c['axis'])[:40]}.png"
        out.append((name, f"{METRICS.get(c['metric'], c['metric'])} vs {c['axis']}", c))
    return out


def _csv_cell(value: Any) -> Any:
    """A sequence parameter in ``scores.csv``: a list, dict or bool as JSON (``[2, 3]``,
    ``{"a": 1}``, ``true``), None as an empty cell, anything else as is."""
    if isinstance(value, (bool, dict, list)):
        return json.dumps(value, sort_keys=True)
    return value


PAGES = ("scores.csv", "leaderboard.md", "index.html")
"""The text files a benchmark writes beside ``results.json`` (:func:`texts`)."""


def texts(results: dict[str, Any]) -> dict[str, str]:
    """``scores.csv``, ``leaderboard.md`` and ``index.html`` of ``results``, by file name.

    Parameters
    ----------
    results : dict
        A results document (:func:`results_document`).

    Returns
    -------
    dict of str to str
        The text of each of the three files, keyed by its file name.
    """
    meta, board, rows = results["dataset"], results["leaderboard"], results["scores"]
    metric_cols = [m for m in METRICS if any(m in r for r in rows)]
    pnames = list(meta["sequence_params"])
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["tracker", "index", "name", "targets", *pnames, *metric_cols])
    for r in rows:
        w.writerow([r["tracker"], r["index"], r["name"], r["targets"],
                    *[_csv_cell(r["params"].get(p)) for p in pnames],
                    *["" if r.get(m) is None else r[m] for m in metric_cols]])  # fmt: skip
    figures = [(name, cap) for name, cap, _ in figure_list(results)]
    return dict(zip(PAGES, (buf.getvalue(), _markdown(board),
                            _html(meta, board, figures, results["params"])), strict=True))


def write_outputs(
    out: Path, meta: dict[str, Any], trackers: list[str], records: list[dict[str, Any]],
    tracks: list[str] | None = None,
) -> dict[str, Any]:
    """Write the figures, ``results.json`` (sealed), ``scores.csv``, ``leaderboard.md`` and
    ``index.html`` of ``records`` (see :func:`results_document`) into ``out``; return the
    results.

    Every file is written atomically.

    Parameters
    ----------
    out : pathlib.Path
        The output folder (it must exist).
    meta : dict
        :func:`dataset_meta`.
    trackers : list of str
        In the order given on the command line.
    records : list of dict
        Every run record, trackers x sequences in task order.
    tracks : list of str, optional
        The kept tracks' listing (``"trackeval/... SHA256"`` per file,
        :mod:`scenegen.lab.benchmark_tracks`), stored as ``tracks``; None: no such key.

    Returns
    -------
    dict
        The results as ``results.json`` holds them, without its digest.
    """
    from scenegen.io import atomic_path

    doc = results_document(meta, trackers, records)
    results = _content(doc if tracks is None else {**doc, "tracks": tracks})
    for name, _, curve in figure_list(results):
        _figure(curve, out / name)
    write_sealed_json(out / "results.json", results, indent=1)
    for name, text in texts(results).items():
        with atomic_path(out / name, Path(name).suffix) as tmp:
            tmp.write_text(text, encoding="utf-8")
    return results
