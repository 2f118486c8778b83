"""The files an experiment writes and reads back, sealed, and the check of its folder.

An experiment folder ``DIR`` holds one run record per finished run (``DIR/runs/*.json``),
``DIR/results.json``, ``DIR/table.md`` and PNG figures (which nothing reads back).
Records and ``results.json`` are sealed JSON documents
(:mod:`scenegen.io.sealed`: a ``sha256`` key over the canonical content, written
atomically). ``results.json`` also lists, under ``records``, every run file it was
computed from with that file's digest (``"NAME SHA256"``, in run order): the results are
tied to exactly those records.

- A resumed sweep (:func:`scenegen.lab.experiments.runner.execute`) treats a record that
  is damaged, edited, malformed or written by an older version (no digest) as not done:
  it is computed again, with one warning line on stderr; so is a sealed record that
  ``results.json`` lists with another digest (edited after the results were computed).
- :func:`read_results` (the report) raises one :class:`~scenegen.errors.DataError` line
  naming the file for a damaged, edited, malformed or old ``results.json``.
- :func:`check_experiment` (``scenegen validate DIR``) checks everything: each listed
  record reads, matches its digest, its listed digest and its file name, and has the
  record's fields; ``results.json`` equals the summary recomputed from those records (so
  an edit whose digest was recomputed is still found); ``table.md`` is the table of
  ``results.json``; each figure the experiment writes
  (:func:`scenegen.lab.experiments.figures.figure_names`) is there and a whole PNG
  image. With ``deep``, every run is also computed again and compared. When
  only the summary or the table differs, the line names :func:`rerun_command`, which
  recomputes both from the intact runs, and the versions (:data:`WRITTEN_BY`) that
  differ between the software that wrote ``results.json`` and this one.
"""

from __future__ import annotations

import functools
import json
import re
import shlex
import sys
from collections.abc import Callable
from dataclasses import MISSING, fields
from pathlib import Path
from typing import Any

from scenegen.errors import DataError
from scenegen.io.atomic import SpecialFile, read_regular, read_regular_text
from scenegen.io.images import png_problem
from scenegen.io.sealed import content_digest, read_sealed_json, write_sealed_json

__all__ = [
    "RECORDS",
    "WRITTEN_BY",
    "check_experiment",
    "check_report",
    "listed_digest",
    "listing",
    "parse_listing",
    "read_checked",
    "read_record",
    "read_results",
    "record_problems",
    "report_entry",
    "report_rerun_command",
    "rerun_command",
    "source_commit",
    "sweep_of",
    "versions_text",
    "warn",
    "write_record",
    "write_results",
    "written_by",
]

RECORDS = "records"
"""Key of ``results.json``: ``["RUN_FILE SHA256", ...]``, every run it was computed from
(the file's name under ``runs/`` and its digest), in run order."""
WRITTEN_BY = "written_by"
"""Key of ``results.json``: the software that computed it, ``{NAME: VERSION}`` for
scenegen (and its git commit, when run from a checkout), Python and the libraries the
scenes and trackers compute with (absent in files written by older versions). It is
provenance, not a result: ``scenegen validate`` recomputes the rest and compares it, and
names these versions when the rest differs."""
_COMPUTING = ("numpy", "scipy", "numba", "cv2", "skimage", "h5py")
_PER_FRAME = ("state", "precision", "recall", "iou", "centre_error", "path_error")
_MAX_LISTED = 5  # problem lines per folder before "and N more"
_HEX64 = re.compile(r"[0-9a-f]{64}")


_warned: set[str] = set()


def warn(line: str) -> None:
    """Print one warning line on stderr (once per process: a resumed sweep may look at a
    damaged record both when it plans its tasks and when it collects them).

    Parameters
    ----------
    line : str
        The warning, printed after ``"scenegen: warning: "``.
    """
    if line in _warned:
        return
    _warned.add(line)
    print(f"scenegen: warning: {line}", file=sys.stderr, flush=True)


def write_record(path: Path, record: dict[str, Any]) -> str:
    """Write a run record sealed and atomically (creating ``runs/``); return its digest.

    Parameters
    ----------
    path : pathlib.Path
        The run file (``DIR/runs/NAME.json``); missing parent folders are created.
    record : dict
        The run record (JSON-ready).

    Returns
    -------
    str
        The SHA-256 of its canonical content (hex), the digest stored in the file.
    """
    return write_sealed_json(path, record, parents=True)


def _numbers(x: Any, allow_bool: bool = True) -> bool:
    """True if every leaf of ``x`` (lists and dicts) is a number, None (or a bool)."""
    if x is None:
        return True
    if isinstance(x, bool):
        return allow_bool
    if isinstance(x, (int, float)):
        return True
    if isinstance(x, list):
        return all(_numbers(v, allow_bool) for v in x)
    if isinstance(x, dict):
        return all(_numbers(v, allow_bool) for v in x.values())
    return False


def record_problems(data: Any) -> list[str]:
    """What is wrong with the fields of a run record (empty when none is).

    Parameters
    ----------
    data : Any
        A parsed run record (without its digest).

    Returns
    -------
    list of str
        One line per problem: not an object, a ``key`` that is not a
        :class:`~scenegen.lab.experiments.runner.Task`'s, a missing or mistyped field, a
        target whose per-frame lists are not ``n_frames`` numbers, a non-numeric
        diagnostic, no ``failure_threshold``.
    """
    from scenegen.lab.experiments.runner import Task

    if not isinstance(data, dict):
        return ["not a run record (a JSON object is expected)"]
    out = []
    key = data.get("key")
    names = {f.name for f in fields(Task)}
    required = {f.name for f in fields(Task) if f.default is MISSING}  # others: optional
    if not isinstance(key, dict) or not required <= set(key) <= names:
        out.append("key is not a run key")
    else:
        try:
            Task(**key).filename()
        except (TypeError, ValueError):
            out.append("key is not a run key")
    for name, kind in (("tracker", str), ("params", dict), ("scene_digest", str),
                       ("scene_seed", int), ("tracker_seed", int), ("n_frames", int)):  # fmt: skip
        if not isinstance(data.get(name), kind) or isinstance(data.get(name), bool):
            out.append(f"{name} is missing or not a {kind.__name__}")
    n = data.get("n_frames")
    targets = data.get("targets")
    if not isinstance(targets, list) or not targets:
        out.append("targets is missing or empty")
        targets = []
    for i, t in enumerate(targets):
        if not isinstance(t, dict) or not isinstance(t.get("name"), str):
            out.append(f"targets[{i}] is not a target")
            continue
        for f in _PER_FRAME:
            v = t.get(f)
            if v is None and f == "path_error":
                continue
            if not (isinstance(v, list) and len(v) == n and _numbers(v, allow_bool=False)):
                out.append(f"targets[{i}].{f} is not {n} numbers")
    for name in ("failure_threshold", "uniqueness", "effective_dynamics", "order_prob",
                 "orderings", "true_order", "depth_order_accuracy", "overlap"):  # fmt: skip
        if name in data and not _numbers(data[name]):
            out.append(f"{name} is not numeric")
    if "failure_threshold" not in data:
        out.append("failure_threshold is missing")
    return out


def read_record(path: Path) -> dict[str, Any]:
    """The run record at ``path`` (without its digest).

    Parameters
    ----------
    path : pathlib.Path
        A sealed run file (``DIR/runs/NAME.json``).

    Returns
    -------
    dict
        The record's content, checked by :func:`record_problems`.

    Raises
    ------
    DataError
        One line: missing, damaged, edited, written by an older version
        (:class:`scenegen.io.sealed.Unsealed`), or not a run record.
    """
    return read_checked(path, record_problems, "a run record")


def read_checked(path: Path, problems_of: Callable[[Any], list[str]], what: str
                 ) -> dict[str, Any]:  # fmt: skip
    """The sealed document at ``path`` (without its digest) when ``problems_of`` finds
    nothing wrong with its content, else one DataError line: ``PATH: not WHAT (the first
    problem)``; as :func:`scenegen.io.sealed.read_sealed_json` for a damaged file.

    Parameters
    ----------
    path : pathlib.Path
        A sealed JSON document.
    problems_of : callable
        Takes the content, returns the list of its problems (empty when sound).
    what : str
        What the document should be, for the error line (``"a run record"``).

    Returns
    -------
    dict
        The content, without its digest.

    Raises
    ------
    DataError
        Missing, unreadable, damaged or edited, unsealed
        (:class:`scenegen.io.sealed.Unsealed`), or a content with a problem.
    """
    data = read_sealed_json(path)
    problems = problems_of(data)
    if problems:
        raise DataError(f"{path}: not {what} ({problems[0]})")
    return data


def listing(records: list[dict[str, Any]]) -> list[str]:
    """The :data:`RECORDS` entry of ``results.json`` for ``records`` (in run order).

    Parameters
    ----------
    records : list of dict
        Run records, without digest.

    Returns
    -------
    list of str
        ``"NAME SHA256"`` per record: its run file name and the SHA-256 of its canonical
        content.
    """
    from scenegen.lab.experiments.runner import Task

    return [f"{Task(**r['key']).filename()} {content_digest(r)}" for r in records]


def _entries(results: dict[str, Any]) -> list[tuple[str, str]] | None:
    return parse_listing(results.get(RECORDS))


def parse_listing(entries: Any) -> list[tuple[str, str]] | None:
    """``[(NAME, SHA256), ...]`` of a :data:`RECORDS` listing, or None when it is not a
    non-empty list of ``"NAME SHA256"`` strings.

    Parameters
    ----------
    entries : Any
        The listing as read (the digest is the last word; a name may hold spaces).

    Returns
    -------
    list of (str, str) or None
        The name and the 64-hex-digit digest of each entry, in order.

    Examples
    --------
    >>> parse_listing(["a b.json " + "0" * 64])[0][0]
    'a b.json'
    >>> parse_listing([]) is None
    True
    """
    if not isinstance(entries, list) or not entries:
        return None
    out = []
    for e in entries:
        # The digest is the last word; a run's file name may hold spaces (a list-valued
        # --param gives "sigma-(1, 1, 0.001)").
        name, _, digest = e.rpartition(" ") if isinstance(e, str) else ("", "", "")
        if not name or not _HEX64.fullmatch(digest):
            return None
        out.append((name, digest))
    return out


@functools.lru_cache(maxsize=4)
def _listed(path: Path, version: tuple[int, int, int]) -> tuple[int, bool, dict[str, str]]:
    try:
        res = read_results(path)
    except DataError:
        return (-1, False, {})
    return (res["seed"], res["quick"], dict(_entries(res) or []))


def listed_digest(record_path: Path, seed: int, quick: bool) -> str | None:
    """The digest that ``DIR/results.json`` lists for the run file ``DIR/runs/NAME``, or
    None (no sound ``results.json`` of that base seed and mode, or the run not listed).

    Parameters
    ----------
    record_path : pathlib.Path
        The run file, ``DIR/runs/NAME``.
    seed : int
        The sweep's base seed.
    quick : bool
        The sweep's quick flag.

    Returns
    -------
    str or None
        The listed SHA-256 (hex).
    """
    res = record_path.parent.parent / "results.json"
    try:
        st = res.stat()
    except OSError:
        return None
    s, q, listed = _listed(res, (st.st_ino, st.st_size, st.st_mtime_ns))
    if (s, q) != (seed, quick):
        return None
    return listed.get(record_path.name)


def source_commit(root: str | Path | None = None, timeout: float = 5.0) -> str | None:
    """The git commit of the scenegen source that runs, when it runs from a checkout.

    Parameters
    ----------
    root : str or Path, optional
        The checkout to ask (a folder with ``pyproject.toml`` and ``.git``); by default
        the one the imported ``scenegen`` package lies in.
    timeout : float, optional
        Seconds each ``git`` call may take (a slow or damaged repository gives None,
        never a hang).

    Returns
    -------
    str or None
        The commit's first 12 hex digits, with ``+dirty`` when tracked files differ
        from it; None for an installed wheel, without git, or outside a scenegen checkout.
    """
    import subprocess

    import scenegen

    src = Path(scenegen.__file__).resolve().parent.parent if root is None else Path(root)
    if not (src / "pyproject.toml").is_file() or not (src / ".git").exists():
        return None

    def git(*args: str) -> str | None:
        try:
            done = subprocess.run(["git", "-C", str(src), *args], capture_output=True,
                                  text=True, timeout=timeout, check=False)  # fmt: skip
        except (OSError, subprocess.TimeoutExpired):
            return None
        return done.stdout.strip() if done.returncode == 0 else None

    head = git("rev-parse", "--verify", "--quiet", "HEAD")
    if not head:
        return None
    changed = git("status", "--porcelain", "--untracked-files=no")
    if changed is None:
        return None
    return head[:12] + ("+dirty" if changed else "")


@functools.lru_cache(maxsize=1)
def _versions() -> tuple[tuple[str, str], ...]:
    import importlib
    import platform

    import scenegen

    names = {"cv2": "opencv", "skimage": "scikit-image"}
    out = [("scenegen", scenegen.__version__)]
    commit = source_commit()
    if commit is not None:
        out.append(("scenegen commit", commit))
    out.append(("python", platform.python_version()))
    for module in _COMPUTING:
        out.append((names.get(module, module), str(importlib.import_module(module).__version__)))
    return tuple(out)


def written_by() -> dict[str, str]:
    """The :data:`WRITTEN_BY` entry for results computed here.

    Returns
    -------
    dict of str to str
        ``{"scenegen": ..., "python": ..., "numpy": ..., "scipy": ..., "numba": ...,
        "opencv": ..., "scikit-image": ..., "h5py": ...}``, the installed versions, with
        ``"scenegen commit"`` after ``"scenegen"`` when it runs from a git checkout
        (:func:`source_commit`: a version number cannot tell two commits apart).
    """
    return dict(_versions())


def versions_text(who: dict[str, str]) -> str:
    """A :data:`WRITTEN_BY` entry as a phrase, ``"scenegen 0.1.0, python 3.11.7, ..."``, in
    :func:`written_by`'s order whatever the file's key order (sealed files sort keys).

    Parameters
    ----------
    who : dict of str to str
        Software name -> version; names :func:`written_by` does not give come last, by
        name.

    Returns
    -------
    str
        ``"NAME VERSION"`` per entry, joined by ``", "``.
    """
    known = [name for name, _ in _versions()]
    order = sorted(who, key=lambda k: (known.index(k) if k in known else len(known), k))
    return ", ".join(f"{k} {who[k]}" for k in order)


def _version_change(then: Any, now: dict[str, str]) -> str:
    """What differs between the software that wrote a ``results.json`` and this one, as a
    phrase (empty when nothing is known to differ)."""
    if not isinstance(then, dict):
        return " (it records no versions: an older scenegen)"
    diff = [f"{k} {then.get(k, '?')} there, {v} here" for k, v in now.items()
            if then.get(k) != v]  # fmt: skip
    return f" ({'; '.join(diff)})" if diff else ""


def write_results(path: Path, results: dict[str, Any]) -> None:
    """Write ``results.json`` sealed and atomically (indented: users read it).

    Parameters
    ----------
    path : pathlib.Path
        The file to write.
    results : dict
        The experiment's results (JSON-ready).
    """
    write_sealed_json(path, results, indent=1)


def read_results(path: Path, name: str | None = None) -> dict[str, Any]:
    """The content of an experiment's ``results.json`` (without its digest).

    Parameters
    ----------
    path : Path
        The ``results.json`` file.
    name : str, optional
        The experiment it must belong to.

    Returns
    -------
    dict
        Its content: a known ``experiment``, ``runs``, ``scenes``, ``seed``, ``quick``,
        ``indicative``, ``claims`` (each with a verdict), ``summary``, a :data:`RECORDS`
        listing, and :data:`WRITTEN_BY` when present.

    Raises
    ------
    DataError
        One line naming the file: missing, damaged, edited, written by an older version
        (run the experiment again to recompute it), or not an experiment's results.
    """
    from scenegen.io.sealed import Unsealed

    try:
        data = read_sealed_json(path)
    except Unsealed as err:
        raise DataError(f"{err}: run the experiment again into its folder to recompute "
                        "it") from None  # fmt: skip
    problem = _results_problem(data, name)
    if problem:
        raise DataError(f"{path}: not an experiment's results ({problem})")
    return data


def _results_problem(data: dict[str, Any], name: str | None) -> str | None:
    from scenegen.lab.experiments.definitions import names

    exp = data.get("experiment")
    if not isinstance(exp, str) or exp not in names():
        return "experiment is missing or unknown"
    if name is not None and exp != name:
        return f"experiment is {exp!r}, expected {name!r}"
    for key, kind in (("runs", int), ("scenes", int), ("seed", int), ("quick", bool),
                      ("indicative", bool), ("claims", list), ("summary", dict)):  # fmt: skip
        if not isinstance(data.get(key), kind):
            return f"{key} is missing or not a {kind.__name__}"
    if not all(isinstance(c, dict) and isinstance(c.get("verdict"), str)
               and c["verdict"] in ("reproduced", "not reproduced", "inconclusive")
               for c in data["claims"]):  # fmt: skip
        return "claims has an entry without a verdict"
    if _entries(data) is None:
        return f"{RECORDS} is missing or not a list of 'RUN_FILE SHA256'"
    who = data.get(WRITTEN_BY, {})
    if not (isinstance(who, dict) and all(isinstance(k, str) and isinstance(v, str)
                                          for k, v in who.items())):  # fmt: skip
        return f"{WRITTEN_BY} is not a mapping of names to versions"
    return None


def _more(problems: list[str]) -> list[str]:
    if len(problems) <= _MAX_LISTED:
        return problems
    return [*problems[:_MAX_LISTED], f"... and {len(problems) - _MAX_LISTED} more problems"]


def sweep_of(keys: list[dict[str, Any]]) -> tuple[int, int, int, bool]:
    """R, S, the base seed and the quick flag of a sweep, from its runs' ``key``s.

    Parameters
    ----------
    keys : list of dict
        The ``key`` of each run record (non-empty); the seed and quick flag are the
        first one's.

    Returns
    -------
    runs, scenes, seed : int
        The largest ``run`` + 1, the largest ``scene`` + 1, the base seed.
    quick : bool
        The quick flag.
    """
    runs = max(k["run"] for k in keys) + 1
    scenes = max(k["scene"] for k in keys) + 1
    return runs, scenes, int(keys[0]["seed"]), bool(keys[0]["quick"])


def rerun_command(exp: Any, keys: list[dict[str, Any]], folder: str | Path) -> str:
    """The ``scenegen experiment`` command that plans exactly the runs of ``keys``.

    Run into ``folder``, it resumes: the intact runs are kept and ``results.json`` and
    ``table.md`` are computed again from them (what a summary written by another version
    of scenegen needs).

    Parameters
    ----------
    exp : Experiment
        The experiment the runs belong to.
    keys : list of dict
        The ``key`` of each run record (S, R, base seed, quick flag, methods, swept values
        and overrides are read from them).
    folder : str or Path
        The experiment folder.

    Returns
    -------
    str
        A shell command line, e.g. ``scenegen experiment shm-depth --runs 1 -o out/shm``.
    """
    runs, scenes, seed, quick = sweep_of(keys)
    args = ["scenegen", "experiment", exp.name]
    if scenes != exp.scenes:
        args += ["--scenes", str(scenes)]
    if runs != exp.runs:
        args += ["--runs", str(runs)]
    if seed:
        args += ["--seed", str(seed)]
    if quick:
        args.append("--quick")
    return shlex.join([*args, *_restriction_args(exp, keys), "-o", str(folder)])


def _restriction_args(exp: Any, keys: list[dict[str, Any]]) -> list[str]:
    """The ``--method``, ``--value`` and ``--param`` options that plan the runs of ``keys``
    (none for a sweep of every method and value without overrides)."""
    args: list[str] = []
    quick = sweep_of(keys)[3]
    chosen = {k["method"] for k in keys}
    if chosen != {m.slug for m in exp.methods}:
        for m in exp.methods:
            if m.slug in chosen:
                args += ["--method", m.slug]
    values = sorted({float(k["value"]) for k in keys if k["param"]})
    if values and values != sorted(float(v) for _, v in exp.sweep_values(quick)):
        for v in values:
            args += ["--value", f"{v:g}"]
    for name, value in sorted(map(tuple, keys[0].get("overrides") or ())):
        text = value if isinstance(value, str) else json.dumps(value)
        args += ["--param", f"{name}={text}"]
    return args


def report_rerun_command(sweeps: dict[str, list[dict[str, Any]]], folder: str | Path
                         ) -> str | None:  # fmt: skip
    """The command that writes a report folder's ``results.json`` and ``index.html`` again
    from its intact experiments, or None when no one command planned them all.

    Parameters
    ----------
    sweeps : dict
        Per experiment name, the ``key`` of each of its run records.
    folder : str or Path
        The report folder.

    Returns
    -------
    str or None
        ``scenegen demo -o DIR`` for the demo's counts (:data:`DEMO_PLAN`, base seed 0),
        else ``scenegen experiment all ... -o DIR`` when every experiment ran every method
        and value without ``--param`` and one ``--scenes``/``--runs``/``--seed``/``--quick``
        fits them all; run into the folder, either resumes without computing a run again.
    """
    from scenegen.lab.experiments.definitions import DEMO_PLAN, get, names

    if set(sweeps) != set(names()):
        return None  # `all` would run the missing experiments: not a repair
    exps = {name: get(name) for name in sweeps}
    if any(_restriction_args(exps[n], keys) for n, keys in sweeps.items()):
        return None
    plans = {n: sweep_of(keys) for n, keys in sweeps.items()}  # (R, S, seed, quick)
    if len({p[2] for p in plans.values()}) != 1 or len({p[3] for p in plans.values()}) != 1:
        return None
    seed, quick = next(iter(plans.values()))[2:]
    if all((s, r, q) == DEMO_PLAN[n] for n, (r, s, _, q) in plans.items()) and seed == 0:
        return shlex.join(["scenegen", "demo", "-o", str(folder)])
    args = ["scenegen", "experiment", "all"]
    for flag, at, default in (("--scenes", 1, "scenes"), ("--runs", 0, "runs")):
        if all(p[at] == getattr(exps[n], default) for n, p in plans.items()):
            continue
        if len({p[at] for p in plans.values()}) != 1:
            return None
        args += [flag, str(next(iter(plans.values()))[at])]
    if seed:
        args += ["--seed", str(seed)]
    if quick:
        args.append("--quick")
    return shlex.join([*args, "-o", str(folder)])


def check_experiment(folder: str | Path, *, deep: bool = False) -> list[str]:
    """Check an experiment folder; one line per problem, empty when it is sound.

    Parameters
    ----------
    folder : str or Path
        A folder written by ``scenegen experiment NAME -o DIR``.
    deep : bool
        Also run every listed run again (same seeds) and compare it with its record: finds
        a record edited with its digests recomputed everywhere.

    Returns
    -------
    list of str
        Each line names the file at fault (at most a few per kind, then a count).
    """
    return _check_experiment(folder, deep)[0]


def _check_experiment(folder: str | Path, deep: bool) -> tuple[list[str], list[dict[str, Any]]]:
    """:func:`check_experiment`'s lines, and the ``key`` of every record it read."""
    from scenegen.lab.experiments import results_document
    from scenegen.lab.experiments.definitions import get
    from scenegen.lab.experiments.figures import figure_names
    from scenegen.lab.experiments.runner import Task, run_task
    from scenegen.lab.experiments.tables import render_table
    from scenegen.lab.experiments.why import WHY

    root = Path(folder)
    res_path = root / "results.json"
    try:
        results = read_results(res_path)
    except DataError as err:
        return [str(err)], []
    exp = get(results["experiment"])
    problems: list[str] = []
    records: list[dict[str, Any]] = []
    entries = _entries(results) or []
    for name, digest in entries:
        path = root / "runs" / name
        if Path(name).name != name or not name.endswith(".json"):
            problems.append(f"{res_path}: {RECORDS} names {name!r}, not a run file")
            continue
        try:
            rec = read_record(path)
        except DataError as err:
            problems.append(str(err))
            continue
        if Task(**rec["key"]).filename() != name:
            problems.append(f"{path}: holds the run {Task(**rec['key']).filename()!r}")
        elif content_digest(rec) != digest:
            problems.append(f"{path}: is not the run {res_path.name} was computed from "
                            "(edited or replaced since)")  # fmt: skip
        records.append(rec)
    keys = [r["key"] for r in records]
    if problems:
        return _more(problems), keys
    try:
        fresh = results_document(exp, records)
    except Exception as err:  # noqa: BLE001 - sound digests, yet contents no summary expects
        return [f"{res_path}: its runs cannot be summarised ({type(err).__name__}: "
                f"{str(err)[:80]})"], keys  # fmt: skip
    # The runs are intact (digests above), so a summary or table that differs was edited,
    # or written by a scenegen that summarises differently; the hint says how to redo it,
    # and which versions differ. Who wrote the file is provenance, not compared.
    def redo() -> str:
        command = rerun_command(exp, keys, root)
        change = _version_change(results.get(WRITTEN_BY), fresh[WRITTEN_BY])
        return (f"or written by another version of scenegen{change}: `{command}` "
                "recomputes it from the runs")  # fmt: skip

    changed = sorted(k for k in set(fresh) | set(results)
                     if k != WRITTEN_BY and fresh.get(k) != results.get(k))  # fmt: skip
    if changed:
        verb = "differs" if len(changed) == 1 else "differ"
        problems.append(f"{res_path}: {', '.join(changed)} {verb} from the summary of its runs "
                        f"(edited, {redo()})")  # fmt: skip
    table = root / "table.md"
    try:
        text = read_regular_text(table)
    except FileNotFoundError:
        problems.append(f"{table}: missing")
    except SpecialFile as err:
        problems.append(f"{err} (remove it, then `{rerun_command(exp, keys, root)}` writes "
                        "the table again)")  # fmt: skip
    except (OSError, UnicodeDecodeError) as err:
        problems.append(f"{table}: unreadable ({type(err).__name__})")
    else:
        shown = {k: v for k, v in fresh.items() if k != WRITTEN_BY}
        if WRITTEN_BY in results:  # the table names who wrote results.json
            shown[WRITTEN_BY] = results[WRITTEN_BY]
        if text != render_table(exp, shown, WHY.get(exp.name, "")):
            problems.append(f"{table}: is not the table of {res_path.name} (damaged, edited, "
                            f"{redo()})")  # fmt: skip
    for name in figure_names(exp.name, fresh, records):
        problems += _figure_problems(root / name, lambda: rerun_command(exp, keys, root))
    if deep and not problems:
        for (name, _), rec in zip(entries, records, strict=True):
            again = json.loads(json.dumps(run_task(Task(**rec["key"])), sort_keys=True))
            if again != rec:
                problems.append(f"{root / 'runs' / name}: differs from the run computed again")
    return _more(problems), keys


def _figure_problems(path: Path, command: Callable[[], str]) -> list[str]:
    """A figure the experiment writes: there, a regular file, and a whole PNG image
    (:func:`scenegen.io.images.png_problem`; nothing reads it back, so it is not compared
    with anything); ``command()`` writes it again."""
    try:
        data = read_regular(path)
    except FileNotFoundError:
        return [f"{path}: missing (`{command()}` writes it again)"]
    except SpecialFile as err:
        return [f"{err} (remove it, then `{command()}` writes it again)"]
    except OSError as err:
        return [f"{path}: unreadable ({type(err).__name__})"]
    problem = png_problem(data)
    if problem is not None:
        return [f"{path}: {problem} (damaged: `{command()}` writes it again)"]
    return []


def check_report(folder: str | Path,
                 index_problem: Callable[[Path], str | None] | None = None) -> list[str]:
    """Check a report folder (``scenegen experiment all -o DIR``): every experiment in
    ``DIR/experiments/`` (:func:`check_experiment`) and ``DIR/results.json``, which must
    hold exactly their results; and, given ``index_problem`` (what is wrong with
    ``DIR/index.html``, or None: :func:`scenegen.lab.report.index_problem`), the page.

    Parameters
    ----------
    folder : str or pathlib.Path
        The report folder.
    index_problem : callable, optional
        Takes the folder, returns what is wrong with its ``index.html`` (``"stale"`` for
        a page that is not this folder's report) or None; None: the page is not checked.

    Returns
    -------
    list of str
        One line per problem, naming the file at fault (with the command that writes it
        again when one command can); empty when the folder is sound.
    """
    from scenegen.lab.experiments.definitions import names

    root = Path(folder)
    problems: list[str] = []
    expected: dict[str, Any] = {}
    sweeps: dict[str, list[dict[str, Any]]] = {}
    for name in names():
        sub = root / "experiments" / name
        if not (sub / "results.json").exists():
            continue
        found, sweeps[name] = _check_experiment(sub, False)
        problems += found
        if not found:
            expected[name] = report_entry(read_results(sub / "results.json", name))
    path = root / "results.json"
    try:
        doc = read_sealed_json(path)
    except DataError as err:
        return [*problems, str(err)]
    if problems:
        return problems

    def redo(tail: str) -> str:  # the hint, computed only for a line that needs it
        command = report_rerun_command(sweeps, root)
        return f"; `{command}` writes it again{tail}" if command else ""

    if doc.get("experiments") != expected:
        return [f"{path}: does not hold the results of {root / 'experiments'} "
                f"(edited or stale{redo(' from them')})"]  # fmt: skip
    page = index_problem(root) if index_problem is not None else None
    if page == "stale":
        page = f"is not the report of this folder (damaged, edited, or stale{redo('')})"
    elif page is not None:
        page = f"{page}{redo('')}"
    if page is not None:
        problems.append(f"{root / 'index.html'}: {page}")
    return problems


def report_entry(results: dict[str, Any]) -> dict[str, Any]:
    """An experiment's results as the report's ``results.json`` holds them (no listing).

    Parameters
    ----------
    results : dict
        The content of an experiment's ``results.json``.

    Returns
    -------
    dict
        A copy without the :data:`RECORDS` key.
    """
    return {k: v for k, v in results.items() if k != RECORDS}
