"""The tracker outputs of a benchmark, kept for TrackEval (``scenegen benchmark --keep-tracks``).

With ``--keep-tracks`` a benchmark also writes ``OUT/trackeval/``, a folder laid out as
TrackEval's ``scripts/run_mot_challenge.py`` expects it (benchmark :data:`BENCHMARK`,
split :data:`SPLIT`)::

    trackeval/gt/mot_challenge/seqmaps/scenegen-all.txt      every sequence
    trackeval/gt/mot_challenge/seqmaps/scenegen-multi.txt    those with several targets
    trackeval/gt/mot_challenge/scenegen-all/SEQ/gt/gt.txt
    trackeval/gt/mot_challenge/scenegen-all/SEQ/seqinfo.ini
    trackeval/trackers/mot_challenge/scenegen-all/TRACKER/data/SEQ.txt

``SEQ`` is the sequence's name in the dataset (:func:`sequence_names`), ``TRACKER`` the
name of its run folder under ``OUT/runs/``. The ground truth is the one the benchmark
scores with, ``amodal`` (:data:`GT_MODE`, :mod:`scenegen.io.mot`): ``gt.txt`` holds every
target's box in every frame where it is in the scene, written by
:func:`scenegen.io.mot.gt_rows`; ``seqinfo.ini`` is :func:`scenegen.io.export.seqinfo_text`.
Each tracker file is the tracker's boxes on that sequence
(:func:`scenegen.io.mot.write_mot_tracker`, 1-based pixels); it is empty on a sequence
without a target at frame 0, where the tracker is not run. The leaderboard's "(combined)"
columns take the sequences with several targets as one: TrackEval's ``COMBINED_SEQ`` row
with the seqmap ``scenegen-multi.txt`` (``--SEQMAP_FILE``).

Every file is written atomically. ``results.json`` lists them under ``tracks``
(``"trackeval/... SHA256"``, the digest of the file's bytes), a key it has only when the
tracks are kept; a run record is the same with or without them. Until ``results.json``
lists them (it is written last), each pair's tracker file has a sealed note in
:data:`PENDING`, written after the file and its run record: the file's digest and the
record's. A resumed benchmark keeps a file whose digest is the one listed (with the run
record listed beside it) or the one its note gives (with that run record), and runs its
pair again otherwise; the run record it gives must be the stored one. So a benchmark
interrupted after writing some tracks resumes without running their pairs again; the
notes are removed once ``results.json`` lists the files.
:func:`check_tracks` is the part of ``scenegen validate OUT`` that checks the folder.
"""

from __future__ import annotations

import hashlib
import re
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "BENCHMARK",
    "FOLDER",
    "GT_MODE",
    "PENDING",
    "SPLIT",
    "check_tracks",
    "file_digest",
    "gt_files",
    "kept_files",
    "listed_tracks",
    "pending_file",
    "pending_sound",
    "pair_with_tracks",
    "prepare_folder",
    "remove_pending",
    "remove_unlisted",
    "seqmap_file",
    "seqmap_text",
    "sound_file",
    "sequence_names",
    "track_file",
    "unlisted",
    "write_gt",
    "write_pending",
    "write_tracks",
]

FOLDER = "trackeval"
"""The folder of the kept tracks in the benchmark's output folder."""
BENCHMARK = "scenegen"
"""TrackEval's ``--BENCHMARK`` of the kept folder."""
SPLIT = "all"
"""TrackEval's ``--SPLIT_TO_EVAL`` of the kept folder."""
MULTI = "multi"
"""The seqmap ``scenegen-multi.txt``: the sequences with several targets."""
GT_MODE = "amodal"
"""The ground-truth mode the benchmark scores with (:func:`scenegen.evaluation.evaluate`'s
default) and the kept ``gt.txt`` files are written in."""

PENDING = "tracks-pending"
"""The folder, in the output folder, of the notes of the tracker files written since
``results.json`` last listed them (:func:`write_pending`)."""

_GT = f"{FOLDER}/gt/mot_challenge"
_TRACKERS = f"{FOLDER}/trackers/mot_challenge/{BENCHMARK}-{SPLIT}"
_SAFE = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]*")


def sequence_names(entries: Iterable[tuple[int, str]]) -> dict[int, str]:
    """TrackEval's name of each sequence: its name in the dataset, or ``seq-NNNNN`` for
    every sequence when one name is not a safe file name or two are the same.

    Parameters
    ----------
    entries : iterable of (int, str)
        Each sequence's index and name (from the manifest, or from the run records).

    Returns
    -------
    dict of int to str
        Index -> folder and file name in the kept folder.

    Examples
    --------
    >>> sequence_names([(0, "two-00000"), (1, "two-00001")])
    {0: 'two-00000', 1: 'two-00001'}
    >>> sequence_names([(0, "a b"), (1, "c")])
    {0: 'seq-00000', 1: 'seq-00001'}
    """
    names = dict(entries)
    safe = all(_SAFE.fullmatch(n) for n in names.values())
    if safe and len(set(names.values())) == len(names):
        return {i: names[i] for i in sorted(names)}
    return {i: f"seq-{i:05d}" for i in sorted(names)}


def seqmap_file(split: str = SPLIT) -> str:
    """The seqmap of ``split`` (``all`` or ``multi``), relative to the output folder.

    Parameters
    ----------
    split : str
        ``all`` (every sequence) or ``multi`` (those with several targets).

    Returns
    -------
    str
        ``trackeval/gt/mot_challenge/seqmaps/scenegen-SPLIT.txt``.
    """
    return f"{_GT}/seqmaps/{BENCHMARK}-{split}.txt"


def gt_files(seq: str) -> tuple[str, str]:
    """The ``gt.txt`` and ``seqinfo.ini`` of the sequence ``seq``, relative to the output
    folder.

    Parameters
    ----------
    seq : str
        TrackEval's name of the sequence (:func:`sequence_names`).

    Returns
    -------
    (str, str)
        ``trackeval/gt/mot_challenge/scenegen-all/SEQ/gt/gt.txt`` and ``.../SEQ/seqinfo.ini``.
    """
    base = f"{_GT}/{BENCHMARK}-{SPLIT}/{seq}"
    return f"{base}/gt/gt.txt", f"{base}/seqinfo.ini"


def track_file(tracker: str, seq: str) -> str:
    """The tracker file of ``tracker`` on the sequence ``seq``, relative to the output folder.

    Parameters
    ----------
    tracker : str
        A tracker as given to the benchmark (its run folder's name is used).
    seq : str
        TrackEval's name of the sequence (:func:`sequence_names`).

    Returns
    -------
    str
        ``trackeval/trackers/mot_challenge/scenegen-all/TRACKER/data/SEQ.txt``.
    """
    from scenegen.lab.benchmark import run_file

    return f"{_TRACKERS}/{run_file(tracker, 0).split('/')[1]}/data/{seq}.txt"


def kept_files(trackers: list[str], names: dict[int, str]) -> list[str]:
    """Every file of the kept folder, in the order ``results.json`` lists them: the two
    seqmaps, each sequence's ``gt.txt`` and ``seqinfo.ini``, then each tracker's files.

    Parameters
    ----------
    trackers : list of str
        The benchmark's trackers, in order.
    names : dict of int to str
        :func:`sequence_names`.

    Returns
    -------
    list of str
        Paths relative to the output folder.
    """
    out = [seqmap_file(SPLIT), seqmap_file(MULTI)]
    for i in sorted(names):
        out += gt_files(names[i])
    out += [track_file(t, names[i]) for t in trackers for i in sorted(names)]
    return out


def seqmap_text(seqs: list[str]) -> str:
    """A TrackEval seqmap: the header ``name``, then one sequence per line.

    Parameters
    ----------
    seqs : list of str
        Sequence names, in order.

    Returns
    -------
    str
        The file's text.
    """
    return "".join(f"{s}\n" for s in ["name", *seqs])


def file_digest(path: Path) -> str | None:
    """SHA-256 of a file's bytes, or None when it cannot be read.

    Parameters
    ----------
    path : pathlib.Path
        The file.

    Returns
    -------
    str or None
        64 hex digits; None also for a FIFO, a device or a socket (never waited on).
    """
    from scenegen.io.atomic import SpecialFile, read_regular

    try:
        return hashlib.sha256(read_regular(path)).hexdigest()
    except (OSError, SpecialFile):
        return None


def pair_with_tracks(task: Any) -> tuple[dict[str, Any], Any, Any]:
    """Run a benchmark pair and keep its boxes (the worker of ``--keep-tracks``).

    Parameters
    ----------
    task : scenegen.lab.benchmark.BenchTask
        The tracker and the sequence.

    Returns
    -------
    record : dict
        :func:`scenegen.lab.benchmark.run_pair`'s record.
    track_ids : ndarray of int, shape (M,), or None
        The ids of the tracks (the targets' entity ids); None when the tracker was not run.
    boxes : ndarray of shape (T, M, 4), or None
        The tracker's boxes, 0-based pixels.
    """
    from scenegen.lab.benchmark import run_pair_tracks

    rec, res = run_pair_tracks(task)
    if res is None:
        return rec, None, None
    return rec, np.asarray(res.target_ids), np.asarray(res.boxes)


def write_tracks(path: Path, n_frames: int, track_ids: Any, boxes: Any) -> None:
    """Write a pair's tracker file atomically (its folders made as needed); an empty file
    when the tracker was not run (``track_ids`` None).

    Parameters
    ----------
    path : pathlib.Path
        The tracker file (:func:`track_file` in the output folder).
    n_frames : int
        The sequence's frames (for an empty result).
    track_ids, boxes : array_like or None
        As :func:`pair_with_tracks` returns them.
    """
    from scenegen.io.mot import write_mot_tracker

    path.parent.mkdir(parents=True, exist_ok=True)
    if track_ids is None:
        track_ids, boxes = np.zeros(0, np.int64), np.zeros((n_frames, 0, 4))
    write_mot_tracker(path, boxes, track_ids)


def write_gt(out: Path, root: Path, entries: list[dict[str, Any]], names: dict[int, str],
             multi: list[int], keep: set[str]) -> None:  # fmt: skip
    """Write the seqmaps and each sequence's ``gt.txt`` and ``seqinfo.ini`` atomically,
    but the files of ``keep`` (found sound).

    Parameters
    ----------
    out : pathlib.Path
        The benchmark's output folder.
    root : pathlib.Path
        The dataset folder.
    entries : list of dict
        The manifest's sequences (``index``, ``name``, ``file``).
    names : dict of int to str
        :func:`sequence_names`.
    multi : list of int
        The indices of the sequences with several targets, in order.
    keep : set of str
        Files (relative to ``out``) left as they are.
    """
    from scenegen.io import read
    from scenegen.io.atomic import write_text
    from scenegen.io.export import seqinfo_text
    from scenegen.io.mot import gt_rows

    write_text(out / seqmap_file(SPLIT), seqmap_text([names[i] for i in sorted(names)]),
               parents=True)  # fmt: skip
    write_text(out / seqmap_file(MULTI), seqmap_text([names[i] for i in multi]), parents=True)
    for e in sorted(entries, key=lambda e: e["index"]):
        gt, ini = gt_files(names[e["index"]])
        if gt in keep and ini in keep:
            continue
        seq = read(root / e["file"], e["name"])
        rows = "".join(f"{r}\n" for t in range(seq.n_frames) for r in gt_rows(seq, t, GT_MODE))
        write_text(out / gt, rows, parents=True)
        write_text(out / ini, seqinfo_text(seq), parents=True)


def check_tracks(root: Path, results: dict[str, Any], records: list[dict[str, Any]]
                 ) -> list[str]:  # fmt: skip
    """The kept folder against ``results.json``'s ``tracks`` listing; one line per problem.

    Every file of :func:`kept_files` (for the trackers of ``results`` and the sequences of
    its records) must be listed, in order, nothing else listed, each file present with its
    listed digest and the folder's own (neither it nor a folder on its way from
    ``trackeval/`` a symbolic link); and ``trackeval/`` must hold no other tracker
    folder, tracker file, sequence folder or seqmap (TrackEval would read them). Files
    TrackEval writes beside a tracker's ``data/`` folder are allowed. Without ``tracks``,
    there must be no ``trackeval/`` folder.

    Parameters
    ----------
    root : pathlib.Path
        The benchmark's output folder.
    results : dict
        Its ``results.json`` (sound, and the results of ``records``).
    records : list of dict
        Its run records, in the listed order.

    Returns
    -------
    list of str
        One line per problem, each naming the file or folder at fault.
    """
    from scenegen.io.atomic import describe_special_file
    from scenegen.lab.experiments.outputs import parse_listing

    rerun = "run the same `scenegen benchmark ... --keep-tracks` command again to rewrite it"
    kept = root / FOLDER
    if "tracks" not in results:
        if kept.exists():
            return [f"{kept}: kept tracks that results.json does not list (written by an "
                    f"unfinished run: {rerun})"]  # fmt: skip
        return []
    names = sequence_names((r["key"]["index"], r["key"]["name"]) for r in records)
    want = kept_files(list(results["trackers"]), names)
    listed = parse_listing(results["tracks"]) or []
    got = [n for n, _ in listed]
    problems: list[str] = []
    if got != want:
        missing = [n for n in want if n not in got]
        extra = [n for n in got if n not in want]
        if missing:
            problems.append(f"{root / 'results.json'}: tracks lists no {missing[0]}"
                            + (f" (nor {len(missing) - 1} more files)" if len(missing) > 1
                               else ""))  # fmt: skip
        problems += [f"{root / 'results.json'}: tracks names {n!r}, not a file of the kept "
                     "tracks" for n in extra]  # fmt: skip
        if not problems:
            problems.append(f"{root / 'results.json'}: tracks lists the files out of order")
        return problems
    blocked: set[Path] = set()
    for name, digest in listed:
        path = root / name
        up = _file_in_the_way(root, name)
        if up is not None:
            if up not in blocked:
                blocked.add(up)
                problems.append(f"{up}: a file where the kept tracks have a folder (remove "
                                f"it, then {rerun})")  # fmt: skip
        elif path.is_dir():
            problems.append(f"{path}: a folder where the kept tracks have a file (remove it, "
                            f"then {rerun})")  # fmt: skip
        elif (special := describe_special_file(path)) is not None:
            problems.append(f"{special} (remove it, then {rerun})")
        elif (link := _link_on_the_way(root, name)) is not None:
            # The bytes behind a link are not the folder's: they change or vanish with
            # the target, and a copy of the folder may keep the link alone.
            if link not in blocked:
                blocked.add(link)
                problems.append(f"{link}: a symbolic link in the kept tracks (they must be "
                                f"the folder's own files: {rerun})")  # fmt: skip
        elif not path.is_file():
            problems.append(f"{path}: missing ({rerun})")
        elif file_digest(path) != digest:
            problems.append(f"{path}: is not the file results.json lists (damaged or edited: "
                            f"{rerun})")  # fmt: skip
    return problems + _extra_files(root, set(want))


def _file_in_the_way(root: Path, name: str) -> Path | None:
    """The first folder of the kept file ``name`` (from ``trackeval/`` down) that is there
    as something else than a folder, or None."""
    for part in reversed(Path(name).parents[:-1]):
        p = root / part
        if p.exists() and not p.is_dir():
            return p
    return None


def _link_on_the_way(root: Path, name: str) -> Path | None:
    """The first of the kept file ``name``'s folders (from ``trackeval/`` down) and the
    file itself that is a symbolic link, or None."""
    for part in [*reversed(Path(name).parents[:-1]), Path(name)]:
        if (root / part).is_symlink():
            return root / part
    return None


def prepare_folder(root: Path, want: list[str]) -> list[Path]:
    """Make the kept folder ready to be written: remove the symbolic links in it (a link
    would have the benchmark write one tracker's boxes through it, into another file), and
    refuse a file where a kept file needs a folder, a folder where it needs a file, and a
    FIFO, device or socket where it needs a file (reading it would wait or never end).

    Parameters
    ----------
    root : pathlib.Path
        The benchmark's output folder.
    want : list of str
        The kept files (:func:`kept_files`), relative to ``root``.

    Returns
    -------
    list of pathlib.Path
        The links removed.

    Raises
    ------
    scenegen.errors.ConfigError
        ``"PATH: is a file, not a folder"``, ``"PATH: is a folder, expected a file
        name"`` or ``"PATH: is not a regular file (a FIFO); remove it"``, before anything
        is written.
    """
    import os

    from scenegen.errors import ConfigError
    from scenegen.io.atomic import describe_special_file

    removed = []
    kept = root / FOLDER
    if kept.is_dir():
        for folder, dirs, files in os.walk(kept):
            for n in sorted(dirs + files):
                p = Path(folder) / n
                if p.is_symlink():
                    p.unlink()
                    removed.append(p)
    # Each folder once (a large benchmark's files share a few), the outermost first.
    folders = {f for name in want for f in Path(name).parents[:-1]}
    for f in sorted(folders, key=lambda f: (len(f.parts), f)):
        if (root / f).exists() and not (root / f).is_dir():
            raise ConfigError(f"{root / f}: is a file, not a folder")
    for name in want:
        if (root / name).is_dir():
            raise ConfigError(f"{root / name}: is a folder, expected a file name")
        special = describe_special_file(root / name)
        if special is not None:  # reading it would wait for a writer, or never end
            raise ConfigError(f"{special}; remove it")
    return removed


def _extra_files(root: Path, want: set[str]) -> list[str]:
    """One line per folder or file of the kept folder TrackEval would read that is not
    listed."""
    out = []
    for p in unlisted(root, want):
        what = "folder" if p.is_dir() else "file"
        out.append(f"{p}: a {what} the benchmark did not write (TrackEval would read it: "
                   "remove it)")  # fmt: skip
    return out


def unlisted(root: Path, want: set[str]) -> list[Path]:
    """The folders and files of the kept folder that TrackEval would read and that are not
    among ``want``: tracker folders and their files, sequence folders and their ``gt/``
    files, and seqmaps (temporary files of an interrupted write are not counted).

    Parameters
    ----------
    root : pathlib.Path
        The benchmark's output folder.
    want : set of str
        The kept files (:func:`kept_files`), relative to ``root``.

    Returns
    -------
    list of pathlib.Path
        Each folder before the files in it, in sorted order.
    """
    from scenegen.io.atomic import describe_temp_file

    def rel(p: Path) -> str:
        return p.relative_to(root).as_posix()

    dirs = {str(Path(w).parent) for w in want} | {
        str(p) for w in want for p in Path(w).parents}  # fmt: skip
    out: list[Path] = []
    seqmaps = root / Path(seqmap_file()).parent
    gts = root / _GT / f"{BENCHMARK}-{SPLIT}"
    trackers = root / _TRACKERS
    candidates: list[Path] = []
    for folder in (seqmaps, gts, trackers):
        if folder.is_dir():
            candidates += sorted(folder.iterdir())
    for folder in sorted(trackers.glob("*/data")) + sorted(gts.glob("*/gt")):
        if folder.is_dir():
            candidates += sorted(folder.iterdir())
    for p in candidates:
        r = rel(p)
        if r in want or r in dirs or describe_temp_file(p) is not None:
            continue
        out.append(p)
    return out


def remove_unlisted(root: Path, want: set[str]) -> list[Path]:
    """Remove what :func:`unlisted` finds (a tracker the benchmark no longer runs, a
    sequence of an earlier dataset), so that the kept folder holds only what
    ``results.json`` lists; return what was removed (folders, then loose files).

    Parameters
    ----------
    root : pathlib.Path
        The benchmark's output folder.
    want : set of str
        The kept files (:func:`kept_files`), relative to ``root``.

    Returns
    -------
    list of pathlib.Path
        The folders and files removed (a folder's files are not listed apart).
    """
    import shutil

    removed: list[Path] = []
    for p in unlisted(root, want):
        if any(d in p.parents for d in removed):
            continue
        if p.is_dir() and not p.is_symlink():
            shutil.rmtree(p)
        else:
            p.unlink(missing_ok=True)
        removed.append(p)
    return removed


def listed_tracks(out: Path, meta: dict[str, Any]) -> dict[str, str]:
    """The files ``OUT/results.json`` lists under ``tracks``, with their digests; empty when
    there is no sound ``results.json``, it lists none, or it was computed on another dataset
    than ``meta`` describes (another family digest, seed or count).

    Parameters
    ----------
    out : pathlib.Path
        The benchmark's output folder.
    meta : dict
        The description of the dataset about to be run
        (:func:`scenegen.lab.benchmark.dataset_meta`).

    Returns
    -------
    dict of str to str
        File (relative to ``out``) -> its listed SHA-256.
    """
    from scenegen.errors import DataError
    from scenegen.lab.benchmark_outputs import RESULTS, read_results
    from scenegen.lab.experiments.outputs import parse_listing

    try:
        res = read_results(Path(out) / RESULTS)
    except DataError:
        return {}
    if any(res["dataset"].get(k) != meta.get(k) for k in ("family_digest", "seed", "count")):
        return {}
    return dict(parse_listing(res.get("tracks")) or [])


def pending_file(run_name: str) -> str:
    """The note of a pair's tracker file, relative to the output folder.

    Parameters
    ----------
    run_name : str
        The pair's run file (``"runs/TRACKER/NNNNN.json"``).

    Returns
    -------
    str
        ``"tracks-pending/TRACKER/NNNNN.json"``.

    Examples
    --------
    >>> pending_file("runs/kalman/00007.json")
    'tracks-pending/kalman/00007.json'
    """
    return f"{PENDING}/{run_name.removeprefix('runs/')}"


def write_pending(out: Path, run_name: str, track: str, record_digest: str) -> None:
    """Write the note of a pair's tracker file (sealed, atomically), once the file and the
    pair's run record are written: the file's name and digest, and the record's digest.

    Parameters
    ----------
    out : pathlib.Path
        The benchmark's output folder.
    run_name : str
        The pair's run file (``"runs/TRACKER/NNNNN.json"``).
    track : str
        Its tracker file (:func:`track_file`).
    record_digest : str
        :func:`scenegen.io.sealed.content_digest` of its run record.
    """
    from scenegen.io.sealed import write_sealed_json

    write_sealed_json(out / pending_file(run_name), {
        "file": track, "file_digest": file_digest(out / track), "record_digest": record_digest,
    }, parents=True)  # fmt: skip


def pending_sound(out: Path, run_name: str, track: str, record_digest: str) -> bool:
    """Whether a pair's tracker file is the one its note (:func:`write_pending`) says, for
    the run record of digest ``record_digest``.

    Parameters
    ----------
    out : pathlib.Path
        The benchmark's output folder.
    run_name : str
        The pair's run file.
    track : str
        Its tracker file.
    record_digest : str
        The digest of its stored run record.

    Returns
    -------
    bool
        False for no note, a damaged or edited one, one of another record, or a tracker
        file that is missing or of another digest.

    Raises
    ------
    scenegen.errors.ConfigError
        The note is a FIFO, a device or a socket (it could not be written again).
    """
    from scenegen.errors import ConfigError, DataError
    from scenegen.io.atomic import SpecialFile
    from scenegen.io.sealed import read_sealed_json

    path = Path(out) / pending_file(run_name)
    if not path.exists():
        return False
    try:
        note = read_sealed_json(path)
    except SpecialFile as err:
        raise ConfigError(f"{err}; remove it") from None
    except DataError:
        return False
    digest = file_digest(Path(out) / track)
    return digest is not None and note == {"file": track, "file_digest": digest,
                                           "record_digest": record_digest}  # fmt: skip


def remove_pending(out: Path) -> None:
    """Remove the notes (:data:`PENDING`), once ``results.json`` lists the files.

    Parameters
    ----------
    out : pathlib.Path
        The benchmark's output folder.
    """
    import shutil

    path = Path(out) / PENDING
    if path.is_symlink() or path.is_file():
        path.unlink()
    elif path.is_dir():
        shutil.rmtree(path)


def sound_file(out: Path, name: str, listed: dict[str, str]) -> bool:
    """Whether the file ``name`` of the output folder ``out`` is the one ``listed``
    (:func:`listed_tracks`) says, byte for byte.

    Parameters
    ----------
    out : pathlib.Path
        The benchmark's output folder.
    name : str
        A file of the kept folder, relative to ``out``.
    listed : dict of str to str
        :func:`listed_tracks`.

    Returns
    -------
    bool
        False for a file not listed, missing, unreadable or of another digest.
    """
    return name in listed and file_digest(Path(out) / name) == listed[name]
