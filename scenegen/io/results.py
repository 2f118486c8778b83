"""Tracker result files (schema ``scenegen/1``, ``/results/<tracker>/``; the layout is
:data:`scenegen.io.schema.RESULT_FIELDS`, described in ``docs/format.md``).

Written atomically like sequence files, with ``description`` and ``units`` on every
dataset; read through the same checks (:func:`scenegen.io.hdf5.open_checked`).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import h5py
import numpy as np
from numpy.typing import ArrayLike, NDArray

from scenegen.errors import ConfigError, DataError, NotInFile
from scenegen.io import guard
from scenegen.io.atomic import atomic_path
from scenegen.io.hdf5 import (
    _WRITE_OPTIONS,
    _dataset,
    _members,
    _seal,
    _write_header,
    describe_read_error,
    open_checked,
)
from scenegen.io.integrity import as_text, put_attrs_digest, put_text
from scenegen.io.schema import field

__all__ = ["TrackerResult", "read_result", "write_result"]


def bad_box_rows(boxes: NDArray[Any]) -> NDArray[np.bool_]:
    """Rows of ``boxes`` (..., 4) that break the protocol, shape (...): a row is a box,
    finite with w, h >= 0, or a lost target, all NaN."""
    b = np.asarray(boxes, dtype=np.float64)
    finite = np.isfinite(b).all(axis=-1)
    return ~(finite | np.isnan(b).all(axis=-1)) | (finite & (b[..., 2:] < 0).any(axis=-1))


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

    def problems(self) -> list[str]:
        """What keeps this result from being written: shapes that disagree (``boxes``
        (T, M, 4) with M distinct ``target_ids``; ``orderings`` (L, M) of positions 0..M-1 and
        ``order_prob`` (T, L), both or neither) and box rows that are neither finite with
        w, h >= 0 nor all NaN.
        Empty if none.

        Returns
        -------
        list of str
            One sentence per problem, also for a ``tracker`` that cannot name an HDF5
            group (not a string, empty, holding ``/``: :func:`scenegen.config.checks.
            _check_name`), a ``seed`` that is not an integer in [0, 2**64 - 1], target ids
            that are not integers within int32, repeated ``target_ids``, box values beyond
            float32 and ``order_prob`` values that are not probabilities in [0, 1]. A shape
            problem of ``target_ids``, ``boxes`` or ``orderings``, or ``orderings`` without
            ``order_prob`` (or the reverse), is the only one given (the later checks need
            those shapes).
        """
        out = _header_problems(self.tracker, self.seed)
        ids, boxes = np.asarray(self.target_ids), np.asarray(self.boxes)
        if ids.ndim != 1:
            return [f"target_ids has shape {ids.shape}, expected (M,)"]
        m = ids.shape[0]
        if boxes.ndim != 3 or boxes.shape[1:] != (m, 4):
            return [f"boxes has shape {boxes.shape}, expected (T, {m}, 4)"]
        if bad := _bad_ids(ids):
            out.append(bad)
        elif rep := repeated_ids(ids):
            out.append(rep)
        if bad_box_rows(boxes).any():
            out.append(
                "boxes has rows that are neither finite with w, h >= 0 nor all NaN "
                "(a lost target)"
            )
        elif boxes.size and np.nanmax(np.abs(boxes.astype(np.float64))) > _FLOAT32_MAX:
            out.append(f"boxes has values beyond float32's range (|value| > {_FLOAT32_MAX:.3g})")
        if (self.orderings is None) != (self.order_prob is None):
            return ["orderings and order_prob must come together"]
        if self.orderings is None:
            return out
        orderings, prob = np.asarray(self.orderings), np.asarray(self.order_prob)
        if orderings.ndim != 2 or orderings.shape[1] != m:
            return [f"orderings has shape {orderings.shape}, expected (L, {m})"]
        if orderings.size and (orderings.min() < 0 or orderings.max() >= m):
            out.append(f"orderings name positions outside 0..{m - 1}")
        if prob.shape != (boxes.shape[0], orderings.shape[0]):
            out.append(
                f"order_prob has shape {prob.shape}, expected "
                f"({boxes.shape[0]}, {orderings.shape[0]}) (T frames, L orderings)"
            )
        if bad := bad_probabilities(prob):
            out.append(bad)
        return out


_FLOAT32_MAX = float(np.finfo(np.float32).max)


def _header_problems(tracker: Any, seed: Any) -> list[str]:
    """The problems with a result's ``tracker`` name (it names the HDF5 group
    ``/results/<tracker>``: a ``/`` made nested groups that read back as damaged) and its
    ``seed`` (an integer in [0, 2**64 - 1], as ``--seed`` and sequence files take)."""
    from scenegen.config.checks import _check_name
    from scenegen.config.messages import _short

    out = []
    if not isinstance(tracker, str):
        out.append(f"tracker must be a string, got {_short(tracker)}")
    else:
        try:
            _check_name("tracker", tracker)
        except ConfigError as err:
            out.append(str(err))
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not (
            0 <= seed <= 2**64 - 1):  # fmt: skip
        out.append(f"seed must be an integer in [0, 2**64 - 1], got {_short(seed)}")
    return out


def _bad_ids(ids: NDArray[Any]) -> str:
    """The problem with target ids (M,) that are not integers within int32 ("" if none):
    they were cast to int32, so 7.6 was stored as 7 and 2**32 + 1 as 1."""
    info = np.iinfo(np.int32)
    try:
        num = ids.astype(np.float64)
    except (TypeError, ValueError):
        return f"target_ids must be integers, got {ids[:5].tolist()}"
    bad = ~np.isfinite(num) | (num != np.round(num)) | (num < info.min) | (num > info.max)
    if ids.dtype.kind in "iu":  # exact, whatever float64 rounds
        bad = (ids < info.min) | (ids > info.max)
    if ids.dtype.kind == "b" or bad.any():
        first = ids[bad][0].item() if bad.any() else ids[0].item()
        return f"target_ids must be integers within int32, got {first!r}"
    return ""


def bad_probabilities(prob: ArrayLike) -> str:
    """The problem with ``order_prob`` (T, L) whose values are not probabilities, finite
    and within [0, 1] ("" if none): a damaged or wrong result."""
    a = np.asarray(prob, dtype=np.float64)
    bad = ~((a >= 0.0) & (a <= 1.0))  # NaN fails both
    if not bad.any():
        return ""
    t = int(np.argwhere(bad)[0][0])
    return (f"order_prob holds values that are not probabilities in [0, 1] (first at frame "
            f"{t}: {a[bad][0]:g})")  # fmt: skip


def repeated_ids(
    ids: ArrayLike, name: str = "target_ids", why: str = "each target is tracked once"
) -> str:
    """The problem with ids (M,) that repeat one ("" if none does), naming the array
    ``name`` and saying ``why`` each id is there once: by default a result's
    ``target_ids``, where one id twice is a damaged or wrong result."""
    a = np.asarray(ids).reshape(-1)
    values, counts = np.unique(a, return_counts=True)
    if not (counts > 1).any():
        return ""
    return f"{name} repeat id {values[counts > 1][0].item()} ({why})"


def write_result(path: str | Path, *results: TrackerResult) -> None:
    """Write tracker results to a result file (atomically), one group per tracker.

    Parameters
    ----------
    path : str or Path
    *results : TrackerResult
        At least one; at most one per tracker name.

    Raises
    ------
    ConfigError
        No result, an argument that is not a :class:`TrackerResult`, two results of one
        tracker, a result whose shapes disagree (:meth:`TrackerResult.problems`, which
        also refuses a tracker name that cannot name a group, a seed outside [0, 2**64 -
        1], target ids that are not int32 integers or repeat, box rows neither finite
        with w, h >= 0 nor all NaN, and ``order_prob`` values outside [0, 1]), or a
        missing folder.
    """
    if not results:
        raise ConfigError("write_result needs at least one result")
    for r in results:
        if not isinstance(r, TrackerResult):
            raise ConfigError(f"write_result takes TrackerResult objects, got a {type(r).__name__}")
        if bad := r.problems():
            raise ConfigError(f"result of tracker {r.tracker!r}: {bad[0]}")
    with atomic_path(path) as tmp, h5py.File(tmp, "w", **_WRITE_OPTIONS) as f:
        _write_header(f)
        root = f.create_group("results")
        for r in results:
            if r.tracker in root:
                raise ConfigError(f"two results for tracker {r.tracker!r} in one file")
            g = root.create_group(r.tracker)
            put_text(g, "tracker", r.tracker)
            put_text(g, "params", json.dumps(r.params, sort_keys=True, default=str))
            g.attrs["seed"] = int(r.seed)
            put_text(g, "sequence", r.sequence)
            put_attrs_digest(g)
            arrays = {"target_ids": r.target_ids, "boxes": r.boxes}
            if r.orderings is not None and r.order_prob is not None:
                arrays |= {"orderings": r.orderings, "order_prob": r.order_prob}
            for key, arr in arrays.items():
                spec = field(f"results/{key}")
                _dataset(g, spec, name=key, data=np.asarray(arr, dtype=spec.dtype))
        _seal(f)
    guard.trust(path)


def read_result(path: str | Path, tracker: str | None = None) -> TrackerResult:
    """Read one tracker's result (the only one if ``tracker`` is None).

    Parameters
    ----------
    path : str or Path
    tracker : str, optional
        The tracker's name; default: the only result in the file.

    Returns
    -------
    TrackerResult

    Raises
    ------
    DataError
        If the file is not a result file, is damaged, or has no (or several, unnamed)
        results.
    """
    p = Path(path)
    with open_checked(p) as f:
        names = _members(p, f, "results")
        if not names:
            raise DataError(f"{p}: holds no tracker results")
        if tracker is None:
            if len(names) > 1:
                raise NotInFile(f"{p}: holds results of {', '.join(names)}; name one")
            tracker = names[0]
        if tracker not in names:
            raise NotInFile(f"{p}: no result for tracker {tracker!r}; it holds "
                            f"{', '.join(names)}")  # fmt: skip
        try:
            g = f[f"results/{tracker}"]
            return TrackerResult(
                tracker=as_text(g.attrs["tracker"]),
                params=json.loads(g.attrs["params"]),
                seed=int(g.attrs["seed"]),
                sequence=as_text(g.attrs["sequence"]),
                target_ids=g["target_ids"][()].astype(np.int32),
                boxes=g["boxes"][()].astype(np.float32),
                orderings=g["orderings"][()] if "orderings" in g else None,
                order_prob=g["order_prob"][()] if "order_prob" in g else None,
            )
        except (KeyError, ValueError, TypeError, OSError, RuntimeError) as err:
            raise DataError(
                f"{p}: result {tracker!r} is damaged: {describe_read_error(err)}"
            ) from None
