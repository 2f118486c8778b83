"""Evaluate a tracker result against a sequence's ground truth.

:func:`evaluate` scores a scenegen result (boxes of shape (T, M, 4) for given target ids);
:func:`evaluate_tracks` scores any tracks (e.g. read from a MOTChallenge tracker file),
pairing each target with a track; :func:`evaluate_target` scores a single-object
tracker's boxes (T, 4) for one target (an OTB or GOT-10k result file). All return a typed
:class:`~scenegen.evaluation.report.SequenceReport` (per target and overall);
:func:`format_table` renders it for a terminal and :func:`to_json` as one JSON document.
A result that does not fit its sequence raises :class:`~scenegen.errors.DataError` naming
the mismatch.

Which ground truth counts (``gt_mode``): ``"amodal"`` (default) scores every frame where a
target is in the scene, with its amodal box; ``"visible"`` follows MOTChallenge and ignores
a target in frames where its visible fraction is at most ``visibility_threshold`` (and
drops tracker boxes matched to a distractor). The MOT export writes the same convention,
so TrackEval on the exported files gives the numbers of ``evaluate`` (see
:mod:`scenegen.io.mot`). CLEAR MOT, identity and HOTA are scored over every target of the
sequence (what the MOT ground-truth export holds), single-target scores per target row.

Examples
--------
>>> seq = scenegen.generate("kams-a", seed=0)                     # doctest: +SKIP
>>> report = evaluate(seq, boxes, seq.target_ids(), tracker="kams")  # doctest: +SKIP
>>> print(format_table(report))                                   # doctest: +SKIP
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import linear_sum_assignment

from scenegen.errors import ConfigError, DataError
from scenegen.evaluation import metrics
from scenegen.evaluation.mot import (
    box_iou,
    mot_frames,
    remove_distractor_matches,
    score_all,
)
from scenegen.evaluation.report import (
    MotSummary,
    OverallScores,
    SequenceReport,
    TargetScores,
    format_table,
)
from scenegen.io.mot import check_gt_mode, gt_keep
from scenegen.io.results import bad_box_rows, repeated_ids

__all__ = [
    "DEFAULT_RECOVER_FRAMES",
    "GT_MODES",
    "OTB_AVERAGES",
    "check_options",
    "SequenceReport",
    "TargetScores",
    "evaluate",
    "evaluate_target",
    "evaluate_tracks",
    "failure_threshold",
    "format_table",
    "frame_measures",
    "pick_target",
    "to_json",
]

DEFAULT_RECOVER_FRAMES = 5
"""Final frames that must all be tracked for a run to count as recovered."""

GT_MODES = ("amodal", "visible")
"""Ground-truth conventions: amodal boxes in every frame, or MOTChallenge's visible ones."""

OTB_AVERAGES = ("sequence", "frames")
"""Overall OTB AUC / P@20: mean over targets (as OTB averages sequences), or pooled frames."""

_MOT_ROLES = ("target", "distractor", "occluder")


def frame_measures(est: ArrayLike, gt: ArrayLike) -> dict[str, NDArray[Any]]:
    """Per-frame measures of estimates against ground truth, each of shape (T, M).

    Parameters
    ----------
    est, gt : array_like of shape (T, M, 4)
        Estimated and ground-truth boxes (NaN where absent).

    Returns
    -------
    dict
        ``state`` (bool, DPS track state), ``precision`` and ``recall`` (fractions),
        ``iou``, ``centre_error`` (pixels); NaN where undefined.
    """
    p, r = metrics.precision_recall(est, gt)
    return {
        "state": metrics.track_state(est, gt),
        "precision": p,
        "recall": r,
        "iou": metrics.iou(est, gt),
        "centre_error": metrics.centre_error(est, gt),
    }


def failure_threshold(gt: ArrayLike, *, fraction: float = 1.0) -> NDArray[np.float64]:
    """Centre error beyond which a target counts as lost, per target.

    (open) KAMS says a run fails when the error stays above a threshold, "e.g. the target
    radius", yet reports mean errors of 15–18 px for runs that track throughout. We take
    ``fraction`` times the target's size (the mean of its ground-truth box width and
    height over the frames where it is present); with the default 1.0 that is the
    diameter of a disc target: beyond it, estimate and target no longer overlap.

    Parameters
    ----------
    gt : array_like of shape (T, M, 4)
    fraction : float
        Multiple of the target size (> 0); 0.5 gives the radius.

    Returns
    -------
    ndarray of shape (M,)
        Threshold in pixels (NaN for a target never present).

    Raises
    ------
    ValueError
        If ``fraction`` is not > 0.
    """
    if not fraction > 0:
        raise ValueError(f"fraction must be > 0, got {fraction}")
    g = np.asarray(gt, dtype=np.float64)
    size = fraction * (g[..., 2] + g[..., 3]) / 2.0
    finite = np.isfinite(size)
    n = finite.sum(axis=0)
    s = np.where(finite, size, 0.0).sum(axis=0)
    return np.where(n > 0, s / np.maximum(n, 1), np.nan)


def _mean(x: NDArray[Any]) -> float | None:
    return float(np.mean(x)) if x.size else None


def _finite(x: float) -> float | None:
    return float(x) if np.isfinite(x) else None


def check_options(
    gt_mode: str,
    visibility_threshold: float,
    otb_average: str,
    iou_threshold: float = 0.5,
    *,
    recover_frames: int = DEFAULT_RECOVER_FRAMES,
    persist: int = 10,
) -> None:
    """Raise ConfigError naming an unknown ``gt_mode`` / ``otb_average``, a bad threshold
    (:func:`scenegen.io.mot.check_gt_mode`: one definition with the exports) or a bad
    frame count.

    Parameters
    ----------
    gt_mode : str
        Ground-truth convention, one of :data:`GT_MODES`.
    visibility_threshold : float
        Visible fraction above which a target counts, in [0, 1); 0 in ``"amodal"`` mode.
    otb_average : str
        Overall OTB average, one of :data:`OTB_AVERAGES`.
    iou_threshold : float
        IoU of a match, in (0, 1].
    recover_frames : int
        Final frames that must be tracked for ``recovered``, an integer >= 1.
    persist : int
        Frames the error must stay above the threshold for a failure, an integer >= 1.

    Raises
    ------
    ConfigError
        If ``iou_threshold`` is not in (0, 1], ``gt_mode`` or ``otb_average`` is unknown,
        ``visibility_threshold`` is not in [0, 1), or it is not 0 with ``gt_mode``
        ``"amodal"``, or ``recover_frames`` or ``persist`` is not an integer >= 1.
    """
    if not 0.0 < iou_threshold <= 1.0:
        raise ConfigError(f"iou_threshold must be in (0, 1], got {iou_threshold}")
    for name, value in (("recover_frames", recover_frames), ("persist", persist)):
        try:
            metrics._count(value, name)
        except ValueError as err:
            raise ConfigError(str(err)) from None
    check_gt_mode(gt_mode, visibility_threshold)
    if otb_average not in OTB_AVERAGES:
        raise ConfigError(
            f"otb_average must be one of {', '.join(OTB_AVERAGES)}; got {otb_average!r}"
        )


def evaluate(
    sequence: Any,
    boxes: ArrayLike,
    target_ids: ArrayLike,
    *,
    tracker: str = "",
    order_prob: ArrayLike | None = None,
    orderings: ArrayLike | None = None,
    recover_frames: int = DEFAULT_RECOVER_FRAMES,
    persist: int = 10,
    iou_threshold: float = 0.5,
    gt_mode: str = "amodal",
    visibility_threshold: float = 0.0,
    otb_average: str = "sequence",
) -> SequenceReport:
    """Scores of one scenegen tracker result on one sequence.

    Parameters
    ----------
    sequence : scenegen.Sequence
        The sequence tracked (its ``gt``, ``entities`` are used).
    boxes : array_like of shape (T, M, 4)
        Estimated boxes per frame and target.
    target_ids : array_like of int, shape (M,)
        Entity ids tracked, in the order of ``boxes``' second axis (column m is the track
        of target ``target_ids[m]``).
    tracker : str
        Tracker name, for the report.
    order_prob : array_like of shape (T, L), optional
        SHM trackers: P(ordering) per frame; with ``orderings`` adds depth-order accuracy.
    orderings : array_like of int, shape (L, M), optional
        SHM trackers: target positions per ordering, nearest first.
    recover_frames : int
        Final frames that must be tracked for ``recovered`` (see
        :func:`scenegen.evaluation.metrics.recovery_rate`).
    persist : int
        Frames the centre error must stay above the threshold for a failure (see
        :func:`scenegen.evaluation.metrics.failure_frame`).
    iou_threshold : float
        IoU of a match for CLEAR MOT and IDF1.
    gt_mode : {"amodal", "visible"}
        Which ground truth counts (module docstring).
    visibility_threshold : float
        ``visible`` mode: a target counts where its visible fraction exceeds this, in [0, 1).
    otb_average : {"sequence", "frames"}
        Overall OTB AUC and P@20: mean of the per-target values, or pooled frames.

    Returns
    -------
    SequenceReport
        One row per target of ``target_ids``.

    Raises
    ------
    DataError
        If ``boxes`` is not of shape (T, M, 4) for the M ids of ``target_ids``, the
        result's frame count differs from the sequence's, its target count differs
        from the number of targets present at frame 0 (those ``scenegen track`` follows),
        a target id is not one of those targets, is repeated or is not an integer, a box
        row is neither a box (finite, w, h >= 0) nor all NaN, or ``order_prob`` and
        ``orderings`` do not fit the frames and targets.
    ConfigError
        If an option is out of range.
    """
    check_options(gt_mode, visibility_threshold, otb_average, iou_threshold,
                  recover_frames=recover_frames, persist=persist)  # fmt: skip
    est = np.asarray(boxes, dtype=np.float64)
    ids = _int_ids(target_ids, "target_ids")
    name = str(getattr(sequence, "name", ""))
    t_n = int(np.asarray(sequence.gt.box).shape[0])
    if est.ndim != 3 or est.shape[2] != 4:
        raise DataError(f"result boxes must have shape (T, M, 4), got {est.shape}")
    _check_boxes(est, "result boxes")
    if est.shape[0] != t_n:
        raise DataError(f"result has {est.shape[0]} frames but sequence {name!r} has {t_n} frames")
    if est.shape[1] != ids.shape[0]:
        raise DataError(
            f"result boxes hold {est.shape[1]} targets but target_ids lists {ids.shape[0]}"
        )
    target_idx = np.asarray(sequence.target_indices())
    tracked = target_idx[np.asarray(sequence.gt.present)[0, target_idx]]
    if ids.shape[0] != tracked.shape[0]:
        raise DataError(
            f"result tracks {ids.shape[0]} targets but sequence {name!r} has "
            f"{tracked.shape[0]} targets present at frame 0"
        )
    entity_ids = np.asarray(sequence.entities.id).astype(np.int64)
    target_ids_seq = entity_ids[tracked]
    if rep := repeated_ids(ids):
        raise DataError(f"result {rep}")
    rows = []
    for i in ids:
        hit = np.flatnonzero(entity_ids == i)
        if hit.size == 0 or int(i) not in target_ids_seq:
            raise DataError(
                f"result target id {int(i)} is not a target of sequence {name!r} "
                f"(target ids: {', '.join(str(int(x)) for x in target_ids_seq)})"
            )
        rows.append(int(hit[0]))
    report = _report(
        sequence, est, ids, rows, list(range(len(rows))), tracker=tracker,
        recover_frames=recover_frames, persist=persist, iou_threshold=iou_threshold,
        gt_mode=gt_mode, visibility_threshold=visibility_threshold, otb_average=otb_average,
        rank=None,
    )  # fmt: skip
    if order_prob is None or orderings is None:
        return report
    prob = np.asarray(order_prob, dtype=np.float64)
    orders = np.asarray(orderings)
    if prob.shape[0] != t_n or orders.ndim != 2 or orders.shape[1] != ids.shape[0]:
        raise DataError(
            f"order_prob {prob.shape} / orderings {orders.shape} do not fit {t_n} frames "
            f"and {ids.shape[0]} targets"
        )
    depth = np.asarray(sequence.gt.depth)[:, rows]
    gt = np.asarray(sequence.gt.box, dtype=np.float64)[:, rows]
    acc = _finite(metrics.depth_order_accuracy(prob, orders, depth, gt))
    return replace(report, overall=replace(report.overall, depth_order_accuracy=acc))


def pick_target(sequence: Any, target_id: int | None = None, option: str = "target_id") -> int:
    """The entity id of the target a single-object result follows.

    Parameters
    ----------
    sequence : scenegen.Sequence
    target_id : int, optional
        The target's entity id; it must be a target present at frame 0 (where a
        single-object tracker is started). Default: the only such target.
    option : str
        How the caller names ``target_id`` in messages (``"--target"`` on the command line).

    Returns
    -------
    int

    Raises
    ------
    ConfigError
        If ``target_id`` is not an integer (a bool is not one) or not a target present at
        frame 0, or it is None and several targets are, naming them.
    DataError
        If no target is present at frame 0.
    """
    if target_id is not None and (
            isinstance(target_id, (bool, np.bool_))
            or not isinstance(target_id, (int, np.integer))):  # fmt: skip
        raise ConfigError(f"{option} must be an integer entity id, got {target_id!r}")
    idx = np.asarray(sequence.target_indices())
    idx = idx[np.asarray(sequence.gt.present)[0, idx]]
    ids = [int(i) for i in np.asarray(sequence.entities.id)[idx]]
    name = str(getattr(sequence, "name", ""))
    listed = ", ".join(str(i) for i in ids)
    if not ids:
        raise DataError(f"sequence {name!r} has no target present at frame 0")
    if target_id is None:
        if len(ids) > 1:
            raise ConfigError(
                f"sequence {name!r} has {len(ids)} targets present at frame 0 (ids {listed}): "
                f"choose the one the result follows with {option}"
            )
        return ids[0]
    if target_id not in ids:
        raise ConfigError(
            f"{option} {target_id} is not a target present at frame 0 of sequence {name!r}, "
            f"where a single-object tracker starts (ids {listed})"
        )
    return int(target_id)


def evaluate_target(
    sequence: Any,
    boxes: ArrayLike,
    target_id: int | None = None,
    *,
    tracker: str = "",
    recover_frames: int = DEFAULT_RECOVER_FRAMES,
    persist: int = 10,
    iou_threshold: float = 0.5,
    gt_mode: str = "amodal",
    visibility_threshold: float = 0.0,
    otb_average: str = "sequence",
) -> SequenceReport:
    """Scores of a single-object tracker's boxes for one target (an OTB or GOT-10k result).

    The sequence is scored as the single-object exports see it, with that target alone:
    the report has its row, and the overall row (CLEAR MOT, IDF1 and HOTA too) covers
    that target only. On a sequence with one target present at frame 0 this is
    :func:`evaluate` of ``boxes[:, None]`` for that target; with several, the target's
    row is the one :func:`evaluate` gives it in a result holding every target (in
    ``gt_mode`` "visible" a box is dropped when matched to a distractor, here against
    this one track).

    Parameters
    ----------
    sequence : scenegen.Sequence
    boxes : array_like of shape (T, 4)
        The tracker's box per frame (NaN rows where it has none), in scenegen's 0-based
        pixels (:func:`scenegen.io.benchmarks.read_benchmark_result`).
    target_id : int, optional
        The entity id of the target followed (:func:`pick_target`: a target present at
        frame 0; default the only one).
    tracker : str
        Tracker name, for the report.
    recover_frames, persist : int
        As in :func:`evaluate`.
    iou_threshold, visibility_threshold : float
        As in :func:`evaluate`.
    gt_mode : {"amodal", "visible"}
        As in :func:`evaluate`.
    otb_average : {"sequence", "frames"}
        As in :func:`evaluate`.

    Returns
    -------
    SequenceReport
        One row, for the target.

    Raises
    ------
    DataError
        If ``boxes`` is not of shape (T, 4), the frame count differs from the sequence's,
        a box row is neither a box (finite, w, h >= 0) nor all NaN, or no target is
        present at frame 0.
    ConfigError
        If an option is out of range, or ``target_id`` is not an integer (a bool is not
        one) or not a target present at frame 0 (:func:`pick_target`).

    Examples
    --------
    >>> boxes = read_benchmark_result("otb.txt", seq.n_frames, "otb")  # doctest: +SKIP
    >>> print(format_table(evaluate_target(seq, boxes, 1)))            # doctest: +SKIP
    """
    check_options(gt_mode, visibility_threshold, otb_average, iou_threshold,
                  recover_frames=recover_frames, persist=persist)  # fmt: skip
    est = np.asarray(boxes, dtype=np.float64)
    name = str(getattr(sequence, "name", ""))
    t_n = int(np.asarray(sequence.gt.box).shape[0])
    if est.ndim != 2 or est.shape[1] != 4:
        raise DataError(f"single-object boxes must have shape (T, 4), got {est.shape}")
    if est.shape[0] != t_n:
        raise DataError(f"result has {est.shape[0]} frames but sequence {name!r} has {t_n} frames")
    _check_boxes(est[:, None], "result boxes")
    ident = pick_target(sequence, target_id)
    k = int(np.flatnonzero(np.asarray(sequence.entities.id).astype(np.int64) == ident)[0])
    return _report(
        sequence, est[:, None], np.array([ident], dtype=np.int64), [k], [0], tracker=tracker,
        recover_frames=recover_frames, persist=persist, iou_threshold=iou_threshold,
        gt_mode=gt_mode, visibility_threshold=visibility_threshold, otb_average=otb_average,
        rank=None, mot_rows=[k],
    )  # fmt: skip


def _sequence_frame(index: int, scored: NDArray[np.bool_]) -> int:
    """The sequence frame of the ``index``-th scored frame (``scored`` (T,)); -1 stays."""
    return int(np.flatnonzero(scored)[index]) if index >= 0 else -1


def _pair_tracks(
    gt: NDArray[np.float64], est: NDArray[np.float64], gt_ids: NDArray[np.int64],
    track_ids: NDArray[np.int64], iou_threshold: float,
) -> list[int]:  # fmt: skip
    """Track column paired with each target column (-1 for none).

    A target pairs with the track of the same id; the others with the track the identity
    (IDF1) matching assigns them among the remaining tracks, if they share a matched frame.
    """
    pair = [-1] * gt.shape[1]
    by_id = {int(i): c for c, i in enumerate(track_ids)}
    for m, i in enumerate(gt_ids):
        pair[m] = by_id.get(int(i), -1)
    free_g = [m for m in range(gt.shape[1]) if pair[m] < 0]
    free_e = [c for c in range(est.shape[1]) if c not in set(pair)]
    if not free_g or not free_e:
        return pair
    count = np.zeros((len(free_g), len(free_e)))
    for t in range(gt.shape[0]):
        g, e = gt[t, free_g], est[t, free_e]
        ok = np.all(np.isfinite(g), axis=-1)[:, None] & np.all(np.isfinite(e), axis=-1)[None]
        if ok.any():
            sim = box_iou(np.nan_to_num(g), np.nan_to_num(e))
            count += ok & (sim >= iou_threshold)
    r, c = linear_sum_assignment(-count)
    for a, b in zip(r, c, strict=True):
        if count[a, b] > 0:
            pair[free_g[a]] = free_e[b]
    return pair


def _int_ids(values: ArrayLike, name: str) -> NDArray[np.int64]:
    """``values`` as int64 ids, shape (N,); a fractional or non-finite id is a DataError
    (it was truncated: 7.6 scored as track 7)."""
    raw = np.asarray(values).reshape(-1)
    if raw.dtype.kind == "b":  # True was scored as id 1
        raise DataError(f"{name} must be integers, got booleans {raw[:5].tolist()}")
    if raw.dtype.kind not in "iu":
        try:
            num = raw.astype(np.float64)
        except (TypeError, ValueError):
            raise DataError(f"{name} must be integers, got {raw[:5].tolist()}") from None
        bad = ~np.isfinite(num) | (num != np.round(num)) | (np.abs(num) >= 2.0**63)
        if bad.any():
            raise DataError(f"{name} must be integers, got {num[bad][0]!r}")
        return num.astype(np.int64)
    return raw.astype(np.int64)


def _check_boxes(est: NDArray[np.float64], what: str) -> None:
    """Refuse rows that are neither a box (finite, w, h >= 0) nor all NaN, as the result
    and tracker-file readers do (:func:`scenegen.io.results.bad_box_rows`)."""
    bad = np.argwhere(bad_box_rows(est))
    if bad.size:
        t, m = (int(v) for v in bad[0])
        raise DataError(
            f"{what} at frame {t}, column {m}: {est[t, m].tolist()} is neither a box "
            "(finite, width and height >= 0) nor all NaN"
        )


def evaluate_tracks(
    sequence: Any,
    boxes: ArrayLike,
    track_ids: ArrayLike,
    *,
    tracker: str = "",
    recover_frames: int = DEFAULT_RECOVER_FRAMES,
    persist: int = 10,
    iou_threshold: float = 0.5,
    gt_mode: str = "amodal",
    visibility_threshold: float = 0.0,
    otb_average: str = "sequence",
    rank: ArrayLike | None = None,
) -> SequenceReport:
    """Scores of any tracks (e.g. a MOTChallenge tracker file) on one sequence.

    Parameters
    ----------
    sequence : scenegen.Sequence
    boxes : array_like of shape (T, H, 4)
        Track boxes per frame (NaN where a track has none).
    track_ids : array_like of int, shape (H,)
        Track ids. A target is paired with the track of its own entity id (scenegen's
        exports use those), else with the track the identity matching assigns it.
    tracker : str
        Tracker name, for the report.
    recover_frames, persist : int
        As in :func:`evaluate`.
    iou_threshold, visibility_threshold : float
        As in :func:`evaluate`.
    gt_mode : {"amodal", "visible"}
        As in :func:`evaluate`.
    otb_average : {"sequence", "frames"}
        As in :func:`evaluate`.
    rank : array_like of int, shape (T, H), optional
        Order of each frame's boxes in the tracker file
        (:func:`scenegen.io.mot.read_mot_tracker_rows`): TrackEval's matchings take a
        frame's boxes in file order, which breaks their ties. Default: column order.

    Returns
    -------
    SequenceReport
        One row per target of the sequence that is in the scene in some frame.

    Raises
    ------
    DataError
        If ``boxes`` is not of shape (T, H, 4) for the H ids of ``track_ids``, the frame
        count differs from the sequence's, ``rank`` is not of shape (T, H), ``track_ids``
        repeat an id or hold one that is not an integer, or a box row is neither a box
        (finite, w, h >= 0) nor all NaN (as the tracker-file reader refuses).
    ConfigError
        If an option is out of range.
    """
    check_options(gt_mode, visibility_threshold, otb_average, iou_threshold,
                  recover_frames=recover_frames, persist=persist)  # fmt: skip
    est = np.asarray(boxes, dtype=np.float64)
    ids = _int_ids(track_ids, "track_ids")
    name = str(getattr(sequence, "name", ""))
    t_n = int(np.asarray(sequence.gt.box).shape[0])
    if est.ndim != 3 or est.shape[2] != 4 or est.shape[1] != ids.shape[0]:
        raise DataError(f"track boxes must have shape (T, {ids.shape[0]}, 4), got {est.shape}")
    _check_boxes(est, "track boxes")
    if est.shape[0] != t_n:
        raise DataError(f"tracks span {est.shape[0]} frames but sequence {name!r} has {t_n}")
    if rank is not None and np.shape(rank) != est.shape[:2]:
        raise DataError(f"rank must have shape {est.shape[:2]}, got {np.shape(rank)}")
    # One column per track, as a tracker file has one id per track: two columns of one id
    # would be scored as two tracks (and paired with two targets) where TrackEval sees one.
    if rep := repeated_ids(ids, "track_ids", "one column per track: merge its boxes"):
        raise DataError(rep)
    idx = np.asarray(sequence.target_indices())
    idx = idx[np.asarray(sequence.gt.present)[:, idx].any(axis=0)]
    return _report(
        sequence, est, ids, [int(k) for k in idx], None, tracker=tracker,
        recover_frames=recover_frames, persist=persist, iou_threshold=iou_threshold,
        gt_mode=gt_mode, visibility_threshold=visibility_threshold, otb_average=otb_average,
        rank=rank,
    )  # fmt: skip


def _report(
    sequence: Any, est: NDArray[np.float64], track_ids: NDArray[np.int64], rows: list[int],
    pair: list[int] | None, *, tracker: str, recover_frames: int, persist: int,
    iou_threshold: float, gt_mode: str, visibility_threshold: float, otb_average: str,
    rank: ArrayLike | None, mot_rows: list[int] | None = None,
) -> SequenceReport:  # fmt: skip
    """The report of tracks ``est`` (T, H, 4); row ``rows[m]`` (entity index) pairs ``pair[m]``
    (None: paired by :func:`_pair_tracks` on the scored ground truth and tracks, those of
    ``gt_mode``); ``rank`` (T, H) or None as in :func:`evaluate_tracks`; the overall
    multi-object scores cover the entities ``mot_rows`` (None: every target)."""
    gt_box = np.asarray(sequence.gt.box, dtype=np.float64)
    present = np.asarray(sequence.gt.present, dtype=bool)
    keep = gt_keep(sequence, gt_mode, visibility_threshold)
    gt_all = np.where(keep[..., None], gt_box, np.nan)
    roles = np.asarray(sequence.entities.role).astype(str)
    entity_ids = np.asarray(sequence.entities.id).astype(np.int64)
    est_keep = np.all(np.isfinite(est), axis=-1)
    if gt_mode == "visible":
        # MOTChallenge preprocessing: all rows of the ground-truth file, in file order.
        cols = [k for k in range(len(roles)) if roles[k] in _MOT_ROLES]
        file_gt = np.where(present[..., None], gt_box, np.nan)[:, cols]
        est_keep &= remove_distractor_matches(file_gt, roles[cols] == "distractor", est,
                                              est_rank=rank)  # fmt: skip
    est_scored = np.where(est_keep[..., None], est, np.nan)
    if pair is None:
        pair = _pair_tracks(gt_all[:, rows], est_scored, entity_ids[rows], track_ids,
                            iou_threshold)  # fmt: skip
    # Multi-object scores over every target of the sequence (evaluate_target: its own).
    targets_all = np.flatnonzero(roles == "target") if mot_rows is None else np.array(mot_rows)
    overall_mot = MotSummary.from_scores(
        score_all(mot_frames(gt_all[:, targets_all], est_scored, est_rank=rank),
                  threshold=iou_threshold)
    )
    nan_track = np.full((est.shape[0], 1, 4), np.nan)
    rows_gt = gt_all[:, rows]
    rows_est = np.concatenate(
        [est_scored[:, [p]] if p >= 0 else nan_track for p in pair], axis=1
    ) if rows else np.zeros((est.shape[0], 0, 4))  # fmt: skip
    fm = frame_measures(rows_est, rows_gt)
    thresholds = failure_threshold(rows_gt)
    has_gt = np.all(np.isfinite(rows_gt), axis=-1)
    targets = []
    for m, k in enumerate(rows):
        ok = has_gt[:, m]
        state = fm["state"][ok, m][None, :]
        curves = metrics.otb_curves(rows_est[:, m], rows_gt[:, m])
        err = np.nan_to_num(fm["centre_error"][ok, m], nan=np.inf)
        mot = score_all(mot_frames(rows_gt[:, [m]], rows_est[:, [m]]), threshold=iou_threshold)
        targets.append(
            TargetScores(
                id=int(entity_ids[k]),
                name=str(np.asarray(sequence.entities.name)[k]),
                track_id=int(track_ids[pair[m]]) if pair[m] >= 0 else None,
                frames=int(ok.sum()),
                tracked=100.0 * float(np.mean(state)) if ok.any() else None,
                success=bool(metrics.success_rate(state) == 100.0) if ok.any() else None,
                recovered=(
                    bool(metrics.recovery_rate(state, last_k=recover_frames) == 100.0)
                    if ok.any()
                    else None
                ),
                precision=_finite(
                    metrics.mean_over_tracked(fm["precision"][:, m], fm["state"][:, m])
                ),
                recall=_finite(metrics.mean_over_tracked(fm["recall"][:, m], fm["state"][:, m])),
                mean_iou=_mean(np.nan_to_num(fm["iou"][ok, m])),
                mean_centre_error=_mean(err[np.isfinite(err)]),
                auc=_finite(curves.auc),
                precision_20=_finite(curves.precision_20),
                failure_frame=_sequence_frame(
                    metrics.failure_frame(err, float(thresholds[m]), persist=persist)
                    if ok.any()
                    else -1,
                    ok,
                ),
                mot=MotSummary.from_scores(mot),
            )
        )
    # The single-target means are over the targets present at frame 0, those a tracker is
    # started on, whichever the tracks came from (a result file has rows for only those;
    # a tracker file for every target): the two give the same overall row.
    initial = present[0, rows] if rows else np.zeros(0, dtype=bool)
    if otb_average == "frames":
        pooled = metrics.otb_curves(rows_est[:, initial], rows_gt[:, initial])
        auc, p20 = _finite(pooled.auc), _finite(pooled.precision_20)
    else:
        aucs = [t.auc for t, i in zip(targets, initial, strict=True) if i and t.auc is not None]
        p20s = [
            t.precision_20
            for t, i in zip(targets, initial, strict=True)
            if i and t.precision_20 is not None
        ]
        auc = float(np.mean(aucs)) if aucs else None
        p20 = float(np.mean(p20s)) if p20s else None
    overall = OverallScores(
        mean_iou=_mean(np.nan_to_num(fm["iou"][has_gt & initial[None, :]])),
        auc=auc,
        precision_20=p20,
        otb_average=otb_average,
        mot=overall_mot,
    )
    return SequenceReport(
        sequence=str(getattr(sequence, "name", "")),
        tracker=tracker,
        n_frames=int(gt_box.shape[0]),
        gt_mode=gt_mode,
        visibility_threshold=float(visibility_threshold),
        targets=tuple(targets),
        overall=overall,
    )


def to_json(report: SequenceReport) -> str:
    """One JSON document for a report (sorted keys, no NaN); ``report.to_json()``.

    Parameters
    ----------
    report : SequenceReport
        The report to serialise.

    Returns
    -------
    str
        The JSON text; undefined numbers are ``null``.
    """
    return report.to_json()
