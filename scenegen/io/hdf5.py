"""HDF5 reading and writing of sequences (schema ``scenegen/1``: the layout is
:mod:`scenegen.io.schema`, described for readers in ``docs/format.md``). With
:mod:`scenegen.io.results` (tracker result files, built on the helpers here), the only
module that touches HDF5 files.

Layout
    Every dataset is created from its :class:`scenegen.io.schema.Field` (shape, dtype) and
    carries its ``description`` and ``units`` attributes; the root carries the
    ``conventions``. Reading does not need these attributes, so older files without them
    read the same; a file without ``gt/path_center`` reads it as NaN.

Atomic writes
    Every write goes through :func:`scenegen.io.atomic.atomic_path` (a temporary file in
    the target's folder, renamed onto the target only when complete); see
    :mod:`scenegen.io.atomic` for the naming and the clean-up of leftovers.

Integrity
    Frames, labels, ground truth and templates are stored with the Fletcher-32 checksum
    filter (besides the chosen compression), so a flipped byte in any chunk makes reading
    it fail instead of returning silently wrong pixels; :mod:`scenegen.io.validate` reports
    such chunks. Read errors of damaged files surface as :class:`DataError` with one line.

Lazy reads
    Frames and labels are stored one frame per chunk, so reading a frame range costs in
    proportion to the range; :func:`read` returns lazy arrays that read only what is
    indexed. Writing streams a block of frames at a time (:data:`BLOCK_BYTES`) with no
    chunk cache and a compact chunk index (:data:`LIBVER`), so memory stays bounded
    whatever the sequence length.

Concurrent readers
    Because writers only ever rename complete files into place, a reader opens either the
    old complete file or the new one. :func:`read` pins its lazy arrays to the version
    whose ground truth it read (and reads again if a writer replaced the file in between);
    an open lazy array keeps reading its version, and one reopened after the file was
    replaced raises :class:`DataError`. HDF5 SWMR is not used: a file that another
    program holds open for writing is refused with "is being written by another process",
    and a temporary file is refused as "an unfinished temporary file".
"""

from __future__ import annotations

import json
import os
import re
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import h5py
import numpy as np
from numpy.typing import NDArray

from scenegen.config import from_stored, to_dict
from scenegen.errors import ConfigError, DataError, NotInFile
from scenegen.io import guard
from scenegen.io.atomic import (
    atomic_path,
    clean_temp_files,
    describe_special_file,
    describe_temp_file,
    temp_file_owner,
    temp_prefix,
)
from scenegen.io.integrity import (
    DIGEST,
    INTEGRITY,
    Hasher,
    as_text,
    digest,
    put_attrs_digest,
    put_text,
    text_array,
)
from scenegen.io.schema import (
    CONVENTIONS,
    GT_FIELDS,
    SCHEMA,
    Field,
    dataset_attrs,
    field,
    schema_problem,
    template_size_problem,
)
from scenegen.sequence import Entities, GroundTruth, Sequence

__all__ = [
    "BLOCK_BYTES",
    "COMPRESSIONS",
    "LIBVER",
    "SCHEMA",
    "LazyArray",
    "atomic_path",
    "clean_temp_files",
    "describe_open_error",
    "describe_read_error",
    "describe_temp_file",
    "filter_options",
    "frames_per_block",
    "open_checked",
    "read",
    "sequence_names",
    "temp_file_owner",
    "temp_prefix",
    "write",
    "write_scenario",
]

COMPRESSIONS = ("gzip", "lzf", "none")
BLOCK_BYTES = 32 * 2**20
"""Upper bound on the pixel bytes (frames + labels) of one block rendered and written at
once: long or large sequences are written a block at a time in bounded memory."""

LIBVER = ("v110", "v110")
"""HDF5 file-format bounds of written files: readable by HDF5 1.10 and later (2016), and
their chunk index (a fixed array) stays small whatever the frame count, so writing
20,000 frames does not grow memory the way the 1.8 format's B-tree index does."""

# Writers write whole chunks once and never read them back, so the chunk cache (8 MiB per
# dataset by default in HDF5 2) would only hold memory: it is switched off.
_WRITE_OPTIONS: dict[str, Any] = {"libver": LIBVER, "rdcc_nbytes": 0}
_BLOCK = 64  # frames per write call, at most
_READ_ATTEMPTS = 5  # reads of a path that atomic writers keep replacing


def __getattr__(name: str) -> Any:
    # Tracker result files moved to scenegen.io.results; old imports from here still work.
    if name in ("TrackerResult", "read_result", "write_result"):
        from scenegen.io import results

        return getattr(results, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _version() -> str:
    from scenegen import __version__

    return __version__


# ---------------------------------------------------------------------------------------
# Writing


def filter_options(compression: str) -> dict[str, Any]:
    """h5py dataset options for ``compression``, always with the Fletcher-32 checksum.

    Parameters
    ----------
    compression : {'gzip', 'lzf', 'none'}

    Returns
    -------
    dict
        Keyword arguments for ``create_dataset``.

    Raises
    ------
    ConfigError
        For another compression name.
    """
    if compression not in COMPRESSIONS:
        raise ConfigError(
            f"compression must be one of {', '.join(COMPRESSIONS)}; got {compression!r}"
        )
    if compression == "gzip":
        return {"compression": "gzip", "compression_opts": 4, "fletcher32": True}
    if compression == "lzf":
        return {"compression": "lzf", "fletcher32": True}
    return {"fletcher32": True}


def frames_per_block(height: int, width: int, limit: int = _BLOCK) -> int:
    """Frames rendered and written at once: at most ``limit`` and :data:`BLOCK_BYTES`.

    Parameters
    ----------
    height, width : int
        Frame size in pixels.
    limit : int
        Upper bound on the block length.

    Returns
    -------
    int
        At least 1.
    """
    per_frame = height * width * 5  # RGB uint8 + uint16 label
    return max(1, min(limit, BLOCK_BYTES // max(per_frame, 1)))


def _write_header(f: h5py.File) -> None:
    put_text(f, "schema", SCHEMA)
    put_text(f, "generator_version", _version())
    put_text(f, "conventions", "\n".join(CONVENTIONS))
    put_text(f, INTEGRITY, DIGEST)


def _seal(f: h5py.File) -> None:
    """Last step of every write: the digest of the root's attributes."""
    put_attrs_digest(f)


def _dataset(g: h5py.Group, f: Field, *, name: str | None = None, **kwargs: Any) -> h5py.Dataset:
    """Create the dataset of ``f`` in ``g`` (at ``name``, default its path) with its
    ``description`` and ``units`` attributes; ``kwargs`` go to ``create_dataset``. Given
    ``data``, the dataset is checksummed (chunked, Fletcher-32) and digested at once;
    else the caller fills it and calls :func:`_digest` with the values written."""
    data = kwargs.get("data")
    if data is not None:
        data = kwargs["data"] = np.asarray(data, dtype=kwargs.pop("dtype", None))
        if data.size and "chunks" not in kwargs:
            kwargs.update(chunks=data.shape, fletcher32=True)
    ds = g.create_dataset(f.path if name is None else name, **kwargs)
    for key, value in dataset_attrs(f).items():
        put_text(ds, key, value)
    if data is not None:
        _digest(ds, digest(data), f)
    return ds


def _digest(ds: h5py.Dataset, hexdigest: str, f: Field | None = None) -> None:
    """Store the values' digest and the attributes' digest of a dataset made by
    :func:`_dataset`; given its field ``f``, the attributes' digest is computed from
    ``dataset_attrs(f)`` (what :func:`_dataset` wrote), not read back."""
    put_text(ds, DIGEST, hexdigest)
    put_attrs_digest(ds, None if f is None else dataset_attrs(f))


def _hashers(*datasets: h5py.Dataset) -> dict[str, Hasher]:
    return {ds.name: Hasher() for ds in datasets}


def _fill(ds: h5py.Dataset, start: int, values: Any, hashers: dict[str, Hasher]) -> None:
    """Write rows ``start:`` of ``ds`` (converted to its dtype first, so the digest is of
    the values stored) and feed them to its hasher; rows come in order."""
    arr = np.asarray(values, dtype=ds.dtype)
    if ds.size:
        ds[start : start + arr.shape[0]] = arr
    hashers[ds.name].update(arr)


def _close_hashers(f: h5py.File, hashers: dict[str, Hasher]) -> None:
    for name, h in hashers.items():
        _digest(f[name], h.hexdigest())


def _create_sequence_group(
    f: h5py.File, seq_meta: dict[str, Any], entities: Entities, compression: str
) -> tuple[h5py.Group, h5py.Dataset, h5py.Dataset]:
    name = seq_meta["name"]
    if f"sequences/{name}" in f:
        raise ConfigError(f"two sequences are named {name!r}: names must be unique in a file")
    g = f.require_group("sequences").create_group(name)
    t, h, w = seq_meta["n_frames"], seq_meta["height"], seq_meta["width"]
    g.attrs["seed"] = int(seq_meta["seed"])
    put_text(g, "config", json.dumps(seq_meta["config"], sort_keys=True))
    put_text(g, "preset", str(seq_meta["preset"]))
    g.attrs["n_frames"] = t
    g.attrs["height"] = h
    g.attrs["width"] = w
    put_attrs_digest(g)
    filt = filter_options(compression)
    pixels = []
    for f in (field("frames"), field("labels")):
        shape = f.shape_for(T=t, H=h, W=w)
        pixels.append(_dataset(g, f, shape=shape, dtype=f.dtype, chunks=(1, *shape[1:]), **filt))
    g.create_group("entities")
    _dataset(g, field("entities/id"), data=entities.id.astype(np.int32))
    # Fixed-length strings: out of the global heap (see scenegen.io.integrity).
    _dataset(g, field("entities/role"), data=text_array(entities.role))
    _dataset(g, field("entities/name"), data=text_array(entities.name))
    return g, pixels[0], pixels[1]


def _create_gt(g: h5py.Group, t: int, k: int, rows: int) -> dict[str, h5py.Dataset]:
    """Empty ground-truth datasets, chunked by ``rows`` frames, checksummed."""
    g.create_group("gt")
    out = {}
    for key, dtype in GT_FIELDS.items():
        f = field(f"gt/{key}")
        shape = f.shape_for(T=t, K=k)
        if k == 0:  # nothing to checksum; HDF5 chunks cannot have a zero side
            out[key] = _dataset(g, f, shape=shape, dtype=dtype)
        else:
            chunks = (max(1, min(rows, t)), *shape[1:])
            out[key] = _dataset(g, f, shape=shape, dtype=dtype, chunks=chunks, fletcher32=True)
    return out


def _write_gt(g: h5py.Group, gt: dict[str, NDArray[Any]]) -> None:
    t, k = np.shape(gt["present"])[:2]
    for key, ds in _create_gt(g, t, k, _BLOCK).items():
        arr = np.asarray(gt[key], dtype=GT_FIELDS[key])
        if ds.size:
            ds[...] = arr
        _digest(ds, digest(arr.astype(ds.dtype)), field(f"gt/{key}"))


def _write_templates(g: h5py.Group, templates: dict[int, NDArray[np.uint8]]) -> None:
    group = g.create_group("templates")
    f = field("templates/<id>")
    for eid, tpl in templates.items():
        _dataset(group, f, name=str(int(eid)), data=np.asarray(tpl, dtype=np.uint8))


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
        At least one; names must be unique. Lazy frames (from :func:`read`) are copied a
        block at a time, so memory stays bounded.
    compression : {'gzip', 'lzf', 'none'}
        Filter for frames and labels (one frame per chunk).

    Raises
    ------
    ConfigError
        No sequence, an argument that is not a :class:`Sequence` (``write(path, [seq])``),
        duplicate names, a bad compression or a missing folder.
    """
    if not sequences:
        raise ConfigError("write needs at least one sequence")
    for seq in sequences:
        if not isinstance(seq, Sequence):  # a preset name, a list of sequences, ...
            raise ConfigError(f"write takes Sequence objects, got a {type(seq).__name__}")
    filter_options(compression)
    with atomic_path(path) as tmp, h5py.File(tmp, "w", **_WRITE_OPTIONS) as f:
        _write_header(f)
        for seq in sequences:
            g, frames, labels = _create_sequence_group(f, _meta(seq), seq.entities, compression)
            hashers = _hashers(frames, labels)
            # Blocks of whole chunks: bounded memory for lazy inputs, few h5py calls.
            block = frames_per_block(seq.height, seq.width)
            for t in range(0, seq.n_frames, block):
                stop = min(t + block, seq.n_frames)
                _fill(frames, t, seq.frames[t:stop], hashers)
                _fill(labels, t, seq.labels[t:stop], hashers)
            _close_hashers(f, hashers)
            _write_gt(g, seq.gt.as_dict())
            _write_templates(g, seq.templates)
        _seal(f)
    guard.trust(path)


def write_scenario(
    path: str | Path,
    scenario: Any,
    *,
    compression: str = "gzip",
    chunk: int = _BLOCK,
    progress: Callable[[int], None] | None = None,
) -> None:
    """Render ``scenario`` (:class:`scenegen.render.plan.Scenario`) straight into a file.

    Frames and their ground truth are rendered and written a block at a time (at most
    ``chunk`` frames and :data:`BLOCK_BYTES` of pixels), so memory stays bounded whatever
    the sequence length; the file appears at ``path`` only when complete.

    Parameters
    ----------
    path : str or Path
    scenario : Scenario
    compression : {'gzip', 'lzf', 'none'}
    chunk : int
        Upper bound on the frames rendered at once.
    progress : callable, optional
        Called with the number of frames written so far.

    Raises
    ------
    ConfigError
        A bad compression or a missing folder.
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
    filter_options(compression)
    block = frames_per_block(cfg.height, cfg.width, max(1, int(chunk)))
    with atomic_path(path) as tmp, h5py.File(tmp, "w", **_WRITE_OPTIONS) as f:
        _write_header(f)
        g, frames, labels = _create_sequence_group(f, meta, scenario.entities(), compression)
        gt = _create_gt(g, cfg.n_frames, scenario.n_entities, block)
        hashers = _hashers(frames, labels, *gt.values())
        for c in scenario.chunks(block):
            stop = c.start + c.frames.shape[0]
            # Chunk-aligned writes: h5py writes whole chunks without reading them back.
            _fill(frames, c.start, c.frames, hashers)
            _fill(labels, c.start, c.labels, hashers)
            for key, ds in gt.items():
                _fill(ds, c.start, c.gt[key], hashers)
            if progress is not None:
                progress(stop)
            del c  # else this block stays alive while the next one renders: twice the memory
        _close_hashers(f, hashers)
        _write_templates(g, scenario.template_images())
        _seal(f)
    guard.trust(path)


# ---------------------------------------------------------------------------------------
# Reading


def describe_open_error(path: str | Path, err: OSError) -> str:
    """One line saying why HDF5 could not open ``path``.

    Parameters
    ----------
    path : str or Path
    err : OSError
        What ``h5py.File`` raised.

    Returns
    -------
    str
        ``"PATH: ..."``: an unfinished temporary file of an atomic write, truncated (with
        the byte counts), being written by another process, not HDF5 at all, not
        readable (permission denied), or otherwise damaged.
    """
    p = Path(path)
    text = str(err)
    temp = describe_temp_file(p)
    if temp is not None:
        return temp
    if "unable to lock file" in text:
        return f"{p}: is being written by another process (the HDF5 file is locked)"
    m = re.search(r"truncated file: eof = (\d+).*stored_eof = (\d+)", text)
    if m:
        return f"{p}: truncated HDF5 file ({m[1]} of {m[2]} bytes)"
    if "file signature not found" in text:
        return f"{p}: not an HDF5 file"
    if "errno = 13" in text or isinstance(err, PermissionError):
        return f"{p}: cannot read the file (permission denied)"
    first = text.strip().splitlines()[0] if text.strip() else type(err).__name__
    return f"{p}: not a readable HDF5 file (truncated or corrupted: {first})"


def describe_read_error(err: BaseException) -> str:
    """One line for an error h5py raised while reading a dataset.

    Parameters
    ----------
    err : BaseException

    Returns
    -------
    str
        ``"checksum or decompression failed"`` for a damaged chunk, else the error's
        first line.
    """
    text = str(err).strip().splitlines()
    first = text[0] if text else type(err).__name__
    if "filter returned failure" in first:
        return "checksum or decompression failed"
    return first


def _stamp(f: h5py.File) -> tuple[int, int, int]:
    """Identity of the file actually open (inode, size, mtime): atomic writers replace a
    path with a new inode, so a stamp tells which version of a path was read."""
    try:
        st = os.fstat(f.id.get_vfd_handle())
    except (OSError, TypeError, ValueError, RuntimeError):  # a driver without a descriptor
        st = os.stat(f.filename)
    return st.st_ino, st.st_size, st.st_mtime_ns


class _Replaced(DataError):
    """The path now names another file than the one read first."""


def _key_text(key: Any) -> str:
    if isinstance(key, slice):
        return f"{'' if key.start is None else key.start}:{'' if key.stop is None else key.stop}"
    if isinstance(key, tuple):
        return ", ".join(_key_text(k) for k in key)
    return "..." if key is Ellipsis else str(key)


def _numpy_only(key: Any) -> bool:
    """Whether h5py cannot read ``key`` (a first-axis index) as numpy would."""
    if isinstance(key, slice):
        return key.step is not None and key.step < 0
    if isinstance(key, (list, np.ndarray)):
        a = np.asarray(key)
        if a.dtype == bool or a.ndim != 1:
            return True
        return a.size > 1 and not bool(np.all(np.diff(a) > 0)) or bool((a < 0).any())
    return False


class LazyArray:
    """A read-only view of an HDF5 dataset that reads only what is indexed.

    Supports ``shape``, ``dtype``, ``len()``, integer/slice indexing and ``np.asarray``.
    The file is opened on first access and reopened after pickling, so lazy arrays can be
    sent to worker processes. Reopening checks that the file is still the one first
    opened (atomic writers replace files whole), and a damaged chunk raises
    :class:`DataError` naming the file, dataset and index.

    Parameters
    ----------
    path : str or Path
    dataset : str
        Path of the dataset inside the file.
    stamp : tuple of int, optional
        Identity (inode, size, mtime) of the file version this array must read; by
        default the version found when it is first opened.

    Raises
    ------
    DataError
        When the file cannot be opened, is not the expected version, holds no dataset
        ``dataset`` (missing, or a group), or a read fails.
    """

    def __init__(
        self, path: str | Path, dataset: str, *, stamp: tuple[int, int, int] | None = None
    ) -> None:
        self.path = str(path)
        self.dataset = dataset
        self._file: h5py.File | None = None
        self._stamp = stamp
        ds = self._ds()
        self.shape: tuple[int, ...] = tuple(ds.shape)
        self.dtype = ds.dtype

    def _ds(self) -> h5py.Dataset:
        if self._file is None or not self._file.id.valid:
            if not os.path.exists(self.path):
                raise DataError(f"{self.path}: no longer exists")
            if self._stamp is None:  # not opened through read(): a file not yet checked
                guard.preflight(self.path)
            try:
                f = h5py.File(self.path, "r")
            except OSError as err:
                raise DataError(describe_open_error(self.path, err)) from None
            stamp = _stamp(f)
            if self._stamp is not None and stamp != self._stamp:
                f.close()
                raise _Replaced(
                    f"{self.path}: the file was replaced or changed since it was read; "
                    "read it again"
                )
            self._file, self._stamp = f, stamp
        ds = self._file.get(self.dataset)
        if not isinstance(ds, h5py.Dataset):
            raise DataError(f"{self.path}: holds no dataset {self.dataset!r}")
        return ds

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state["_file"] = None
        return state

    def __len__(self) -> int:
        return self.shape[0]

    @property
    def ndim(self) -> int:
        """Number of dimensions, an int (``len(shape)``)."""
        return len(self.shape)

    def _get(self, key: Any) -> NDArray[Any]:
        try:
            return self._read(key)
        except (OSError, RuntimeError) as err:
            raise DataError(
                f"{self.path}: {self.dataset}[{_key_text(key)}] is unreadable "
                f"(damaged file: {describe_read_error(err)})"
            ) from None

    def _read(self, key: Any) -> NDArray[Any]:
        """``dataset[key]`` with numpy's semantics on the first axis: h5py reads only
        increasing positive steps and increasing, distinct index lists, so a reversed
        slice, a boolean mask or a list in any order (repeats allowed) is read as its
        distinct rows in increasing order and rearranged here."""
        ds = self._ds()
        parts = key if isinstance(key, tuple) else (key,)
        first = parts[0] if parts else None
        if not self.shape or not _numpy_only(first):
            return ds[key]
        idx = np.arange(self.shape[0])[first]  # numpy's rules and its IndexError
        rows, inverse = np.unique(idx, return_inverse=True)
        if rows.size == 0:
            return ds[(slice(0, 0),) + parts[1:]][np.zeros(idx.shape, dtype=np.intp)]
        return ds[(rows,) + parts[1:]][inverse.reshape(idx.shape)]

    def __getitem__(self, key: Any) -> NDArray[Any]:
        return self._get(key)

    def __array__(self, dtype: Any = None, copy: Any = None) -> NDArray[Any]:
        arr = self._get(())
        return arr if dtype is None else arr.astype(dtype)

    def __iter__(self) -> Iterator[NDArray[Any]]:
        for t in range(self.shape[0]):
            yield self[t]

    def close(self) -> None:
        """Close this array's handle on the file, if open (no-op otherwise).

        The array stays usable: the next access reopens the file, checking that it is
        still the version first read.
        """
        if self._file is not None:
            self._file.close()
            self._file = None

    def __repr__(self) -> str:
        return f"LazyArray({self.path!r}, {self.dataset!r}, shape={self.shape}, dtype={self.dtype})"


def open_checked(path: str | Path) -> h5py.File:
    """Open an HDF5 file for reading and check its schema.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    h5py.File
        Open for reading; the caller closes it.

    Raises
    ------
    DataError
        If the file is missing, a folder, a FIFO or device, a temporary file of an
        unfinished write, not HDF5, truncated, being written by another process, or of
        another schema; or if its metadata is damaged or cannot be read within the deadline
        (:func:`scenegen.io.guard.preflight`).
    """
    p = Path(path)
    if not p.exists():
        raise DataError(f"{p}: no such file")
    if p.is_dir():
        raise DataError(f"{p}: is a folder, not a scenegen file")
    special = describe_special_file(p)
    if special is not None:  # HDF5 would wait on a FIFO until the deadline
        raise DataError(special)
    temp = describe_temp_file(p)
    if temp is not None:  # incomplete by construction, even when HDF5 could open it
        raise DataError(temp)
    guard.preflight(p)  # metadata read in a child under a deadline, once per version
    try:
        f = h5py.File(p, "r")
    except OSError as err:
        raise DataError(describe_open_error(p, err)) from None
    try:
        schema = f.attrs.get("schema")
    except (OSError, RuntimeError, KeyError):
        f.close()
        raise DataError(f"{p}: damaged HDF5 file (unreadable attributes)") from None
    if problem := schema_problem(schema):
        f.close()
        raise DataError(f"{p}: {problem}")
    return f


def sequence_names(path: str | Path) -> list[str]:
    """Names of the sequences in a file.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    list of str
    """
    with open_checked(path) as f:
        return _members(Path(path), f, "sequences")


def _str_array(ds: h5py.Dataset) -> NDArray[np.str_]:
    return np.array([v.decode() if isinstance(v, bytes) else str(v) for v in ds[()]], dtype=str)


def _read_gt(g: h5py.Group) -> GroundTruth:
    """The ground truth of sequence group ``g``; an optional field the file lacks (files
    written before it existed) is NaN-filled at its shape."""
    arrays = {}
    t, k = g["gt/present"].shape
    for key, dtype in GT_FIELDS.items():
        if key in g["gt"]:
            arrays[key] = g[f"gt/{key}"][()].astype(dtype)
        elif field(f"gt/{key}").optional:
            arrays[key] = np.full(field(f"gt/{key}").shape_for(T=t, K=k), np.nan, dtype)
        else:
            raise KeyError(f"missing dataset gt/{key}")
    return GroundTruth(**arrays)


def read(path: str | Path, name: str | None = None) -> Sequence:
    """Read one sequence; frames and labels stay on disk as :class:`LazyArray`.

    Parameters
    ----------
    path : str or Path
    name : str, optional
        The sequence to read; required when the file holds several.

    Returns
    -------
    Sequence
        Ground truth, entities and templates in memory (O(T K)); pixels lazy, pinned to
        the same version of the file (if a writer replaces it meanwhile, the lazy arrays
        keep reading the version whose ground truth was read).

    Raises
    ------
    DataError
        If the file is not a valid scenegen file, is damaged, or has no such sequence.
    """
    for _ in range(_READ_ATTEMPTS - 1):
        try:
            return _read_once(Path(path), name)
        except _Replaced:  # replaced by an atomic writer between two opens: read again
            continue
    return _read_once(Path(path), name)


def _members(p: Path, f: h5py.File, group: str) -> list[str]:
    """Names in ``/group`` (none if absent); a damaged group is a DataError."""
    try:
        if group in f and not isinstance(f[group], h5py.Group):
            raise DataError(f"{p}: /{group} is not a group")
        return list(f[group].keys()) if group in f else []
    except (KeyError, ValueError, TypeError, OSError, RuntimeError) as err:
        raise DataError(f"{p}: /{group} is damaged: {describe_read_error(err)}") from None


def _read_once(p: Path, name: str | None) -> Sequence:
    with open_checked(p) as f:
        stamp = _stamp(f)
        seqs = _members(p, f, "sequences")
        if not seqs:
            raise DataError(f"{p}: holds no sequences")
        if name is None:
            if len(seqs) > 1:
                raise NotInFile(f"{p}: holds {len(seqs)} sequences; name one of "
                                f"{', '.join(seqs)}")  # fmt: skip
            name = seqs[0]
        if name not in seqs:
            raise NotInFile(f"{p}: no sequence {name!r}; it holds {', '.join(seqs)}")
        try:
            g = f[f"sequences/{name}"]
            config = from_stored(json.loads(g.attrs["config"]))
            entities = Entities(
                id=g["entities/id"][()].astype(np.int32),
                role=_str_array(g["entities/role"]),
                name=_str_array(g["entities/name"]),
            )
            gt = _read_gt(g)
            held = dict(g["templates"].items())
            if too_big := template_size_problem([getattr(v, "shape", ()) for v in held.values()]):
                raise DataError(f"{p}: sequence {name!r} is damaged: {too_big}")
            templates = {int(k): v[()] for k, v in held.items()}
            seed, preset = int(g.attrs["seed"]), as_text(g.attrs["preset"])
            frames = LazyArray(p, f"sequences/{name}/frames", stamp=stamp)
            labels = LazyArray(p, f"sequences/{name}/labels", stamp=stamp)
        except _Replaced:
            raise
        except (KeyError, ValueError, TypeError, OSError, RuntimeError, ConfigError) as err:
            raise DataError(
                f"{p}: sequence {name!r} is damaged: {describe_read_error(err)}"
            ) from None
    return Sequence(
        name=name,
        seed=seed,
        config=config,
        preset=preset,
        frames=frames,
        labels=labels,
        entities=entities,
        gt=gt,
        templates=templates,
    )
