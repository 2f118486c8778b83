"""Building a dataset: sequences drawn from a family, written in shards, with a manifest.

Layout of a dataset folder ``DIR``::

    DIR/manifest.json        one entry per sequence: index, name, seed, file, params, digests
    DIR/shard-00000.h5       sequences 0 .. S-1 (schema scenegen/1), S = shard size
    DIR/shard-00001.h5       ...

Reproducible to the byte: sequence ``i``'s config and seed come from (family, seed, i)
only (:meth:`Family.draw`), shard ``j`` holds sequences ``j*S .. j*S+S-1`` in index
order, files are written by :func:`scenegen.io.write` (deterministic bytes) and the
manifest is sorted; so the folder is the same whether it is made by one process, a local
pool or a Dask cluster, in any completion order.

Resumable: a shard is written atomically (a temporary file renamed into place), and the
manifest is rewritten atomically as shards finish. Running the same command again keeps
every shard file whose sequences have the expected names, seeds and configs and whose
contents match their digests (the manifest's, when it lists them), and makes the rest.
A larger ``--count`` extends a dataset the same way (the first sequences do not depend
on the count), remaking only its last, partial shard.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from scenegen.datasets.builtin import resolve_family
from scenegen.datasets.executor import check_executor, probe, run_tasks
from scenegen.datasets.family import Axis, Draw, Family
from scenegen.errors import ConfigError, DataError
from scenegen.render.plan import MAX_SEED

__all__ = [
    "DEFAULT_SHARD_SIZE",
    "MANIFEST",
    "SCHEMA",
    "ShardTask",
    "build_dataset",
    "holds_benchmark_outputs",
    "holds_experiment_outputs",
    "holds_report",
    "make_output_folder",
    "make_shard",
    "manifest_axes",
    "manifest_entries",
    "manifest_family",
    "plan_shards",
    "read_manifest",
    "shard_name",
    "write_manifest",
]

SCHEMA = "scenegen-dataset/1"
MANIFEST = "manifest.json"
DEFAULT_SHARD_SIZE = 4
"""Sequences per shard file: small enough that many workers write in parallel and a lost
shard costs little, large enough to keep the file count down (10,000 sequences: 2,500
files). A worker holds one shard's sequences in memory while writing it."""

_FLUSH_SECONDS = 2.0  # the manifest is rewritten at most this often while shards finish


def shard_name(j: int) -> str:
    """File name of shard ``j``: ``shard-NNNNN.h5``.

    Parameters
    ----------
    j : int
        The shard's index (>= 0).

    Returns
    -------
    str
        ``j`` zero-padded to five digits (more when it needs them): ``shard-00002.h5``.
    """
    return f"shard-{j:05d}.h5"


@dataclass(frozen=True)
class ShardTask:
    """One shard to make (or to verify and keep).

    Attributes
    ----------
    shard : int
    root : str
        The dataset folder.
    draws : tuple of Draw
        Its sequences, in index order.
    compression : str
    expected : tuple of (dict or None)
        Per sequence, the digests an earlier run recorded in the manifest (None if not).
    """

    shard: int
    root: str
    draws: tuple[Draw, ...]
    compression: str
    expected: tuple[dict[str, str] | None, ...]

    @property
    def file(self) -> str:
        """The shard's file name, a str relative to ``root``: ``shard-NNNNN.h5``."""
        return shard_name(self.shard)


def _shard_label(task: ShardTask) -> str:
    """``making shard-00002.h5 (sequences 8-11)``: what a worker that died was doing."""
    first, last = task.draws[0].index, task.draws[-1].index
    which = f"sequences {first}-{last}" if last > first else f"sequence {first}"
    return f"making {task.file} ({which})"


def _entry(d: Draw, file: str, seq: Any, digests: dict[str, str]) -> dict[str, Any]:
    roles = [str(r) for r in seq.entities.role]
    return {
        "index": d.index,
        "name": d.name,
        "seed": d.seed,
        "preset": d.preset,
        "file": file,
        "params": d.params,
        "n_frames": int(d.config["n_frames"]),
        "width": int(d.config["width"]),
        "height": int(d.config["height"]),
        "targets": roles.count("target"),
        "digests": digests,
    }


def is_drawn(seq: Any, d: Draw) -> bool:
    """Whether the stored sequence ``seq`` is the one ``d`` describes (seed, preset and
    config)."""
    from scenegen.config import to_dict

    return seq.seed == d.seed and seq.preset == d.preset and to_dict(seq.config) == d.config


def _verify(task: ShardTask) -> list[dict[str, Any]] | None:
    """Entries of an existing complete shard file that matches the task, else None."""
    import scenegen
    from scenegen.io import sequence_names
    from scenegen.testing.fixtures import digests

    path = Path(task.root) / task.file
    if not path.is_file():
        return None
    try:
        if sequence_names(path) != [d.name for d in task.draws]:
            return None
        out = []
        for d, want in zip(task.draws, task.expected, strict=True):
            seq = scenegen.read(path, d.name)
            if not is_drawn(seq, d):
                return None
            got = digests(seq)
            if want is not None and got != want:
                return None
            out.append(_entry(d, task.file, seq, got))
        return out
    except (DataError, ConfigError, OSError):
        return None  # damaged or foreign: make it again


def _generate(d: Draw) -> Any:
    from scenegen.config import from_dict
    from scenegen.render.plan import plan
    from scenegen.sequence import GroundTruth, Sequence

    cfg = from_dict(d.config)
    try:  # planning finds what validation cannot (a missing image, a runaway AR2 path)
        scn = plan(cfg, d.seed, preset=d.preset)
    except ConfigError as err:
        shown = ", ".join(f"{p}={json.dumps(v)}" for p, v in d.params.items())
        raise ConfigError(f"sequence {d.index} ({shown}): {err}" if shown
                          else f"sequence {d.index}: {err}") from None  # fmt: skip
    chunk = scn.render()
    return Sequence(
        name=cfg.name,
        seed=scn.seed,
        config=cfg,
        preset=d.preset,
        frames=chunk.frames,
        labels=chunk.labels,
        entities=scn.entities(),
        gt=GroundTruth(**chunk.gt),
        templates=scn.template_images(),
    )


def make_shard(task: ShardTask) -> dict[str, Any]:
    """Make one shard file (atomically) unless a matching one exists; return its entries.

    Runs in a worker process (or on a Dask worker, which must see the dataset folder).

    Parameters
    ----------
    task : ShardTask
        The shard: its index, folder, draws, compression and the digests expected of an
        existing file.

    Returns
    -------
    dict
        ``shard``, ``reused`` (the file existed and verified), ``entries`` (manifest
        entries, one per sequence, with digests), and the worker's ``pid``,
        ``cpu_seconds`` (CPU time of this shard) and ``peak_rss_mb`` (peak resident memory
        so far, MiB).

    Raises
    ------
    ConfigError
        A sequence that cannot be planned (a missing image, a runaway AR2 path), naming
        its index and parameters; or the shard that cannot be written (a full disk, a
        read-only folder).
    """
    from scenegen.io import write
    from scenegen.io.mot import writable
    from scenegen.testing.fixtures import digests

    cpu = time.process_time()
    kept = _verify(task)
    if kept is not None:
        return {"shard": task.shard, "reused": True, "entries": kept, **_worker(cpu)}
    seqs = [_generate(d) for d in task.draws]
    entries = [_entry(d, task.file, s, digests(s)) for d, s in zip(task.draws, seqs, strict=True)]
    target = Path(task.root) / task.file
    with writable(target):  # a full disk or a read-only folder: one line naming the shard
        Path(task.root).mkdir(parents=True, exist_ok=True)  # a worker without the folder
        write(target, *seqs, compression=task.compression)
    return {"shard": task.shard, "reused": False, "entries": entries, **_worker(cpu)}


def _worker(cpu_start: float) -> dict[str, Any]:
    """Which process made a shard, the CPU time it took and the peak memory so far."""
    import os

    try:
        import resource

        rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # Linux: KiB
    except (ImportError, OSError):
        rss = float("nan")
    return {"pid": os.getpid(), "peak_rss_mb": rss, "cpu_seconds": time.process_time() - cpu_start}


def plan_shards(
    draws: list[Draw],
    root: Path,
    shard_size: int,
    compression: str,
    previous: dict[int, dict[str, Any]] | None = None,
) -> list[ShardTask]:
    """Group draws into shard tasks (``previous``: manifest entries by index).

    Parameters
    ----------
    draws : list of Draw
        The sequences, in index order.
    root : Path
        The dataset folder.
    shard_size : int
        Sequences per shard (>= 1): shard ``j`` holds ``draws[j*S : j*S + S]``.
    compression : str
        The HDF5 compression of the shard files.
    previous : dict of int to dict, optional
        Manifest entries of an earlier run by index: an entry's digests are expected of
        the existing file when its file and seed are those of the new draw.

    Returns
    -------
    list of ShardTask
        One task per shard, in shard order.

    Raises
    ------
    ConfigError
        ``shard_size < 1``.
    """
    if shard_size < 1:
        raise ConfigError(f"--shard-size must be >= 1, got {shard_size}")
    prev = previous or {}
    tasks = []
    for j, start in enumerate(range(0, len(draws), shard_size)):
        group = tuple(draws[start : start + shard_size])
        expected = []
        for d in group:
            e = prev.get(d.index)
            ok = e is not None and e.get("file") == shard_name(j) and e.get("seed") == d.seed
            expected.append(e.get("digests") if ok and e is not None else None)
        tasks.append(ShardTask(j, str(root), group, compression, tuple(expected)))
    return tasks


def _header(fam: Family, count: int, seed: int, shard_size: int, compression: str) -> dict:
    from scenegen import __version__

    return {
        "schema": SCHEMA,
        "family": fam.name,
        "description": fam.description,
        "family_digest": fam.digest(),
        "family_spec": fam.spec,
        "seed": seed,
        "count": count,
        "shard_size": shard_size,
        "shards": -(-count // shard_size),
        "compression": compression,
        "generator_version": __version__,
        "params": fam.param_names,
        "axes": [
            {"name": a.name, "paths": list(a.paths), "values": [list(v) for v in a.values]}
            for a in fam.axes
        ],
        "vary": [{"path": d.path, "kind": d.kind, "args": list(d.args)} for d in fam.distributions],
        # With axes and vary, the whole family: validate draws every sequence again from it.
        "resolved": {
            "bases": fam.bases,
            "base": fam.base,
            "set": [list(o) for o in fam.overrides],
        },
    }


_IDENTITY = ("schema", "family_digest", "seed", "shard_size", "compression")


def write_manifest(root: Path, manifest: dict[str, Any]) -> None:
    """Write ``manifest.json`` atomically (sorted keys, entries in the order given).

    Parameters
    ----------
    root : Path
        The dataset folder.
    manifest : dict
        The header and its ``sequences`` entries (kept in index order by
        :func:`build_dataset`); JSON-serialisable, without NaN or infinity.

    Raises
    ------
    ConfigError
        ``DIR/manifest.json: cannot write: REASON`` (a full disk, a read-only folder).
    """
    from scenegen.io import atomic_path
    from scenegen.io.mot import writable

    text = json.dumps(manifest, sort_keys=True, indent=1, allow_nan=False)
    with writable(root / MANIFEST), atomic_path(root / MANIFEST, ".json") as tmp:
        tmp.write_text(text + "\n", encoding="utf-8")


def read_manifest(root: Path, *, check_entries: bool = True) -> dict[str, Any]:
    """The manifest of the dataset folder ``root``.

    Parameters
    ----------
    root : Path
    check_entries : bool, default True
        Also check its count, shard size and every entry (:func:`manifest_entries`).

    Returns
    -------
    dict
        The parsed manifest: its header fields and the ``sequences`` list.

    Raises
    ------
    DataError
        If it is missing, unreadable or not a scenegen dataset manifest, or (with
        ``check_entries``) an entry is damaged: one line naming the file and the entry.
    """
    from scenegen.io.atomic import describe_special_file

    p = Path(root) / MANIFEST
    special = describe_special_file(p)  # a FIFO would wait for a writer, /dev/zero not end
    if special is not None:
        raise DataError(special)
    try:
        data = json.loads(p.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise DataError(f"{root}: not a dataset folder (no {MANIFEST})") from None
    except (OSError, ValueError) as err:
        raise DataError(f"{p}: unreadable: {err}") from None
    if not isinstance(data, dict) or data.get("schema") != SCHEMA:
        raise DataError(f"{p}: not a scenegen dataset manifest (schema {SCHEMA} expected)")
    if not isinstance(data.get("sequences"), list):
        raise DataError(f"{p}: no 'sequences' list")
    if check_entries:
        _, bad = manifest_entries(data, p)
        if bad:
            more = f" (and {len(bad) - 1} more damaged entries)" if len(bad) > 1 else ""
            raise DataError(bad[0] + more)
    return data


_ENTRY = {"index": int, "name": str, "seed": int, "preset": str, "file": str,
          "params": dict, "n_frames": int, "width": int, "height": int, "targets": int,
          "digests": dict}  # fmt: skip
"""The fields of a manifest entry (:func:`_entry`) and their types."""


def _is(value: Any, kind: type) -> bool:
    return isinstance(value, kind) and not isinstance(value, bool)


def manifest_entries(
    manifest: dict[str, Any], path: Path
) -> tuple[list[dict[str, Any]], list[str]]:
    """The sound entries of a manifest, and one line per damaged one.

    An entry is sound when it is a mapping with every field of an entry, each of its type
    (digests: names to strings), its index in ``0 .. count-1`` and not listed before, and
    its file the shard its index belongs to. Every reader of a manifest checks it so
    (:func:`read_manifest`); :func:`scenegen.datasets.validate_dataset` lists every line.

    Parameters
    ----------
    manifest : dict
        As read from ``manifest.json`` (with a ``sequences`` list).
    path : Path
        The manifest file, for messages.

    Returns
    -------
    sound : list of dict
    problems : list of str
        ``"PATH: entry K (NAME): what is wrong"`` per damaged entry, K its position.

    Raises
    ------
    DataError
        If the header's ``count`` or ``shard_size`` is not an integer >= 1.
    """
    from scenegen.config.messages import _short

    count, size = manifest.get("count"), manifest.get("shard_size")
    if not (_is(count, int) and _is(size, int) and count >= 1 and size >= 1):
        raise DataError(f"{path}: count and shard_size must be integers >= 1")
    sound: list[dict[str, Any]] = []
    problems: list[str] = []
    seen: set[int] = set()
    for k, e in enumerate(manifest["sequences"]):
        if not isinstance(e, dict):
            problems.append(f"{path}: entry {k}: not an entry (a mapping), got {_short(e)}")
            continue
        name = f" ({_short(e['name'])})" if isinstance(e.get("name"), str) else ""
        where = f"{path}: entry {k}{name}"
        missing = [f for f in _ENTRY if f not in e]
        wrong = [f for f, kind in _ENTRY.items() if f in e and not _is(e[f], kind)]
        if missing:
            problems.append(f"{where}: no {missing[0]!r}")
        elif wrong:
            f = wrong[0]
            kind = {int: "an integer", str: "a string", dict: "a mapping"}[_ENTRY[f]]
            problems.append(f"{where}: {f} must be {kind}, got {_short(e[f])}")
        elif not all(isinstance(v, str) for v in e["digests"].values()):
            problems.append(f"{where}: digests must map array names to strings")
        elif not 0 <= e["index"] < count:
            problems.append(f"{where}: index {e['index']} out of range 0..{count - 1}")
        elif e["index"] in seen:
            problems.append(f"{where}: index {e['index']} listed twice")
        elif e["file"] != shard_name(e["index"] // size):
            problems.append(f"{where}: sequence {e['index']} listed in {_short(e['file'])}, "
                            f"expected {shard_name(e['index'] // size)!r}")  # fmt: skip
        else:
            seen.add(e["index"])
            sound.append(e)
    return sound, problems


def manifest_axes(manifest: dict[str, Any], path: Path) -> tuple[Axis, ...]:
    """The grid axes the header of a manifest lists (``axes``).

    Parameters
    ----------
    manifest : dict
        As read from ``manifest.json``.
    path : Path
        The manifest file, for messages.

    Returns
    -------
    tuple of Axis
        The axes, each with a value (a tuple) per path.

    Raises
    ------
    DataError
        One line naming ``path`` when ``axes`` is not a list of axes.
    """
    try:
        axes = tuple(Axis(str(a["name"]), tuple(a["paths"]), tuple(map(tuple, a["values"])))
                     for a in manifest["axes"])  # fmt: skip
    except (KeyError, TypeError) as err:
        raise DataError(f"{path}: axes is not a list of grid axes ({type(err).__name__}: "
                        f"{str(err)[:80]})") from None  # fmt: skip
    if any(len(v) != len(a.paths) for a in axes for v in a.values):
        raise DataError(f"{path}: axes is not a list of grid axes (a value per path)")
    return axes


def manifest_family(manifest: dict[str, Any], path: Path) -> Family:
    """The family a manifest's sequences were drawn from, as its header describes it.

    From the header's ``resolved`` family, ``axes`` and ``vary``, checked against its
    ``family_digest``; so every entry can be drawn again (:meth:`Family.draw`). A manifest
    written before the header held ``resolved`` is tried with its ``family_spec`` (which
    gives the digest only when the order of its sections' keys is the sorted one: the
    manifest is written with sorted keys).

    Parameters
    ----------
    manifest : dict
        As read from ``manifest.json``.
    path : Path
        The manifest file, for messages.

    Returns
    -------
    Family
        The family, its digest equal to the header's ``family_digest``.

    Raises
    ------
    DataError
        One line naming ``path``: the header does not describe a family, or one with
        another digest (edited); for an older manifest whose ``family_spec`` does not give
        its digest, the command that updates it.
    """
    from scenegen.datasets.family import Distribution, family_from_dict

    res, seed = manifest.get("resolved"), manifest.get("seed")
    if not (_is(seed, int) and 0 <= seed <= MAX_SEED):
        raise DataError(f"{path}: seed must be a non-negative integer below 2**64")
    try:
        if isinstance(res, dict):
            fam = Family(
                name=manifest["family"], description=str(manifest.get("description", "")),
                bases=dict(res["bases"]), base=res["base"],
                overrides=tuple((str(p), v) for p, v in res["set"]),
                axes=manifest_axes(manifest, path),
                distributions=tuple(Distribution(d["path"], d["kind"], tuple(d["args"]))
                                    for d in manifest["vary"]),
                count=manifest["count"], seed=seed, source=str(path),
            )  # fmt: skip
        else:  # an older manifest: family_spec may name files found no more, and lost
            try:  # the order of its keys
                fam = family_from_dict(manifest.get("family_spec"), source="family_spec")
                ok = fam.digest() == manifest.get("family_digest")
            except ConfigError:
                ok = False
            if not ok:
                raise DataError(f"{path}: no resolved family in the header (written by an "
                                "older version of scenegen), and its family_spec does not "
                                "give its family_digest: run the same `scenegen dataset` "
                                "command again to update the manifest")  # fmt: skip
        ok = fam.digest() == manifest.get("family_digest")
    except DataError:
        raise
    except (KeyError, TypeError, ValueError, AttributeError) as err:  # ConfigError too
        raise DataError(f"{path}: the header does not describe a family "
                        f"({type(err).__name__}: {str(err)[:120]})") from None  # fmt: skip
    if not ok:
        raise DataError(f"{path}: the header's family does not have its family_digest "
                        "(edited, or made by another version of scenegen)")  # fmt: skip
    return fam


def holds_benchmark_outputs(folder: Path) -> bool:
    """True for a folder holding what ``scenegen benchmark`` writes (even damaged):
    ``scores.csv`` or ``leaderboard.md``, or run folders under ``runs/``.

    Defined here, below the lab, so that no dataset is written into one;
    :func:`scenegen.lab.benchmark_outputs.is_benchmark_folder` uses it.

    Parameters
    ----------
    folder : Path
        The folder (it need not exist).

    Returns
    -------
    bool
        Whether it holds a benchmark's outputs.
    """
    root = Path(folder)
    if (root / "scores.csv").is_file() or (root / "leaderboard.md").is_file():
        return True
    runs = root / "runs"
    return runs.is_dir() and any(p.is_dir() for p in runs.iterdir())


def _results_json(folder: Path) -> Any:
    """The parsed ``folder/results.json``, or None (missing, unreadable, not JSON, or not a
    regular file)."""
    from scenegen.io.atomic import describe_special_file

    path = Path(folder) / "results.json"
    if describe_special_file(path) is not None:
        return None
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):
        return None


def holds_report(folder: Path) -> bool:
    """True for the report folder of ``scenegen experiment all`` or ``scenegen demo`` (even
    damaged): a ``results.json`` holding ``{"experiments": ...}``, or ``experiments/``
    beside an ``index.html``.

    Parameters
    ----------
    folder : Path
        The folder (it need not exist).

    Returns
    -------
    bool
        Whether it holds such a report.
    """
    root = Path(folder)
    held = _results_json(root)
    if isinstance(held, dict) and "experiments" in held:
        return True
    return (root / "experiments").is_dir() and (root / "index.html").exists()


def holds_experiment_outputs(folder: Path) -> bool:
    """True for a folder holding what ``scenegen experiment`` writes (even damaged): a
    ``results.json`` naming an experiment, or run records (``runs/*.json``) beside a
    ``table.md``; or the report of ``scenegen experiment all`` (:func:`holds_report`).

    Defined here, below the lab, so that no dataset is written into one;
    ``scenegen benchmark -o`` refuses such a folder too.

    Parameters
    ----------
    folder : Path
        The folder (it need not exist).

    Returns
    -------
    bool
        Whether it holds an experiment's outputs or a report.
    """
    root = Path(folder)
    held = _results_json(root)
    if isinstance(held, dict) and isinstance(held.get("experiment"), str):
        return True
    if holds_report(root):
        return True
    runs = root / "runs"
    return (root / "table.md").is_file() and runs.is_dir() and any(runs.glob("*.json"))


def make_output_folder(folder: Path) -> None:
    """Create the output folder ``folder`` (``-o``) and its parents, if missing.

    Parameters
    ----------
    folder : Path
        The folder.

    Raises
    ------
    ConfigError
        One line naming the folder when it cannot be created (a parent is a file, a
        read-only or virtual file system).
    """
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise ConfigError(f"-o {folder}: cannot create the folder "
                          f"({err.strerror or type(err).__name__})") from None  # fmt: skip


def build_dataset(
    family: str | Path | Family | dict[str, Any],
    out: str | Path,
    *,
    count: int | None = None,
    seed: int | None = None,
    frames: int | None = None,
    jobs: int | None = None,
    scheduler: str | None = None,
    shard_size: int = DEFAULT_SHARD_SIZE,
    compression: str = "gzip",
    progress: bool = False,
    on_shard: Callable[[dict[str, Any]], None] | None = None,
) -> dict[str, Any]:
    """Generate (or finish) the dataset of ``family`` in the folder ``out``.

    Parameters
    ----------
    family : str, Path, Family or dict
        A family file, a built-in family or preset name, or a parsed family.
    out : str or Path
        The dataset folder (created if missing).
    count : int, optional
        Sequences (default: the family's ``count``).
    seed : int, optional
        Base seed (default: the family's ``seed``).
    frames : int, optional
        Override every sequence's frame count (a ``set: {n_frames: ...}`` entry, so it
        makes a different dataset).
    jobs : int or None
        Local worker processes (None: all cores; 1: this process).
    scheduler : str or None
        A ``dask.distributed`` scheduler address; its workers must see ``out``.
    shard_size : int
        Sequences per shard file.
    compression : {'gzip', 'lzf', 'none'}
    progress : bool
        Show a tqdm bar on stderr.
    on_shard : callable, optional
        Called in this process with each shard's result (``shard``, ``reused``, ``entries``).

    Returns
    -------
    dict
        The manifest, as written to ``out/manifest.json``.

    Raises
    ------
    ConfigError
        For a bad family, count, seed, executor or compression; a ``frames`` the family
        sweeps or draws; an ``out`` that cannot be created, holds another dataset, a
        damaged manifest, a benchmark's outputs, an experiment's results or a report of
        ``scenegen experiment all``.
    """
    from tqdm import tqdm

    from scenegen.io import filter_options

    fam = resolve_family(family)
    if frames is not None:
        if isinstance(frames, bool) or not isinstance(frames, int) or frames < 1:
            raise ConfigError(f"--frames must be >= 1, got {frames}")
        try:
            fam = fam.with_overrides({"n_frames": frames})
        except ConfigError as err:
            raise ConfigError(f"--frames {frames}: {err}") from None
    check_executor(jobs, scheduler)
    filter_options(compression)
    n = fam.count if count is None else count
    s = fam.seed if seed is None else seed
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise ConfigError(f"--count must be >= 1, got {n}")
    if isinstance(s, bool) or not isinstance(s, int) or not 0 <= s <= MAX_SEED:
        shown = s if not isinstance(s, int) or s.bit_length() < 128 else f"{s.bit_length()} bits"
        raise ConfigError(f"--seed must be an integer in [0, 2**64 - 1], got {shown}")
    if shard_size < 1:
        raise ConfigError(f"--shard-size must be >= 1, got {shard_size}")
    root = Path(out)
    if root.exists() and not root.is_dir():
        raise ConfigError(f"{root}: exists and is not a folder")
    if root.is_dir() and holds_benchmark_outputs(root):
        raise ConfigError(f"-o {root}: is a benchmark output folder (scenegen benchmark); "
                          "write the dataset into another folder")  # fmt: skip
    if root.is_dir() and holds_experiment_outputs(root):
        what = ("a report of `scenegen experiment all`" if holds_report(root)
                else "the results of `scenegen experiment`")  # fmt: skip
        raise ConfigError(f"-o {root}: holds {what}; write the dataset into another folder")
    draws = fam.draws(n, s)  # validates every sequence's config before any work
    if scheduler is not None:
        probe(scheduler)  # an unreachable scheduler fails before anything is written
    header = _header(fam, n, s, shard_size, compression)
    previous: dict[int, dict[str, Any]] = {}
    if (root / MANIFEST).exists():
        try:
            old = read_manifest(root)
        except DataError as err:
            raise ConfigError(f"{err}; cannot resume the dataset in {root}: remove the folder "
                              "or choose another output folder") from None  # fmt: skip
        diff = [k for k in _IDENTITY if old.get(k) != header[k]]
        if diff:
            was = ", ".join(f"{k}={old.get(k)!r}" for k in diff if k != "family_digest")
            what = "another family" if "family_digest" in diff else was
            raise ConfigError(
                f"{root}: holds a different dataset ({old.get('family')!r}: {what}); "
                "choose another output folder or remove it"
            )
        if isinstance(old.get("count"), int) and old["count"] > n:
            raise ConfigError(
                f"{root}: holds {old['count']} sequences of {old.get('family')!r}; a rerun "
                f"may extend it (--count >= {old['count']}) but not shrink it"
            )
        previous = {int(e["index"]): e for e in old["sequences"] if isinstance(e, dict)}
    else:
        make_output_folder(root)
        if any(root.glob("shard-*.h5")):
            raise ConfigError(f"{root}: holds shard files but no {MANIFEST}; choose another folder")
    tasks = plan_shards(draws, root, shard_size, compression, previous)
    done: dict[int, list[dict[str, Any]]] = {}
    manifest = dict(header)

    def flush(complete: bool) -> None:
        entries = [e for j in sorted(done) for e in done[j]]
        keep = {e["index"] for e in entries}
        # Entries of shards not redone yet stay listed (their files are checked on resume).
        entries += [e for i, e in sorted(previous.items()) if i not in keep and i < n]
        entries.sort(key=lambda e: e["index"])
        manifest["sequences"] = entries
        manifest["complete"] = complete
        write_manifest(root, manifest)

    flush(False)
    bar = tqdm(total=n, disable=not progress, unit="seq", desc=f"dataset {fam.name}",
               leave=False)  # fmt: skip
    last, wait = [time.monotonic()], [_FLUSH_SECONDS]

    def store(task: ShardTask, res: dict[str, Any]) -> None:
        done[task.shard] = res["entries"]
        bar.update(len(res["entries"]))
        if on_shard is not None:
            on_shard(res)
        if time.monotonic() - last[0] >= wait[0]:
            t0 = time.monotonic()
            flush(False)
            last[0] = time.monotonic()
            # A 10,000-sequence manifest is ~13 MB: rewrite it at most 5% of the time.
            wait[0] = max(_FLUSH_SECONDS, 20.0 * (last[0] - t0))

    try:
        run_tasks(
            make_shard, tasks, store, jobs=jobs, scheduler=scheduler,
            key=lambda t: t.file, name="scenegen-dataset", label=_shard_label,
        )  # fmt: skip
    finally:
        bar.close()
        flush(len(done) == len(tasks))
    return manifest
