"""Checks of a scenegen HDF5 file against schema ``scenegen/1``.

:func:`check_file` returns one line per problem (empty when the file is valid), each
naming the file, the sequence and what is wrong:

- the file: missing, a folder, a FIFO or device, an unfinished temporary file of a write,
  not HDF5, truncated (with the byte counts), locked by a writer, or with a wrong or
  missing schema;
- the layout: missing attributes, groups or datasets, shape or dtype mismatches, a config
  attribute that does not parse or disagrees with the size attributes, missing templates;
- the data: chunks that fail their checksum or decompression (named by frame), ids that
  are not unique and >= 1 (or above what uint16 labels hold), unknown roles, ``labels``
  naming unknown ids, visible boxes or visibilities that disagree with ``labels``, NaN
  patterns that disagree with ``present``, infinite boxes or centres (or a box off the
  frame) where present, centres that disagree with boxes, values out of range.

Frames and labels are read one frame at a time, so memory stays bounded whatever the
file's length; ground truth (T x K) is read whole. Nothing here raises on a damaged file.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import h5py
import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from scenegen.config import from_stored
from scenegen.errors import ConfigError, DataError
from scenegen.io import describe_open_error, describe_read_error, describe_temp_file
from scenegen.io.atomic import describe_special_file
from scenegen.io.guard import beat, call
from scenegen.io.guard import timeout as guard_timeout
from scenegen.io.integrity import ATTRS_DIGEST, DIGEST, INTEGRITY, Hasher, as_text, attrs_digest
from scenegen.io.results import bad_box_rows, bad_probabilities, repeated_ids
from scenegen.io.schema import (
    GT_FIELDS,
    RESULT_FIELDS,
    ROLES,
    SEQUENCE_FIELDS,
    field,
    schema_problem,
    template_size_problem,
)

__all__ = ["check_file", "require_valid"]

_MAX_PER_KIND = 5  # frames listed per kind of problem
_READ_ERRORS = (OSError, RuntimeError, KeyError, ValueError, TypeError)
_ROLES = set(ROLES)
_OPTIONAL = {f.path for f in SEQUENCE_FIELDS if f.optional}  # absent from older files
_RESULT_DTYPE = {f.path: f.numpy_dtype for f in RESULT_FIELDS}
_ATTRS = ("seed", "config", "preset", "n_frames", "height", "width")
_LABELS_DTYPE = field("labels").numpy_dtype
_MAX_ID = int(np.iinfo(_LABELS_DTYPE).max)  # the largest id labels can hold


def check_file(
    path: str | Path, *, check_pixels: bool = True, isolate: bool = False, deep: bool = False
) -> list[str]:
    """Validate a scenegen file; return one line per problem found.

    Parameters
    ----------
    path : str or Path
        A sequence file or a tracker result file.
    check_pixels : bool
        Also read every frame (checksums) and re-derive visible boxes and visibility
        from ``labels`` frame by frame.
    isolate : bool
        Run the check in a guarded child process (:func:`scenegen.io.guard.call`). The
        HDF5 library can crash (segmentation fault) or loop forever on some corrupted
        metadata; isolated, a crash or a stall (no progress within the deadline) becomes
        one problem line instead of killing or hanging the caller. ``scenegen validate``
        always isolates.
    deep : bool
        Also re-render every sequence from its stored config and seed (rendering is
        deterministic) and name every dataset whose values differ: catches edits that
        were written with valid checksums and digests.

    Returns
    -------
    list of str
        Empty when the file is valid.

    Examples
    --------
    >>> check_file("missing.h5")
    ['missing.h5: no such file']
    """
    p = Path(path)
    if isolate:
        return _check_in_child(p, check_pixels, deep)
    if not p.exists():
        return [f"{p}: no such file"]
    if p.is_dir():
        return [f"{p}: is a folder, not a scenegen file"]
    special = describe_special_file(p)
    if special is not None:  # HDF5 would wait on a FIFO until the deadline
        return [special]
    temp = describe_temp_file(p)
    if temp is not None:
        return [temp]
    try:
        f = h5py.File(p, "r")
    except OSError as err:
        return [describe_open_error(p, err)]
    try:
        with f:
            problems = _check_open_file(p, f, check_pixels)
            if deep and "sequences" in f:
                problems += _check_deep(p, f)
            return problems
    except _READ_ERRORS as err:
        return [f"{p}: damaged HDF5 metadata ({_one_line(err)})"]


def require_valid(path: str | Path) -> None:
    """Refuse a file that :func:`check_file` (without the pixel pass) finds problems in.

    The check verbs run before they compute on a file (``track``, ``evaluate``,
    ``export``, ``preview``): layout, shapes, dtypes, NaN patterns against ``present``,
    ids, roles and the digests of everything but frames and labels (whose chunks are
    checksummed and fail when read). It runs in a guarded child, so it is also the
    metadata preflight of :func:`scenegen.io.read`: a file that passes is not surveyed
    again.

    Parameters
    ----------
    path : str or Path

    Raises
    ------
    DataError
        The first problem line, with the count of the others: one line.
    """
    from scenegen.io import guard

    p = Path(path)
    try:
        version = guard._version_key(p)
    except OSError:
        version = None
    problems = check_file(p, check_pixels=False, isolate=True)
    if problems:
        more = len(problems) - 1
        note = f" (and {more} more problem{'s' if more > 1 else ''}: run scenegen validate)"
        raise DataError(problems[0] + (note if more else ""))
    if version is not None:
        guard._remember(version)


def _checked(path: str, check_pixels: bool, deep: bool) -> list[str]:
    return check_file(path, check_pixels=check_pixels, deep=deep)


def _check_in_child(p: Path, check_pixels: bool, deep: bool) -> list[str]:
    """:func:`check_file` in a guarded child (:mod:`scenegen.io.guard`): a crash or a
    stall of the HDF5 library (no progress within the deadline) is one problem line."""
    try:
        # Planning a long scene for --deep may take a while before the first beat.
        seconds = guard_timeout() * (10 if deep else 1)
        problems: list[str] = call(
            _checked, str(p), check_pixels, deep, label=str(p), seconds=seconds
        )
    except DataError as err:
        return [str(err)]
    return problems


def _check_open_file(p: Path, f: h5py.File, check_pixels: bool) -> list[str]:
    if problem := schema_problem(f.attrs.get("schema")):
        return [f"{p}: {problem}"]
    problems: list[str] = []
    if "generator_version" not in f.attrs:
        problems.append(f"{p}: missing attribute generator_version")
    for group in ("sequences", "results"):
        if group in f and not isinstance(f[group], h5py.Group):
            return [*problems, f"{p}: /{group} is not a group"]
    if "sequences" in f:
        names = list(f["sequences"].keys())
        if not names:
            problems.append(f"{p}: /sequences holds no sequence")
        for name in names:
            where = f"{p}: sequence {name!r}"
            try:
                problems += _check_sequence(where, f[f"sequences/{name}"], check_pixels)
            except _READ_ERRORS as err:
                problems.append(f"{where}: unreadable ({_one_line(err)})")
    if "results" in f:
        problems += _check_results(p, f["results"])
    if "sequences" not in f and "results" not in f:
        problems.append(f"{p}: holds neither /sequences nor /results")
    return problems + _check_digests(p, f, check_pixels, problems)


def _one_line(err: BaseException) -> str:
    text = str(err).strip().splitlines()
    return text[0] if text else type(err).__name__


def _frames(idx: list[int] | NDArray[Any]) -> str:
    idx = [int(i) for i in idx]
    shown = ", ".join(str(i) for i in idx[:_MAX_PER_KIND])
    return shown + (f" (+{len(idx) - _MAX_PER_KIND} more)" if len(idx) > _MAX_PER_KIND else "")


def _expected(t: int, h: int, w: int, k: int) -> dict[str, tuple[tuple[int, ...], Any]]:
    """Shape and dtype of each dataset of the layout (scenegen.io.schema), by path."""
    return {
        f.path: (f.shape_for(T=t, H=h, W=w, K=k), f.numpy_dtype)
        for f in SEQUENCE_FIELDS
        if "<" not in f.path
    }


def _dtype_ok(ds: h5py.Dataset, dtype: Any) -> bool:
    if dtype is str:
        return h5py.check_string_dtype(ds.dtype) is not None
    return ds.dtype == np.dtype(dtype)


def _dtype_name(dtype: Any) -> str:
    return "string" if dtype is str else str(np.dtype(dtype))


def _layout(where: str, g: h5py.Group) -> tuple[list[str], tuple[int, int, int, int]]:
    """Attributes, datasets, shapes and dtypes; returns problems and (T, H, W, K)."""
    if not isinstance(g, h5py.Group):
        return [f"{where}: is not a group"], (0, 0, 0, 0)
    problems = [f"{where}: missing attribute {a}" for a in _ATTRS if a not in g.attrs]
    size: dict[str, int] = {}
    for a in ("n_frames", "height", "width"):
        if a in g.attrs:
            try:
                size[a] = int(g.attrs[a])
            except (TypeError, ValueError):
                problems.append(f"{where}: attribute {a} is not an integer: {g.attrs[a]!r}")
    if "config" in g.attrs:
        try:
            cfg = from_stored(json.loads(g.attrs["config"]))
        except (ValueError, TypeError, ConfigError) as err:
            problems.append(f"{where}: attribute config is not a valid config: {_one_line(err)}")
        else:
            for a, value in (("n_frames", cfg.n_frames), ("height", cfg.height),
                             ("width", cfg.width)):  # fmt: skip
                if a in size and size[a] != value:
                    problems.append(
                        f"{where}: attribute {a}={size[a]} disagrees with the config's {value}"
                    )
    if len(size) < 3:
        return problems, (0, 0, 0, 0)
    t, h, w = size["n_frames"], size["height"], size["width"]
    k = -1
    if isinstance(g.get("entities/id"), h5py.Dataset) and g["entities/id"].ndim == 1:
        k = int(g["entities/id"].shape[0])
    for key, (shape, dtype) in _expected(t, h, w, max(k, 0)).items():
        obj = g.get(key)
        if obj is None:
            if key not in _OPTIONAL:
                problems.append(f"{where}: missing dataset {key}")
        elif not isinstance(obj, h5py.Dataset):
            problems.append(f"{where}: {key} is not a dataset")
        else:
            if k < 0 and key == "entities/id":
                problems.append(f"{where}: entities/id has shape {obj.shape}, expected (K,)")
            elif obj.shape != shape:
                problems.append(f"{where}: {key} has shape {obj.shape}, expected {shape}")
            if not _dtype_ok(obj, dtype):
                problems.append(
                    f"{where}: {key} has dtype {obj.dtype}, expected {_dtype_name(dtype)}"
                )
    if not isinstance(g.get("templates"), h5py.Group):
        problems.append(f"{where}: missing group templates")
    return problems, (t, h, w, k)


def _read_small(where: str, g: h5py.Group, keys: list[str]) -> tuple[dict[str, Any], list[str]]:
    out, problems = {}, []
    for key in keys:
        beat()
        try:
            out[key] = g[key][()]
        except _READ_ERRORS as err:
            problems.append(f"{where}: {key} is unreadable ({describe_read_error(err)})")
    return out, problems


def _check_sequence(where: str, g: h5py.Group, check_pixels: bool) -> list[str]:
    problems, (t, h, w, k) = _layout(where, g)
    if problems:
        return problems
    keys = ["entities/id", "entities/role", *(f"gt/{key}" for key in GT_FIELDS if f"gt/{key}" in g)]
    data, problems = _read_small(where, g, keys)
    if "entities/id" not in data:
        return problems
    ids = data["entities/id"]
    if np.any(ids < 1) or len(np.unique(ids)) != k:
        problems.append(f"{where}: entities/id must be unique and >= 1, got {ids.tolist()[:10]}")
        return problems
    if k and int(ids.max()) > _MAX_ID:  # labels could not name it (and the checks below
        # would size their tables by it: 2**31 ids stalled the check)
        problems.append(
            f"{where}: entities/id must be at most {_MAX_ID} (labels are "
            f"{np.dtype(_LABELS_DTYPE)}), got {int(ids.max())}"
        )
        return problems
    if "entities/role" in data:
        roles = {r.decode() if isinstance(r, bytes) else str(r) for r in data["entities/role"]}
        if roles - _ROLES:
            problems.append(f"{where}: entities/role has unknown roles {sorted(roles - _ROLES)}")
    problems += _check_templates(where, g["templates"], ids)
    gt = {key: data.get(f"gt/{key}") for key in GT_FIELDS if f"gt/{key}" in g}
    if all(v is not None for v in gt.values()):
        problems += _check_gt(where, gt, (h, w))
    if check_pixels:
        problems += _check_frames(where, g["frames"])
        problems += _check_labels(where, g["labels"], ids, gt)
    return problems


def _check_templates(where: str, grp: h5py.Group, ids: NDArray[Any]) -> list[str]:
    if too_big := template_size_problem([getattr(ds, "shape", ()) for ds in grp.values()]):
        return [f"{where}: {too_big}"]
    problems = []
    missing = [int(i) for i in ids if str(int(i)) not in grp]
    if missing:
        problems.append(f"{where}: templates missing for ids {_frames(missing)}")
    for key, ds in grp.items():
        if not isinstance(ds, h5py.Dataset) or ds.ndim != 3 or ds.shape[2] != 4:
            shape = getattr(ds, "shape", None)
            problems.append(f"{where}: templates/{key} has shape {shape}, expected (h, w, 4)")
        elif ds.dtype != np.uint8:
            problems.append(f"{where}: templates/{key} has dtype {ds.dtype}, expected uint8")
        else:
            try:
                ds[()]
            except _READ_ERRORS as err:
                problems.append(
                    f"{where}: templates/{key} is unreadable ({describe_read_error(err)})"
                )
    return problems


def _check_gt(where: str, gt: dict[str, NDArray[Any]], size: tuple[int, int]) -> list[str]:
    """The ground-truth invariants of docs/format.md; ``size`` is the frame's (H, W)."""
    beat()
    problems = []
    present = gt["present"].astype(bool)
    for key in ("box", "center", "path_center"):
        if key not in gt:  # path_center: optional, absent from older files
            continue
        nan = np.isnan(gt[key])
        bad = np.flatnonzero((nan.any(axis=-1) == present).any(axis=1) | (
            nan.any(axis=-1) != nan.all(axis=-1)).any(axis=1))  # fmt: skip
        if bad.size:
            problems.append(
                f"{where}: gt/{key} NaN pattern disagrees with gt/present at frames {_frames(bad)}"
            )
        bad = np.flatnonzero((np.isinf(gt[key]).any(axis=-1) & present).any(axis=1))
        if bad.size:
            problems.append(f"{where}: gt/{key} is infinite where present at frames {_frames(bad)}")
    # Present: one pixel of the shape is inside the frame, so the amodal box overlaps it.
    box = gt["box"]
    with np.errstate(invalid="ignore"):
        x, y, bw, bh = box[..., 0], box[..., 1], box[..., 2], box[..., 3]
        inside = (x < size[1]) & (y < size[0]) & (x + bw > 0) & (y + bh > 0)
    bad = np.flatnonzero((~inside & present & np.isfinite(box).all(axis=-1)).any(axis=1))
    if bad.size:
        problems.append(
            f"{where}: gt/box lies outside the frame where present at frames {_frames(bad)}"
        )
    bad = np.flatnonzero((~np.isnan(gt["visible_box"]).all(axis=-1) & ~present).any(axis=1))
    if bad.size:
        problems.append(
            f"{where}: gt/visible_box is set where gt/present is false at frames {_frames(bad)}"
        )
    vis = gt["visibility"]
    bad = np.flatnonzero(((vis != 0) & ~present).any(axis=1))
    if bad.size:
        problems.append(f"{where}: gt/visibility is nonzero where absent at frames {_frames(bad)}")
    bad = np.flatnonzero(((vis < 0) | (vis > 1 + 1e-6) | np.isnan(vis)).any(axis=1))
    if bad.size:
        problems.append(f"{where}: gt/visibility is outside [0, 1] at frames {_frames(bad)}")
    box, center, vb = gt["box"], gt["center"], gt["visible_box"]
    with np.errstate(invalid="ignore"):
        size_bad = (box[..., 2:] <= 0).any(axis=-1) & present
        mid = box[..., :2] + box[..., 2:] / 2
        # The centre is the box's, exactly (float32 sums of integers and halves).
        off = (np.abs(center - mid) > 1e-3).any(axis=-1) & present
        # The visible part lies inside the whole (amodal) box.
        outside = ((vb[..., 0] < box[..., 0] - 1e-3) | (vb[..., 1] < box[..., 1] - 1e-3)
                   | (vb[..., 0] + vb[..., 2] > box[..., 0] + box[..., 2] + 1e-3)
                   | (vb[..., 1] + vb[..., 3] > box[..., 1] + box[..., 3] + 1e-3))  # fmt: skip
        outside &= present & ~np.isnan(vb).any(axis=-1)
    bad = np.flatnonzero(outside.any(axis=1))
    if bad.size:
        problems.append(
            f"{where}: gt/visible_box lies outside gt/box at frames {_frames(bad)}"
        )
    bad = np.flatnonzero(size_bad.any(axis=1))
    if bad.size:
        problems.append(f"{where}: gt/box has width or height <= 0 at frames {_frames(bad)}")
    bad = np.flatnonzero(off.any(axis=1))
    if bad.size:
        problems.append(f"{where}: gt/center is not the centre of gt/box at frames {_frames(bad)}")
    bad = np.flatnonzero((gt["depth"] < 0).any(axis=1))
    if bad.size:
        problems.append(f"{where}: gt/depth is negative at frames {_frames(bad)}")
    return problems


def _check_frames(where: str, frames: h5py.Dataset) -> list[str]:
    bad, reason = [], ""
    for t in range(frames.shape[0]):
        beat()
        try:
            frames[t]
        except _READ_ERRORS as err:
            bad.append(t)
            reason = reason or describe_read_error(err)
    if not bad:
        return []
    return [f"{where}: frames is damaged at frames {_frames(bad)} ({reason})"]


def _check_labels(
    where: str, labels: h5py.Dataset, ids: NDArray[Any], gt: dict[str, Any]
) -> list[str]:
    max_id = int(ids.max()) if ids.size else 0
    # id -> entity index; ids need not be 1..K in order.
    lut = np.full(max_id + 1, -1, dtype=np.int64)
    lut[ids] = np.arange(ids.size)
    unreadable, unknown, box_bad, vis_bad = [], [], [], []
    reason = ""
    vbox, vis, present = gt["visible_box"], gt["visibility"], gt["present"]
    for t in range(labels.shape[0]):
        beat()
        try:
            lab = labels[t]
        except _READ_ERRORS as err:
            unreadable.append(t)
            reason = reason or describe_read_error(err)
            continue
        top = int(lab.max()) if lab.size else 0
        if top > max_id:
            unknown.append(t)
            continue
        counts = np.bincount(lab.ravel(), minlength=max_id + 1)
        if np.any((counts[1:] > 0) & (lut[1:] < 0)):
            unknown.append(t)
            continue
        if vbox is None or vis is None or present is None:
            continue
        slices = ndimage.find_objects(lab.astype(np.int32), max_label=max_id)
        expect = np.full((ids.size, 4), np.nan, dtype=np.float32)
        seen = np.zeros(ids.size, dtype=bool)
        for eid in np.flatnonzero(counts[1:]) + 1:
            k = lut[eid]
            rs, cs = slices[eid - 1]
            expect[k] = (cs.start, rs.start, cs.stop - cs.start, rs.stop - rs.start)
            seen[k] = True
        got = vbox[t]
        same = np.all((expect == got) | (np.isnan(expect) & np.isnan(got)), axis=1)
        if not same.all():
            box_bad.append(t)
        # visibility = visible / amodal pixels, and the amodal pixels fit in the box.
        box = gt.get("box")
        area = (box[t, :, 2].astype(np.float64) * box[t, :, 3] if box is not None
                else np.full(ids.size, np.inf))  # fmt: skip
        with np.errstate(invalid="ignore", divide="ignore"):
            low = counts[ids] / area
        if (np.any(seen & ~present[t]) or np.any((vis[t] > 0) != seen)
                or np.any(seen & (vis[t] < low - 1e-6))):  # fmt: skip
            vis_bad.append(t)
    out = []
    if unreadable:
        out.append(f"{where}: labels is damaged at frames {_frames(unreadable)} ({reason})")
    if unknown:
        out.append(f"{where}: labels name ids not in entities/id at frames {_frames(unknown)}")
    if box_bad:
        out.append(f"{where}: gt/visible_box disagrees with labels at frames {_frames(box_bad)}")
    if vis_bad:
        out.append(
            f"{where}: gt/visibility or gt/present disagree with labels at frames "
            f"{_frames(vis_bad)}"
        )
    return out


def _check_results(p: Path, root: h5py.Group) -> list[str]:
    problems: list[str] = []
    if not isinstance(root, h5py.Group) or not len(root):
        return [f"{p}: /results holds no tracker result"]
    for name, g in root.items():
        where = f"{p}: result {name!r}"
        if not isinstance(g, h5py.Group):
            problems.append(f"{where}: is not a group")
            continue
        problems += [
            f"{where}: missing attribute {a}"
            for a in ("tracker", "params", "seed", "sequence")
            if a not in g.attrs
        ]
        if "params" in g.attrs:
            try:
                json.loads(g.attrs["params"])
            except (ValueError, TypeError) as err:
                problems.append(f"{where}: attribute params is not JSON: {_one_line(err)}")
        missing = [
            key for key in ("target_ids", "boxes") if not isinstance(g.get(key), h5py.Dataset)
        ]
        problems += [f"{where}: missing dataset {key}" for key in missing]
        if missing:
            continue
        m = g["target_ids"].shape[0] if g["target_ids"].ndim == 1 else -1
        t = g["boxes"].shape[0] if g["boxes"].ndim else 0
        expect: dict[str, tuple[tuple[int, ...] | str, Any]] = {
            "target_ids": ((m,) if m >= 0 else "(M,)", _RESULT_DTYPE["target_ids"]),
            "boxes": ((t, m, 4), _RESULT_DTYPE["boxes"]),
        }
        if ("orderings" in g) != ("order_prob" in g):
            problems.append(f"{where}: orderings and order_prob must come together")
        elif "orderings" in g:
            n_ord = g["orderings"].shape[0] if g["orderings"].ndim == 2 else -1
            expect["orderings"] = ((n_ord, m), _RESULT_DTYPE["orderings"])
            expect["order_prob"] = ((t, n_ord), _RESULT_DTYPE["order_prob"])
        for key, (shape, dtype) in expect.items():
            ds = g[key]
            if ds.shape != shape:
                problems.append(f"{where}: {key} has shape {ds.shape}, expected {shape}")
            if ds.dtype != np.dtype(dtype):
                problems.append(f"{where}: {key} has dtype {ds.dtype}, expected {np.dtype(dtype)}")
        data, unreadable = _read_small(where, g, list(expect))
        problems += unreadable
        boxes = data.get("boxes")
        if boxes is not None and boxes.ndim == 3 and boxes.shape[-1] == 4:
            # The protocol: a row is a box (finite, w, h >= 0) or a lost target (all NaN).
            bad = bad_box_rows(boxes)
            if bad.any():
                problems.append(
                    f"{where}: boxes has rows that are neither finite with w, h >= 0 nor "
                    f"all NaN at frames {_frames(np.flatnonzero(bad.any(axis=1)).tolist())}"
                )
        ids = data.get("target_ids")
        if ids is not None and ids.ndim == 1 and (rep := repeated_ids(ids)):
            problems.append(f"{where}: {rep}")
        orderings = data.get("orderings")
        if (
            orderings is not None
            and orderings.size
            and (orderings.min() < 0 or orderings.max() >= m)
        ):
            problems.append(f"{where}: orderings name positions outside 0..{m - 1}")
        prob = data.get("order_prob")
        if prob is not None and (bad := bad_probabilities(prob)):
            problems.append(f"{where}: {bad}")
    return problems


# ---------------------------------------------------------------------------------------
# Digests (scenegen.io.integrity) and the deep check


def _named(problems: list[str], where: str, key: str) -> bool:
    """Whether a problem line of ``where`` already names ``key`` or a group holding it
    (then a digest mismatch of the same dataset is the same problem: not reported twice,
    and a dataset already found oversized is not read)."""
    parts = key.split("/")
    names = "|".join(re.escape("/".join(parts[:i])) for i in range(1, len(parts) + 1))
    return any(
        line.startswith(f"{where}: ") and re.search(rf"(^|[\s/])({names})(\s|\[|$)",
                                                     line[len(where) + 2 :])
        for line in problems
    )  # fmt: skip


def _values_digest(ds: h5py.Dataset) -> str:
    """SHA-256 of a dataset's stored values, read a chunk row at a time."""
    h = Hasher()
    if ds.shape == () or ds.size == 0:
        h.update(np.asarray(ds[()]))
        return h.hexdigest()
    step = ds.chunks[0] if ds.chunks else ds.shape[0]
    for start in range(0, ds.shape[0], step):
        beat()
        h.update(ds[start : start + step])
    return h.hexdigest()


def _check_digests(p: Path, f: h5py.File, check_pixels: bool, found: list[str]) -> list[str]:
    """Every dataset against its ``sha256``, every sealed group against ``attrs_sha256``.

    Files written before digests existed (no root ``integrity``) are checked only where a
    digest is present; files that declare ``integrity`` must carry all of them.
    """
    required = as_text(f.attrs.get(INTEGRITY, "")) == DIGEST
    sealed = any(ATTRS_DIGEST in obj.attrs for obj in _groups(f))
    if not required and sealed:
        return [f"{p}: the root attribute {INTEGRITY} is missing (the file carries digests)"]
    problems: list[str] = []
    groups = [(f"{p}", f, "root")] + [(where, g, "") for where, g in _groups_named(p, f)]
    for where, g, what in groups:
        if ATTRS_DIGEST in g.attrs:
            if as_text(g.attrs[ATTRS_DIGEST]) != attrs_digest(g.attrs) and not any(
                line.startswith(f"{where}: ") and "attribute" in line for line in found
            ):
                problems.append(
                    f"{where}: {what + ' ' if what else ''}attributes do not match their "
                    "digest (changed after writing)"
                )
        elif required:
            problems.append(f"{where}: missing attribute {ATTRS_DIGEST}")
    for where, g in _groups_named(p, f):
        if required and where.startswith(f"{p}: sequence "):  # written by this version
            problems += [f"{where}: missing dataset {key}" for key in sorted(_OPTIONAL)
                         if key not in g and not _named(found, where, key)]  # fmt: skip
        for key, ds in _datasets(g):
            beat()
            if _named(found, where, key):
                continue
            if DIGEST not in ds.attrs:
                if required:
                    problems.append(f"{where}: {key} has no digest ({DIGEST} attribute)")
                continue
            try:
                unchecked = required and ds.size > 0 and not ds.fletcher32
            except _READ_ERRORS as err:
                problems.append(f"{where}: {key} is unreadable ({describe_read_error(err)})")
                continue
            if unchecked:  # its damaged chunks would read as values, not fail
                problems.append(f"{where}: {key} is stored without the Fletcher-32 checksum")
            if key in ("frames", "labels") and not check_pixels:
                continue
            try:
                same = _values_digest(ds) == as_text(ds.attrs[DIGEST])
                attrs_same = (ATTRS_DIGEST not in ds.attrs and not required) or (
                    ATTRS_DIGEST in ds.attrs
                    and as_text(ds.attrs[ATTRS_DIGEST]) == attrs_digest(ds.attrs)
                )
            except _READ_ERRORS as err:
                problems.append(f"{where}: {key} is unreadable ({describe_read_error(err)})")
                continue
            if not same:
                problems.append(
                    f"{where}: {key} does not match its digest (values changed after writing)"
                )
            elif not attrs_same:
                problems.append(f"{where}: {key} attributes do not match their digest")
    return problems


def _datasets(g: h5py.Group) -> list[tuple[str, h5py.Dataset]]:
    out: list[tuple[str, h5py.Dataset]] = []

    def visit(key: str, obj: Any) -> None:
        if isinstance(obj, h5py.Dataset):
            out.append((key, obj))

    g.visititems(visit)
    return out


def _groups_named(p: Path, f: h5py.File) -> list[tuple[str, h5py.Group]]:
    out = []
    for top, label in (("sequences", "sequence"), ("results", "result")):
        if isinstance(f.get(top), h5py.Group):
            for name, g in f[top].items():
                if isinstance(g, h5py.Group):
                    out.append((f"{p}: {label} {name!r}", g))
    return out


def _groups(f: h5py.File) -> list[Any]:
    return [f] + [g for _, g in _groups_named(Path(""), f)]


def _rows_differ(stored: NDArray[Any], fresh: NDArray[Any]) -> NDArray[np.bool_]:
    """Per leading row: do the stored bytes differ from the re-rendered ones?"""
    fresh = np.asarray(fresh).astype(stored.dtype, copy=False)
    if stored.shape != fresh.shape:
        return np.ones(max(len(stored), 1), dtype=bool)
    n = stored.shape[0] if stored.ndim else 1
    if stored.size == 0:  # no entity (K = 0): nothing to differ
        return np.zeros(n, dtype=bool)
    a = np.ascontiguousarray(stored).reshape(n, -1).view(np.uint8)
    b = np.ascontiguousarray(fresh).reshape(n, -1).view(np.uint8)
    return (a != b).any(axis=1)


def _compare(
    g: h5py.Group, changed: dict[str, list[int]], key: str, fresh: Any, start: int | None = None
) -> None:
    """Record in ``changed`` whether ``g[key]`` (rows ``start:``, or all) differs from
    ``fresh``; an unreadable dataset is left to the other checks."""
    try:
        ds = g[key]
        stored = ds[()] if start is None else ds[start : start + len(fresh)]
    except _READ_ERRORS:
        return
    rows = np.flatnonzero(_rows_differ(stored, fresh))
    if rows.size:
        frames = [] if start is None else [start + int(r) for r in rows]
        changed.setdefault(key, []).extend(frames)


def _check_deep(p: Path, f: h5py.File) -> list[str]:
    """Re-render each sequence from its config and seed; one line per dataset whose
    values differ (naming the first frames where they do)."""
    from scenegen.io.hdf5 import frames_per_block
    from scenegen.render.plan import plan

    problems: list[str] = []
    for where, g in _groups_named(p, f):
        if not where.startswith(f"{p}: sequence "):
            continue
        try:
            cfg = from_stored(json.loads(as_text(g.attrs["config"])))
            scn = plan(cfg, int(g.attrs["seed"]), preset=as_text(g.attrs["preset"]))
        except (*_READ_ERRORS, ConfigError) as err:
            problems.append(
                f"{where}: cannot re-render (no usable config and seed: {_one_line(err)})"
            )
            continue
        changed: dict[str, list[int]] = {}  # dataset -> frames (empty: not per frame)

        for c in scn.chunks(frames_per_block(cfg.height, cfg.width)):
            beat()
            _compare(g, changed, "frames", c.frames, c.start)
            _compare(g, changed, "labels", c.labels, c.start)
            for key, values in c.gt.items():
                if f"gt/{key}" in g:
                    _compare(g, changed, f"gt/{key}", values, c.start)
        ents = scn.entities()
        _compare(g, changed, "entities/id", np.asarray(ents.id, np.int32))
        for key, values in (("entities/role", ents.role), ("entities/name", ents.name)):
            try:
                stored = [as_text(v) for v in g[key][()]]
            except _READ_ERRORS:
                continue
            if stored != [str(v) for v in values]:
                changed.setdefault(key, [])
        for eid, tpl in scn.template_images().items():
            if f"templates/{int(eid)}" in g:
                _compare(g, changed, f"templates/{int(eid)}", np.asarray(tpl, np.uint8))
        for key, frames in changed.items():
            at = f" at frames {_frames(sorted(set(frames)))}" if frames else ""
            problems.append(f"{where}: {key} differs from a re-render of its config and seed{at}")
    return problems
