"""The files a benchmark writes and reads back, sealed, and the check of its folder.

A benchmark folder ``OUT`` (``scenegen benchmark DIR ... -o OUT``) holds one run record
per (tracker, sequence) under ``OUT/runs/TRACKER/NNNNN.json``, ``results.json``,
``scores.csv``, ``leaderboard.md``, ``index.html`` and PNG figures. Records and
``results.json`` are sealed JSON documents (:mod:`scenegen.io.sealed`: a ``sha256`` key
over the canonical content, written atomically); ``results.json`` lists under ``records``
every run file it was computed from with that file's digest, as an experiment's does
(:mod:`scenegen.lab.experiments.outputs`).

- A resumed benchmark (:func:`load_record`) runs again, with one warning line, a record
  that is damaged, edited, malformed or written before records were sealed, and a sealed
  record of the same key that ``results.json`` lists with another digest (edited and
  resealed after the results were computed).
- :func:`check_benchmark` (``scenegen validate OUT``) checks everything but the pixels of
  the figures: each listed record reads, matches its digest, its listed digest and its
  file name, and has a record's fields; ``results.json`` equals the results recomputed
  from those records and its own dataset description; the records are one run of each
  listed tracker on each of the dataset's sequences, in order, a built-in tracker's runs
  deterministic; ``scores.csv``, ``leaderboard.md`` and ``index.html`` are the texts of
  ``results.json``; every figure it names is a whole PNG image. With ``deep``, every record's
  key is checked against the manifest of the dataset (found at the path ``results.json``
  names) and its run computed again from it and compared with the record.
- With kept tracks (``--keep-tracks``), every file of ``OUT/trackeval/`` that
  ``results.json`` lists under ``tracks`` is there with its digest, and no other tracker
  file or sequence folder is (:func:`scenegen.lab.benchmark_tracks.check_tracks`); with
  ``deep`` each tracker file is also compared with the boxes of its run computed again.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

from scenegen.errors import ConfigError, DataError
from scenegen.io.atomic import SpecialFile, read_regular, read_regular_text
from scenegen.io.images import png_problem
from scenegen.io.sealed import Unsealed, content_digest, read_sealed_json
from scenegen.lab.experiments.outputs import _more, parse_listing, read_checked, warn
from scenegen.lab.experiments.runner import _round

__all__ = [
    "RESULTS",
    "check_benchmark",
    "is_benchmark_folder",
    "listed_digests",
    "listing",
    "load_record",
    "read_record",
    "read_results",
    "record_problems",
]

RESULTS = "results.json"
"""The benchmark's results file in its output folder."""
_RERUN = "run the same `scenegen benchmark` command again into this folder to recompute it"
_KEY = {"index": int, "name": str, "file": str, "seed": int, "frames_digest": str,
        "tracker": str, "params": dict}  # fmt: skip
_META = {"path": (str,), "family": (str, type(None)), "family_digest": (str, type(None)),
         "seed": (int,), "count": (int,), "description": (str,), "sequence_params": (list,),
         "axes": (list,)}  # fmt: skip
_TOP = ("dataset", "trackers", "params", "leaderboard", "curves", "scores", "records")
_RUN_FILE = re.compile(r"runs/[A-Za-z0-9._-]+/[0-9]{5,}\.json")


def _is(value: Any, kind: type) -> bool:
    return isinstance(value, kind) and not isinstance(value, bool)


def record_problems(data: Any) -> list[str]:
    """What is wrong with the fields of a benchmark run record (empty when none is).

    Parameters
    ----------
    data : Any
        A parsed run record (without its digest).

    Returns
    -------
    list of str
        One line per problem: not an object, a ``key`` without the fields of
        :meth:`scenegen.lab.benchmark.BenchTask.key`, ``tracker_seed``, ``targets`` or
        ``n_frames`` not ints, ``scores`` not metrics of
        :data:`scenegen.lab.benchmark.METRICS` with numbers or null,
        ``sequence_params`` not a dict, ``deterministic`` not a bool, ``mot_counts`` (if
        present) not the counts of :func:`scenegen.evaluation.mot.mot_counts`.
    """
    from scenegen.lab.benchmark import METRICS

    if not isinstance(data, dict):
        return ["not a run record (a JSON object is expected)"]
    out = []
    key = data.get("key")
    if not (isinstance(key, dict) and set(key) == set(_KEY)
            and all(_is(key[k], kind) for k, kind in _KEY.items())):  # fmt: skip
        out.append("key is not a benchmark run key")
    for name in ("tracker_seed", "targets", "n_frames"):
        if not _is(data.get(name), int):
            out.append(f"{name} is missing or not an int")
    scores = data.get("scores")
    if not (isinstance(scores, dict) and set(scores) <= set(METRICS) and all(
            v is None or _is(v, int) or _is(v, float) for v in scores.values())):  # fmt: skip
        out.append("scores is not a dict of metrics (numbers or null)")
    if not isinstance(data.get("sequence_params"), dict):
        out.append("sequence_params is missing or not a dict")
    if not isinstance(data.get("deterministic"), bool):
        out.append("deterministic is missing or not a bool")
    if "mot_counts" in data and not _counts_ok(data["mot_counts"]):
        out.append("mot_counts is not the counts of scenegen.evaluation.mot.mot_counts")
    return out


def _counts_ok(counts: Any) -> bool:
    """Whether ``counts`` has every key of ``mot_counts``: numbers, or lists of 19 numbers."""
    from scenegen.evaluation.mot import COUNT_KEYS, HOTA_ALPHAS, HOTA_COUNT_KEYS

    def number(v: Any) -> bool:
        return _is(v, int) or _is(v, float)

    return isinstance(counts, dict) and set(counts) == set(COUNT_KEYS) and all(
        (isinstance(v, list) and len(v) == len(HOTA_ALPHAS) and all(map(number, v)))
        if k in HOTA_COUNT_KEYS else number(v)
        for k, v in counts.items())  # fmt: skip


def read_record(path: Path) -> dict[str, Any]:
    """The benchmark run record at ``path`` (without its digest).

    Parameters
    ----------
    path : pathlib.Path
        A sealed run file (``OUT/runs/TRACKER/NNNNN.json``).

    Returns
    -------
    dict
        The record's content, checked by :func:`record_problems`.

    Raises
    ------
    DataError
        One line: missing, damaged, edited, written before records were sealed
        (:class:`scenegen.io.sealed.Unsealed`), or not a run record.
    """
    return read_checked(path, record_problems, "a benchmark run record")


def _run_file(key: dict[str, Any]) -> str:
    from scenegen.lab.benchmark import run_file

    return run_file(key["tracker"], key["index"])


def listing(records: list[dict[str, Any]]) -> list[str]:
    """The ``records`` entry of ``results.json``: ``"runs/TRACKER/NNNNN.json SHA256"`` per
    record (as read back, without digest), in order.

    Parameters
    ----------
    records : list of dict
        Run records (:func:`scenegen.lab.benchmark.run_pair`), without digest.

    Returns
    -------
    list of str
        Each record's run file and the SHA-256 of its canonical content.
    """
    return [f"{_run_file(r['key'])} {content_digest(r)}" for r in records]


def _results_problem(data: dict[str, Any]) -> str | None:
    missing = [k for k in _TOP if k not in data]
    if missing:
        return f"no {missing[0]!r}"
    meta = data["dataset"]
    if not (isinstance(meta, dict) and set(meta) == set(_META) and all(
            isinstance(meta[k], kinds) and not isinstance(meta[k], bool)
            for k, kinds in _META.items())
            and all(isinstance(a, str) for a in [*meta["sequence_params"], *meta["axes"]])):
        return "'dataset' is not a dataset description"  # fmt: skip
    if not (isinstance(data["trackers"], list) and data["trackers"]
            and all(isinstance(t, str) for t in data["trackers"])):  # fmt: skip
        return "'trackers' is not a list of tracker names"
    if parse_listing(data["records"]) is None:
        return "'records' is not a listing of run files"
    if "tracks" in data and parse_listing(data["tracks"]) is None:
        return "'tracks' is not a listing of files"
    return None


def read_results(path: Path) -> dict[str, Any]:
    """The content of a benchmark's ``results.json`` (without its digest).

    Parameters
    ----------
    path : pathlib.Path
        The ``results.json`` file.

    Returns
    -------
    dict
        Its content, with every top-level key of a benchmark's results, a dataset
        description, a non-empty list of trackers and a listing of run files.

    Raises
    ------
    DataError
        One line naming the file: missing, damaged, edited, written before results were
        sealed (with the command that recomputes it), or not a benchmark's results.
    """
    try:
        data = read_sealed_json(path)
    except Unsealed as err:
        raise DataError(f"{err}: {_RERUN}") from None
    problem = _results_problem(data)
    if problem:
        raise DataError(f"{path}: not a benchmark's results ({problem})")
    return data


def listed_digests(out: Path, meta: dict[str, Any]) -> dict[str, tuple[str, dict[str, Any]]]:
    """Per run file that ``OUT/results.json`` lists: (its digest, the parameters of its
    tracker then). Empty when there is no sound ``results.json``, or when it was computed
    on another dataset than ``meta`` (:func:`scenegen.lab.benchmark.dataset_meta`)
    describes (another family digest, seed or count).

    Parameters
    ----------
    out : pathlib.Path
        The benchmark's output folder.
    meta : dict
        The description of the dataset about to be run
        (:func:`scenegen.lab.benchmark.dataset_meta`).

    Returns
    -------
    dict of str to (str, dict)
        Run file name (``runs/TRACKER/NNNNN.json``) -> (its listed SHA-256, its tracker's
        parameters in ``results.json``).
    """
    try:
        res = read_results(Path(out) / RESULTS)
    except DataError:
        return {}
    if any(res["dataset"].get(k) != meta.get(k) for k in ("family_digest", "seed", "count")):
        return {}
    entries = parse_listing(res["records"]) or []
    params = res["params"] if isinstance(res["params"], dict) else {}
    out_map: dict[str, tuple[str, dict[str, Any]]] = {}
    for (name, digest), row in zip(entries, res["scores"], strict=False):
        tracker = row.get("tracker") if isinstance(row, dict) else None
        out_map[name] = (digest, params.get(tracker, {}) if isinstance(tracker, str) else {})
    return out_map


def load_record(path: Path, task: Any, listed: tuple[str, dict[str, Any]] | None = None
                ) -> dict[str, Any] | None:  # fmt: skip
    """The stored record of ``task`` (a :class:`scenegen.lab.benchmark.BenchTask`) at
    ``path``, or None when the run must be computed (again).

    Damaged, edited, malformed, unsealed or another file's run; or sound, yet listed by
    ``results.json`` (``listed``: :func:`listed_digests`' entry for the file, computed on
    this dataset) with another digest while that listing was computed with the same
    tracker parameters: None, with one warning line. Missing, or stored for another key
    of the same file (other tracker parameters, another dataset) or with other sequence
    parameters (a named axis by its grid position, as before its value was recorded):
    None, silently.

    Parameters
    ----------
    path : pathlib.Path
        The task's run file in the output folder.
    task : BenchTask
        The task whose run is looked for.
    listed : (str, dict), optional
        The file's entry of :func:`listed_digests` (None: not listed).

    Returns
    -------
    dict or None
        The stored record (without its digest), or None to run the task.

    Raises
    ------
    ConfigError
        ``path`` is a FIFO, a device or a socket (``"PATH: is not a regular file (a
        FIFO); remove it"``): the run could not be stored there, so it is not run.
    """
    if not path.exists():
        return None
    try:
        data = read_record(path)
    except SpecialFile as err:  # its run could not be stored there: refused before running
        raise ConfigError(f"{err}; remove it") from None
    except DataError as err:
        warn(f"{err}; running it again")
        return None
    if _run_file(data["key"]) != task.filename():
        warn(f"{path}: holds the run {_run_file(data['key'])!r}; running it again")
        return None
    if listed is not None and listed[1] == dict(task.params) and (
            content_digest(data) != listed[0]):  # fmt: skip
        warn(f"{path}: is not the run {RESULTS} lists (edited or replaced since); "
             "running it again")  # fmt: skip
        return None
    if data["key"] != task.key() or data["sequence_params"] != _round(
        json.loads(task.sequence_params)
    ):  # another run, or the sequence's parameters as an earlier version recorded them
        return None
    return data


def is_benchmark_folder(folder: str | Path) -> bool:
    """True for a folder that ``scenegen benchmark`` wrote (even a damaged one): it has
    ``scores.csv`` or ``leaderboard.md``, or run folders under ``runs/``.

    Parameters
    ----------
    folder : str or pathlib.Path
        The folder to look at.

    Returns
    -------
    bool
        False for a path that is not a folder, and for a dataset folder (it has
        ``manifest.json``).
    """
    from scenegen.datasets.build import holds_benchmark_outputs

    root = Path(folder)
    if not root.is_dir() or (root / "manifest.json").exists():
        return False
    return holds_benchmark_outputs(root)


def check_benchmark(folder: str | Path, *, deep: bool = False,
                    skipped: list[str] | None = None) -> list[str]:  # fmt: skip
    """Check a benchmark folder; one line per problem, empty when it is sound.

    Parameters
    ----------
    folder : str or Path
        A folder written by ``scenegen benchmark DIR ... -o OUT``.
    deep : bool
        Also check every record's key and sequence parameters against the manifest of the
        dataset at the path ``results.json`` names (a record moved to another sequence),
        and run every listed run again on it (same seeds) and compare it with its record:
        finds a record edited with every digest recomputed. Runs of a user's tracker that
        is not deterministic (its record says so; a built-in tracker's record may not) are
        not run again.
    skipped : list, optional
        With ``deep``, receives the file of every run not run again for that reason.

    Returns
    -------
    list of str
        Each line names the file at fault (at most a few per kind, then a count).
    """
    from scenegen.lab.benchmark import figure_list, results_document, texts
    from scenegen.lab.benchmark_tracks import check_tracks

    root = Path(folder)
    res_path = root / RESULTS
    try:
        results = read_results(res_path)
    except DataError as err:
        return [str(err)]
    problems: list[str] = []
    records: list[dict[str, Any]] = []
    for name, digest in parse_listing(results["records"]) or []:
        path = root / name
        if not _RUN_FILE.fullmatch(name):
            problems.append(f"{res_path}: records names {name!r}, not a run file")
            continue
        try:
            rec = read_record(path)
        except DataError as err:
            problems.append(str(err))
            continue
        if _run_file(rec["key"]) != name:
            problems.append(f"{path}: holds the run {_run_file(rec['key'])!r}")
        elif content_digest(rec) != digest:
            problems.append(f"{path}: is not the run {RESULTS} was computed from (edited or "
                            "replaced since)")  # fmt: skip
        records.append(rec)
    if problems:
        return _more(problems)
    try:
        fresh = results_document(results["dataset"], results["trackers"], records)
        if "tracks" in results:  # checked against the files by check_tracks
            fresh["tracks"] = results["tracks"]
        fresh = json.loads(json.dumps(fresh, sort_keys=True))
    except Exception as err:  # noqa: BLE001 - sound digests, yet contents no summary expects
        return [f"{res_path}: its runs cannot be summarised ({type(err).__name__}: "
                f"{str(err)[:80]})"]  # fmt: skip
    changed = sorted(k for k in set(fresh) | set(results) if fresh.get(k) != results.get(k))
    if changed:
        verb = "differs" if len(changed) == 1 else "differ"
        return [f"{res_path}: {', '.join(changed)} {verb} from the results of its runs "
                f"(edited, or written by another version of scenegen: {_RERUN})"]  # fmt: skip
    # Sound and consistent, yet perhaps forged: runs dropped, listed twice or out of order, a
    # built-in tracker's runs said to be not deterministic (so that --deep skips them).
    problems = _pair_problems(root, results, records)
    if problems:
        return _more(problems)
    problems = check_tracks(root, results, records)
    for name, text in texts(results).items():
        path = root / name
        try:
            stored = read_regular_text(path)
        except FileNotFoundError:
            problems.append(f"{path}: missing ({_RERUN})")
        except SpecialFile as err:
            problems.append(f"{err} (remove it, then {_RERUN})")
        except (OSError, UnicodeDecodeError) as err:
            problems.append(f"{path}: unreadable ({type(err).__name__})")
        else:
            if stored != text:
                problems.append(f"{path}: is not the {name} of {RESULTS} (damaged or edited: "
                                f"{_RERUN})")  # fmt: skip
    for name, _, _ in figure_list(results):
        path = root / name
        try:
            data = read_regular(path)
        except FileNotFoundError:
            problems.append(f"{path}: missing ({_RERUN})")
            continue
        except SpecialFile as err:
            problems.append(f"{err} (remove it, then {_RERUN})")
            continue
        except OSError as err:
            problems.append(f"{path}: unreadable ({type(err).__name__})")
            continue
        problem = png_problem(data)
        if problem is not None:
            problems.append(f"{path}: {problem} (damaged)")
    if deep and not problems:
        problems += _check_deep(root, results, records, skipped if skipped is not None else [])
    return _more(problems)


def _pair_problems(root: Path, results: dict[str, Any], records: list[dict[str, Any]]
                   ) -> list[str]:  # fmt: skip
    """The records against what ``results`` says was run: every tracker it lists on every
    one of the dataset's ``count`` sequences, once each, in that order (trackers x
    sequences), all runs of a tracker with the same parameters; and a built-in
    tracker's runs deterministic (a record saying otherwise would be skipped by ``--deep``).
    One line per problem (at most one per kind for the missing runs and the order)."""
    res_path = root / RESULTS
    trackers: list[str] = results["trackers"]
    count: int = results["dataset"]["count"]
    params: dict[str, Any] = {}  # per tracker, the parameters of its first run
    problems: list[str] = []
    seen: set[tuple[str, int]] = set()
    order: list[tuple[str, int]] = []
    for rec in records:
        key = rec["key"]
        tracker, index = key["tracker"], key["index"]
        path = root / _run_file(key)
        if tracker not in trackers:
            problems.append(f"{path}: a run of {tracker!r}, which is not a tracker "
                            f"{RESULTS} lists")  # fmt: skip
            continue
        if not 0 <= index < count:
            problems.append(f"{path}: a run on sequence {index}, which is not one of the "
                            f"dataset's {count}")  # fmt: skip
            continue
        if (tracker, index) in seen:
            problems.append(f"{res_path}: lists the run {_run_file(key)} twice")
            continue
        seen.add((tracker, index))
        order.append((tracker, index))
        if ":" not in tracker and rec["deterministic"] is not True:
            problems.append(f"{path}: says the built-in tracker {tracker!r} is not "
                            "deterministic (every built-in tracker is)")  # fmt: skip
        if params.setdefault(tracker, key["params"]) != key["params"]:
            problems.append(f"{path}: a run of {tracker!r} with other parameters than its "
                            "other runs")  # fmt: skip
    missing = len(trackers) * count - len(seen)
    if missing > 0:
        first = next((t, i) for t in trackers for i in range(count) if (t, i) not in seen)
        problems.append(f"{res_path}: lists no run of {first[0]!r} on sequence {first[1]}"
                        + (f" (nor {missing - 1} more runs)" if missing > 1 else "")
                        + f"; each tracker runs once on each of the dataset's {count} "
                        "sequences")  # fmt: skip
    elif not problems and order != sorted(order, key=lambda p: (trackers.index(p[0]), p[1])):
        problems.append(f"{res_path}: lists the runs out of their order (trackers as listed, "
                        "then sequences)")  # fmt: skip
    return problems


def _check_deep(root: Path, results: dict[str, Any], records: list[dict[str, Any]],
                skipped: list[str]) -> list[str]:  # fmt: skip
    """Every record against the dataset ``results`` names: its key and sequence
    parameters those of the manifest's sequence (with the tracker's parameters), and its
    run computed again on that sequence."""
    import tempfile

    from scenegen.datasets import read_manifest
    from scenegen.lab.benchmark import _tasks, run_pair
    from scenegen.lab.benchmark_tracks import (
        pair_with_tracks,
        sequence_names,
        track_file,
        write_tracks,
    )

    meta = results["dataset"]
    data = Path(str(meta["path"]))
    try:
        man = read_manifest(data)
    except Exception as err:  # noqa: BLE001 - any failure to read it is one line
        return [f"{root / RESULTS}: --deep needs the dataset it was computed on, at {data} "
                f"({str(err)[:120]})"]  # fmt: skip
    if any(man.get(k) != meta[k] for k in ("family_digest", "seed", "count")):
        return [f"{data}: is not the dataset {root / RESULTS} was computed on (another "
                "family, seed or count)"]  # fmt: skip
    try:
        tasks = _tasks(data, man, {t: results["params"][t] for t in results["trackers"]})
    except Exception as err:  # noqa: BLE001 - any failure to read it is one line
        return [f"{data / 'manifest.json'}: cannot list the runs of {root / RESULTS} "
                f"({str(err)[:120]})"]  # fmt: skip
    expected = {(t.tracker, t.index): t for t in tasks}
    problems = []
    for rec in records:
        path = root / _run_file(rec["key"])
        task = expected.get((rec["key"]["tracker"], rec["key"]["index"]))
        if task is None:  # not one of the manifest's sequences (found by _pair_problems)
            problems.append(f"{path}: a run on no sequence of {data}")
            continue
        want = json.loads(json.dumps(task.key(), sort_keys=True))
        wrong = sorted(k for k in set(want) | set(rec["key"])
                       if want.get(k) != rec["key"].get(k))  # fmt: skip
        if wrong:
            problems.append(f"{path}: its key is not the run of {task.tracker!r} on sequence "
                            f"{task.index} of {data} ({', '.join(wrong)} differ)")  # fmt: skip
            continue
        if rec["sequence_params"] != _round(json.loads(task.sequence_params)):
            problems.append(f"{path}: its sequence_params are not those of sequence "
                            f"{task.index} in {data / 'manifest.json'}")  # fmt: skip
            continue
        if not rec["deterministic"]:
            skipped.append(_run_file(rec["key"]))
            continue
        if "tracks" not in results:
            again = json.loads(json.dumps(run_pair(task), sort_keys=True))
            if again != rec:
                problems.append(f"{path}: differs from the run computed again")
            continue
        done = pair_with_tracks(task)
        if json.loads(json.dumps(done[0], sort_keys=True)) != rec:
            problems.append(f"{path}: differs from the run computed again")
        names = sequence_names((r["key"]["index"], r["key"]["name"]) for r in records)
        kept = root / track_file(task.tracker, names[task.index])
        with tempfile.TemporaryDirectory() as tmp:
            write_tracks(Path(tmp) / "t.txt", rec["n_frames"], done[1], done[2])
            if (Path(tmp) / "t.txt").read_bytes() != read_regular(kept):
                problems.append(f"{kept}: differs from the tracks of the run computed again")
    return problems
