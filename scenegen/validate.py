"""Checks of a scenegen HDF5 file against schema ``scenegen/1``.

:func:`check_file` returns one line per problem (empty when the file is valid): wrong or
missing schema, missing datasets, shape or dtype mismatches, labels naming unknown ids,
visible boxes or visibilities that disagree with the labels, NaN patterns that disagree
with ``present``, truncated or corrupted data. It streams frames one at a time, so memory
stays bounded whatever the file's length.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import h5py
import numpy as np
from scipy import ndimage

from scenegen.config import from_dict
from scenegen.errors import ConfigError
from scenegen.io import SCHEMA
from scenegen.sequence import GT_FIELDS

__all__ = ["check_file"]

_MAX_PER_KIND = 5  # report at most this many frames per kind of disagreement


def _expected_shapes(t: int, h: int, w: int, k: int) -> dict[str, tuple[tuple[int, ...], Any]]:
    return {
        "frames": ((t, h, w, 3), np.uint8),
        "labels": ((t, h, w), np.uint16),
        "entities/id": ((k,), np.int32),
        "gt/box": ((t, k, 4), np.float32),
        "gt/visible_box": ((t, k, 4), np.float32),
        "gt/center": ((t, k, 2), np.float32),
        "gt/visibility": ((t, k), np.float32),
        "gt/present": ((t, k), np.bool_),
        "gt/depth": ((t, k), np.int16),
    }


def check_file(path: str | Path, *, check_pixels: bool = True) -> list[str]:
    """Validate a scenegen file; return one line per problem found.

    Parameters
    ----------
    path : str or Path
    check_pixels : bool
        Also re-derive visible boxes and visibility from ``labels`` frame by frame.
    """
    p = Path(path)
    if not p.exists():
        return [f"{p}: no such file"]
    try:
        f = h5py.File(p, "r")
    except OSError:
        return [f"{p}: not an HDF5 file (or truncated/corrupted)"]
    with f:
        schema = f.attrs.get("schema")
        if isinstance(schema, bytes):
            schema = schema.decode()
        if schema is None:
            return [f"{p}: missing schema attribute (expected {SCHEMA!r})"]
        if schema != SCHEMA:
            return [f"{p}: schema is {schema!r}, expected {SCHEMA!r}"]
        if "sequences" in f:
            problems: list[str] = []
            names = list(f["sequences"].keys())
            if not names:
                problems.append(f"{p}: /sequences holds no sequence")
            for name in names:
                try:
                    problems += _check_sequence(p, name, f[f"sequences/{name}"], check_pixels)
                except (OSError, RuntimeError, KeyError, ValueError) as err:
                    problems.append(f"{p}: sequence {name!r}: unreadable data ({_one_line(err)})")
            return problems
        if "results" in f:
            return _check_results(p, f["results"])
        return [f"{p}: holds neither /sequences nor /results"]


def _one_line(err: BaseException) -> str:
    text = str(err).strip().splitlines()
    return text[0] if text else type(err).__name__


def _check_results(p: Path, root: h5py.Group) -> list[str]:
    problems = []
    for name, g in root.items():
        where = f"{p}: results/{name}"
        for key in ("target_ids", "boxes"):
            if key not in g:
                problems.append(f"{where}: missing dataset {key}")
        if problems:
            continue
        m = g["target_ids"].shape[0]
        if g["boxes"].ndim != 3 or g["boxes"].shape[1:] != (m, 4):
            problems.append(f"{where}/boxes: shape {g['boxes'].shape}, expected (T, {m}, 4)")
        if ("orderings" in g) != ("order_prob" in g):
            problems.append(f"{where}: orderings and order_prob must come together")
    return problems


def _check_sequence(p: Path, name: str, g: h5py.Group, check_pixels: bool) -> list[str]:
    where = f"{p}: sequence {name!r}"
    problems: list[str] = []
    for attr in ("seed", "config", "preset", "n_frames", "height", "width"):
        if attr not in g.attrs:
            problems.append(f"{where}: missing attribute {attr}")
    if problems:
        return problems
    try:
        from_dict(json.loads(g.attrs["config"]))
    except (ValueError, ConfigError) as err:
        problems.append(f"{where}: attribute config is not a valid config: {_one_line(err)}")
    t, h, w = int(g.attrs["n_frames"]), int(g.attrs["height"]), int(g.attrs["width"])
    if "entities/id" not in g:
        return [*problems, f"{where}: missing dataset entities/id"]
    k = int(g["entities/id"].shape[0])
    for key, (shape, dtype) in _expected_shapes(t, h, w, k).items():
        if key not in g:
            problems.append(f"{where}: missing dataset {key}")
            continue
        ds = g[key]
        if not isinstance(ds, h5py.Dataset):
            problems.append(f"{where}: {key} is not a dataset")
            continue
        if ds.shape != shape:
            problems.append(f"{where}: {key} has shape {ds.shape}, expected {shape}")
        if ds.dtype != np.dtype(dtype):
            problems.append(f"{where}: {key} has dtype {ds.dtype}, expected {np.dtype(dtype)}")
    for key in ("entities/role", "entities/name"):
        if key not in g:
            problems.append(f"{where}: missing dataset {key}")
        elif g[key].shape != (k,):
            problems.append(f"{where}: {key} has shape {g[key].shape}, expected ({k},)")
    if "templates" not in g:
        problems.append(f"{where}: missing group templates")
    if problems:
        return problems

    ids = g["entities/id"][()]
    if np.any(ids < 1) or len(np.unique(ids)) != k:
        problems.append(f"{where}: entities/id must be unique and >= 1, got {ids.tolist()[:10]}")
        return problems
    roles = {r.decode() if isinstance(r, bytes) else str(r) for r in g["entities/role"][()]}
    bad_roles = roles - {"target", "distractor", "occluder", "clutter"}
    if bad_roles:
        problems.append(f"{where}: entities/role has unknown roles {sorted(bad_roles)}")
    gt = {key: g[f"gt/{key}"][()] for key in GT_FIELDS}
    present = gt["present"].astype(bool)
    for key in ("box", "center"):
        nan = np.isnan(gt[key]).any(axis=-1)
        bad = np.flatnonzero((nan == present).any(axis=1))
        if bad.size:
            problems.append(
                f"{where}: gt/{key} NaN pattern disagrees with gt/present at frames {_frames(bad)}"
            )
    bad = np.flatnonzero(((gt["visibility"] != 0) & ~present).any(axis=1))
    if bad.size:
        problems.append(f"{where}: gt/visibility is nonzero where absent at frames {_frames(bad)}")
    if np.any((gt["visibility"] < 0) | (gt["visibility"] > 1 + 1e-6)):
        problems.append(f"{where}: gt/visibility has values outside [0, 1]")
    if check_pixels:
        problems += _check_labels(where, g, ids, gt)
    return problems


def _frames(idx: np.ndarray) -> str:
    shown = ", ".join(str(int(i)) for i in idx[:_MAX_PER_KIND])
    return shown + (f" (+{idx.size - _MAX_PER_KIND} more)" if idx.size > _MAX_PER_KIND else "")


def _check_labels(where: str, g: h5py.Group, ids: np.ndarray, gt: dict[str, Any]) -> list[str]:
    labels = g["labels"]
    t_n = labels.shape[0]
    max_id = int(ids.max()) if ids.size else 0
    # id -> entity index; ids need not be 1..K in order.
    lut = np.full(max_id + 1, -1, dtype=np.int64)
    lut[ids] = np.arange(ids.size)
    unknown, box_bad, vis_bad = [], [], []
    vbox, vis, present = gt["visible_box"], gt["visibility"], gt["present"]
    for t in range(t_n):
        lab = labels[t]
        top = int(lab.max()) if lab.size else 0
        counts = np.bincount(lab.ravel(), minlength=max_id + 1)
        if top > max_id or np.any((counts[1:] > 0) & (lut[1:] < 0)):
            unknown.append(t)
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
        if np.any(seen & ~present[t]) or np.any((vis[t] > 0) != seen):
            vis_bad.append(t)
    out = []
    if unknown:
        out.append(
            f"{where}: labels name ids not in entities/id at frames {_frames(np.array(unknown))}"
        )
    if box_bad:
        out.append(
            f"{where}: gt/visible_box disagrees with labels at frames {_frames(np.array(box_bad))}"
        )
    if vis_bad:
        out.append(
            f"{where}: gt/visibility or gt/present disagree with labels at frames "
            f"{_frames(np.array(vis_bad))}"
        )
    return out
