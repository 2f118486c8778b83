"""HDF5 reading and writing (schema ``scenegen/1``, CONTRACT.md). The only module that
touches files.

Every write goes to a temporary file in the target's folder and is renamed into place only
when complete, so a crash or a kill never leaves a half-written file at the target path
and never damages an earlier file there. Frames and labels are stored one frame per chunk,
so reading a frame range costs in proportion to the range; :func:`read` returns lazy arrays
that read only what is indexed.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import h5py
import numpy as np
from numpy.typing import NDArray

from scenegen.config import from_dict, to_dict
from scenegen.errors import ConfigError, DataError
from scenegen.sequence import GT_FIELDS, Entities, GroundTruth, Sequence

__all__ = [
    "COMPRESSIONS",
    "SCHEMA",
    "LazyArray",
    "TrackerResult",
    "atomic_path",
    "filter_options",
    "open_checked",
    "read",
    "read_result",
    "sequence_names",
    "write",
    "write_result",
    "write_scenario",
]

SCHEMA = "scenegen/1"
COMPRESSIONS = ("gzip", "lzf", "none")
_STR = h5py.string_dtype("utf-8")
_BLOCK = 64  # frames per write call


def _version() -> str:
    from scenegen import __version__

    return __version__


@contextlib.contextmanager
def atomic_path(path: str | Path, suffix: str = "") -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it onto ``path`` on success.

    On any exception the temporary file is removed and ``path`` is left untouched.
    """
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise ConfigError(f"{target}: folder {folder} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.tmp-", suffix=suffix, dir=folder)
    os.close(fd)
    tmp_path = Path(tmp)
    # mkstemp makes the file private; give it the permissions a plain open() would.
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp_path, 0o666 & ~umask)
    try:
        yield tmp_path
        os.replace(tmp_path, target)
    except BaseException:
        with contextlib.suppress(OSError):
            tmp_path.unlink()
        raise


def filter_options(compression: str) -> dict[str, Any]:
    if compression not in COMPRESSIONS:
        raise ConfigError(
            f"compression must be one of {', '.join(COMPRESSIONS)}; got {compression!r}"
        )
    if compression == "gzip":
        return {"compression": "gzip", "compression_opts": 4}
    if compression == "lzf":
        return {"compression": "lzf"}
    return {}


def _write_header(f: h5py.File) -> None:
    f.attrs["schema"] = SCHEMA
    f.attrs["generator_version"] = _version()


def _create_sequence_group(
    f: h5py.File, seq_meta: dict[str, Any], entities: Entities, compression: str
) -> tuple[h5py.Group, h5py.Dataset, h5py.Dataset]:
    name = seq_meta["name"]
    if f"sequences/{name}" in f:
        raise ConfigError(f"two sequences are named {name!r}: names must be unique in a file")
    g = f.require_group("sequences").create_group(name)
    t, h, w = seq_meta["n_frames"], seq_meta["height"], seq_meta["width"]
    g.attrs["seed"] = int(seq_meta["seed"])
    g.attrs["config"] = json.dumps(seq_meta["config"], sort_keys=True)
    g.attrs["preset"] = seq_meta["preset"]
    g.attrs["n_frames"] = t
    g.attrs["height"] = h
    g.attrs["width"] = w
    filt = filter_options(compression)
    frames = g.create_dataset("frames", (t, h, w, 3), np.uint8, chunks=(1, h, w, 3), **filt)
    labels = g.create_dataset("labels", (t, h, w), np.uint16, chunks=(1, h, w), **filt)
    e = g.create_group("entities")
    e.create_dataset("id", data=entities.id.astype(np.int32))
    e.create_dataset("role", data=entities.role.astype(object), dtype=_STR)
    e.create_dataset("name", data=entities.name.astype(object), dtype=_STR)
    return g, frames, labels


def _write_gt(g: h5py.Group, gt: dict[str, NDArray[Any]]) -> None:
    grp = g.create_group("gt")
    for key, dtype in GT_FIELDS.items():
        grp.create_dataset(key, data=np.asarray(gt[key], dtype=dtype))


def _write_templates(g: h5py.Group, templates: dict[int, NDArray[np.uint8]]) -> None:
    grp = g.create_group("templates")
    for eid, tpl in templates.items():
        grp.create_dataset(str(int(eid)), data=np.asarray(tpl, dtype=np.uint8))


def _meta(seq: Sequence) -> dict[str, Any]:
    return {
        "name": seq.name,
        "seed": seq.seed,
        "config": to_dict(seq.config),
        "preset": seq.preset,
        "n_frames": seq.n_frames,
        "height": seq.height,
        "width": seq.width,
    }


def write(path: str | Path, *sequences: Sequence, compression: str = "gzip") -> None:
    """Write sequences to one HDF5 file (atomically).

    Parameters
    ----------
    path : str or Path
    *sequences : Sequence
        At least one; names must be unique.
    compression : {'gzip', 'lzf', 'none'}
        Filter for frames and labels (one frame per chunk).
    """
    if not sequences:
        raise ConfigError("write needs at least one sequence")
    filter_options(compression)
    with atomic_path(path) as tmp, h5py.File(tmp, "w") as f:
        _write_header(f)
        for seq in sequences:
            g, frames, labels = _create_sequence_group(f, _meta(seq), seq.entities, compression)
            # Blocks of whole chunks: bounded memory for lazy inputs, few h5py calls.
            for t in range(0, seq.n_frames, _BLOCK):
                stop = min(t + _BLOCK, seq.n_frames)
                frames[t:stop] = np.asarray(seq.frames[t:stop])
                labels[t:stop] = np.asarray(seq.labels[t:stop])
            _write_gt(g, seq.gt.as_dict())
            _write_templates(g, seq.templates)


def write_scenario(
    path: str | Path,
    scenario: Any,
    *,
    compression: str = "gzip",
    chunk: int = 64,
    progress: Callable[[int], None] | None = None,
) -> None:
    """Render ``scenario`` (:class:`scenegen.generator.Scenario`) straight into a file.

    Frames are rendered and written ``chunk`` at a time, so memory stays bounded whatever
    the sequence length. ``progress`` is called with the number of frames written so far.
    """
    cfg = scenario.config
    meta = {
        "name": cfg.name,
        "seed": scenario.seed,
        "config": to_dict(cfg),
        "preset": scenario.preset,
        "n_frames": cfg.n_frames,
        "height": cfg.height,
        "width": cfg.width,
    }
    k = scenario.n_entities
    t_n = cfg.n_frames
    with atomic_path(path) as tmp, h5py.File(tmp, "w") as f:
        _write_header(f)
        g, frames, labels = _create_sequence_group(f, meta, scenario.entities(), compression)
        gt = {
            "box": np.empty((t_n, k, 4), np.float32),
            "visible_box": np.empty((t_n, k, 4), np.float32),
            "center": np.empty((t_n, k, 2), np.float32),
            "visibility": np.empty((t_n, k), np.float32),
            "present": np.empty((t_n, k), bool),
            "depth": np.empty((t_n, k), np.int16),
        }
        for c in scenario.chunks(chunk):
            stop = c.start + c.frames.shape[0]
            # Chunk-aligned writes: h5py writes whole chunks without reading them back.
            frames[c.start : stop] = c.frames
            labels[c.start : stop] = c.labels
            for key in gt:
                gt[key][c.start : stop] = c.gt[key]
            if progress is not None:
                progress(stop)
        _write_gt(g, gt)
        _write_templates(g, scenario.template_images())


class LazyArray:
    """A read-only view of an HDF5 dataset that reads only what is indexed.

    Supports ``shape``, ``dtype``, ``len()``, integer/slice indexing and ``np.asarray``.
    The file is opened on first access and reopened after pickling, so lazy arrays can be
    sent to worker processes.
    """

    def __init__(self, path: str | Path, dataset: str) -> None:
        self.path = str(path)
        self.dataset = dataset
        self._file: h5py.File | None = None
        ds = self._ds()
        self.shape: tuple[int, ...] = tuple(ds.shape)
        self.dtype = ds.dtype

    def _ds(self) -> h5py.Dataset:
        if self._file is None or not self._file.id.valid:
            self._file = h5py.File(self.path, "r")
        return self._file[self.dataset]

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state["_file"] = None
        return state

    def __len__(self) -> int:
        return self.shape[0]

    @property
    def ndim(self) -> int:
        return len(self.shape)

    def __getitem__(self, key: Any) -> NDArray[Any]:
        return self._ds()[key]

    def __array__(self, dtype: Any = None, copy: Any = None) -> NDArray[Any]:
        arr = self._ds()[()]
        return arr if dtype is None else arr.astype(dtype)

    def __iter__(self) -> Iterator[NDArray[Any]]:
        for t in range(self.shape[0]):
            yield self[t]

    def close(self) -> None:
        if self._file is not None:
            self._file.close()
            self._file = None

    def __repr__(self) -> str:
        return f"LazyArray({self.path!r}, {self.dataset!r}, shape={self.shape}, dtype={self.dtype})"


def open_checked(path: str | Path) -> h5py.File:
    """Open an HDF5 file for reading and check its schema.

    Raises
    ------
    DataError
        If the file is missing, not HDF5, or of another schema.
    """
    p = Path(path)
    if not p.exists():
        raise DataError(f"{p}: no such file")
    try:
        f = h5py.File(p, "r")
    except OSError:
        raise DataError(f"{p}: not an HDF5 file (or truncated/corrupted)") from None
    schema = f.attrs.get("schema")
    if isinstance(schema, bytes):
        schema = schema.decode()
    if schema != SCHEMA:
        f.close()
        raise DataError(f"{p}: schema is {schema!r}, expected {SCHEMA!r}")
    return f


def sequence_names(path: str | Path) -> list[str]:
    """Names of the sequences in a file."""
    with open_checked(path) as f:
        return list(f.get("sequences", {}).keys())


def _str_array(ds: h5py.Dataset) -> NDArray[np.str_]:
    return np.array([v.decode() if isinstance(v, bytes) else str(v) for v in ds[()]], dtype=str)


def read(path: str | Path, name: str | None = None) -> Sequence:
    """Read one sequence; frames and labels stay on disk as :class:`LazyArray`.

    Parameters
    ----------
    path : str or Path
    name : str, optional
        The sequence to read; required when the file holds several.

    Raises
    ------
    DataError
        If the file is not a valid scenegen file or has no such sequence.
    """
    p = Path(path)
    with open_checked(p) as f:
        seqs = list(f.get("sequences", {}).keys())
        if not seqs:
            raise DataError(f"{p}: holds no sequences")
        if name is None:
            if len(seqs) > 1:
                raise DataError(f"{p}: holds {len(seqs)} sequences; name one of {', '.join(seqs)}")
            name = seqs[0]
        if name not in seqs:
            raise DataError(f"{p}: no sequence {name!r}; it holds {', '.join(seqs)}")
        g = f[f"sequences/{name}"]
        try:
            config = from_dict(json.loads(g.attrs["config"]))
            entities = Entities(
                id=g["entities/id"][()].astype(np.int32),
                role=_str_array(g["entities/role"]),
                name=_str_array(g["entities/name"]),
            )
            gt = GroundTruth(**{k: g[f"gt/{k}"][()].astype(dt) for k, dt in GT_FIELDS.items()})
            templates = {int(k): v[()] for k, v in g["templates"].items()}
            seed, preset = int(g.attrs["seed"]), str(g.attrs["preset"])
        except (KeyError, ValueError, ConfigError) as err:
            raise DataError(f"{p}: sequence {name!r} is damaged: {err}") from None
    return Sequence(
        name=name,
        seed=seed,
        config=config,
        preset=preset,
        frames=LazyArray(p, f"sequences/{name}/frames"),
        labels=LazyArray(p, f"sequences/{name}/labels"),
        entities=entities,
        gt=gt,
        templates=templates,
    )


# ---------------------------------------------------------------------------------------
# Tracker result files


@dataclass
class TrackerResult:
    """One tracker's result in a result file.

    Attributes
    ----------
    tracker : str
    params : dict
    seed : int
    sequence : str
        The name of the sequence tracked.
    target_ids : ndarray of shape (M,), int32
    boxes : ndarray of shape (T, M, 4), float32
    orderings : ndarray of shape (L, M), int16, or None
        SHM trackers only: target positions nearest first, one row per ordering.
    order_prob : ndarray of shape (T, L), float32, or None
    """

    tracker: str
    params: dict[str, Any]
    seed: int
    sequence: str
    target_ids: NDArray[np.int32]
    boxes: NDArray[np.float32]
    orderings: NDArray[np.int16] | None = None
    order_prob: NDArray[np.float32] | None = None


def write_result(path: str | Path, *results: TrackerResult) -> None:
    """Write tracker results to a result file (atomically), one group per tracker."""
    if not results:
        raise ConfigError("write_result needs at least one result")
    with atomic_path(path) as tmp, h5py.File(tmp, "w") as f:
        _write_header(f)
        root = f.create_group("results")
        for r in results:
            if r.tracker in root:
                raise ConfigError(f"two results for tracker {r.tracker!r} in one file")
            g = root.create_group(r.tracker)
            g.attrs["tracker"] = r.tracker
            g.attrs["params"] = json.dumps(r.params, sort_keys=True, default=str)
            g.attrs["seed"] = int(r.seed)
            g.attrs["sequence"] = r.sequence
            g.create_dataset("target_ids", data=np.asarray(r.target_ids, dtype=np.int32))
            g.create_dataset("boxes", data=np.asarray(r.boxes, dtype=np.float32))
            if r.orderings is not None and r.order_prob is not None:
                g.create_dataset("orderings", data=np.asarray(r.orderings, dtype=np.int16))
                g.create_dataset("order_prob", data=np.asarray(r.order_prob, dtype=np.float32))


def read_result(path: str | Path, tracker: str | None = None) -> TrackerResult:
    """Read one tracker's result (the only one if ``tracker`` is None).

    Raises
    ------
    DataError
        If the file is not a result file, or has no (or several, unnamed) results.
    """
    p = Path(path)
    with open_checked(p) as f:
        if "results" not in f or not len(f["results"]):
            raise DataError(f"{p}: holds no tracker results")
        names = list(f["results"].keys())
        if tracker is None:
            if len(names) > 1:
                raise DataError(f"{p}: holds results of {', '.join(names)}; name one")
            tracker = names[0]
        if tracker not in names:
            raise DataError(f"{p}: no result for tracker {tracker!r}; it holds {', '.join(names)}")
        g = f[f"results/{tracker}"]
        try:
            return TrackerResult(
                tracker=str(g.attrs["tracker"]),
                params=json.loads(g.attrs["params"]),
                seed=int(g.attrs["seed"]),
                sequence=str(g.attrs["sequence"]),
                target_ids=g["target_ids"][()].astype(np.int32),
                boxes=g["boxes"][()].astype(np.float32),
                orderings=g["orderings"][()] if "orderings" in g else None,
                order_prob=g["order_prob"][()] if "order_prob" in g else None,
            )
        except (KeyError, ValueError) as err:
            raise DataError(f"{p}: result {tracker!r} is damaged: {err}") from None
