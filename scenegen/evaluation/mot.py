"""Multi-object tracking scores computed exactly as TrackEval computes them.

CLEAR MOT (MOTA, MOTP, FP, FN, IDSW, MT/PT/ML, Frag), the identity scores (IDF1, IDP, IDR)
and HOTA (with DetA, AssA, LocA) follow TrackEval's ``clear.py``, ``identity.py`` and
``hota.py`` (Luiten & Hoffhues, github.com/JonathonLuiten/TrackEval) step by step: the same
similarity (box IoU with TrackEval's guards against empty boxes), the same Hungarian
matchings (``scipy.optimize.linear_sum_assignment``) on the same score matrices, the same
``eps`` tolerances and the same empty-sequence results. ``tests/scenegen/evaluation``
checks the numbers against TrackEval's own output on committed files
(``tests/data/trackeval/oracle.json``, made by ``tools/trackeval/make_oracle.py``).

The input is :class:`MotFrames`: per frame the ground-truth and tracker ids present
(relabelled 0..n-1) and their similarity matrix, as TrackEval's datasets hand it to its
metrics. :func:`mot_frames` builds it from box arrays, :func:`remove_distractor_matches`
applies MOTChallenge's preprocessing (tracker boxes matched to a distractor are dropped).

Examples
--------
>>> import numpy as np
>>> gt = np.array([[[0, 0, 10, 10.]], [[1, 0, 10, 10.]]])      # (T=2, K=1, 4)
>>> scores = score_all(mot_frames(gt, gt))
>>> scores.clear.mota, scores.identity.idf1, round(scores.hota.hota, 6)
(1.0, 1.0, 1.0)
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import linear_sum_assignment

__all__ = [
    "HOTA_ALPHAS",
    "ClearScores",
    "HotaScores",
    "IdentityScores",
    "MotFrames",
    "MotScores",
    "box_iou",
    "check_threshold",
    "COUNT_KEYS",
    "HOTA_COUNT_KEYS",
    "add_counts",
    "clear",
    "combine",
    "from_counts",
    "hota",
    "identity",
    "mot_counts",
    "mot_frames",
    "remove_distractor_matches",
    "score_all",
]

_EPS = float(np.finfo("float").eps)

HOTA_ALPHAS = np.arange(0.05, 0.99, 0.05)
"""The 19 localisation thresholds of HOTA, 0.05 to 0.95 (TrackEval's ``array_labels``)."""


def box_iou(a: ArrayLike, b: ArrayLike) -> NDArray[np.float64]:
    """IoU of boxes ``[x, y, w, h]``, (N, 4) against (M, 4) -> (N, M), as TrackEval.

    Boxes of zero area and pairs of zero union have IoU 0.

    Parameters
    ----------
    a : array_like of float, shape (N, 4)
        Boxes ``[x, y, w, h]``, pixels (any shape is read as rows of 4).
    b : array_like of float, shape (M, 4)
        Boxes ``[x, y, w, h]``, pixels.

    Returns
    -------
    ndarray of float, shape (N, M)
        IoU of every box of ``a`` with every box of ``b``, in [0, 1].
    """
    b1 = np.array(a, dtype=np.float64).reshape(-1, 4)
    b2 = np.array(b, dtype=np.float64).reshape(-1, 4)
    b1[:, 2] = b1[:, 0] + b1[:, 2]
    b1[:, 3] = b1[:, 1] + b1[:, 3]
    b2[:, 2] = b2[:, 0] + b2[:, 2]
    b2[:, 3] = b2[:, 1] + b2[:, 3]
    lo = np.minimum(b1[:, None, :], b2[None, :, :])
    hi = np.maximum(b1[:, None, :], b2[None, :, :])
    inter = np.maximum(lo[..., 2] - hi[..., 0], 0) * np.maximum(lo[..., 3] - hi[..., 1], 0)
    area1 = (b1[:, 2] - b1[:, 0]) * (b1[:, 3] - b1[:, 1])
    area2 = (b2[:, 2] - b2[:, 0]) * (b2[:, 3] - b2[:, 1])
    union = area1[:, None] + area2[None, :] - inter
    inter[area1 <= _EPS, :] = 0
    inter[:, area2 <= _EPS] = 0
    inter[union <= _EPS] = 0
    union[union <= _EPS] = 1
    return inter / union


@dataclass(frozen=True)
class MotFrames:
    """Detections of one sequence, frame by frame, as TrackEval's metrics take them.

    Attributes
    ----------
    gt_ids, tracker_ids : tuple of ndarray of int
        Per frame (T entries) the ids present, relabelled to 0..n_gt_ids-1 and
        0..n_tracker_ids-1; rows and columns of ``similarity`` follow their order.
    similarity : tuple of ndarray of shape (n_gt_t, n_tracker_t)
        IoU of every ground-truth box with every tracker box of the frame.
    n_gt_ids, n_tracker_ids : int
        Distinct ids over the sequence.
    """

    gt_ids: tuple[NDArray[np.intp], ...]
    tracker_ids: tuple[NDArray[np.intp], ...]
    similarity: tuple[NDArray[np.float64], ...]
    n_gt_ids: int
    n_tracker_ids: int

    @property
    def n_gt_dets(self) -> int:
        """Ground-truth detections of the sequence, an int (ids present, summed over frames)."""
        return int(sum(len(g) for g in self.gt_ids))

    @property
    def n_tracker_dets(self) -> int:
        """Tracker detections of the sequence, an int (ids present, summed over frames)."""
        return int(sum(len(h) for h in self.tracker_ids))


def _relabel(present: NDArray[np.bool_]) -> NDArray[np.intp]:
    """Contiguous ids 0..n-1 for the columns of ``present`` (T, K) that are ever present."""
    used = present.any(axis=0)
    label = np.full(present.shape[1], -1, dtype=np.intp)
    label[used] = np.arange(int(used.sum()))
    return label


def mot_frames(
    gt: ArrayLike,
    est: ArrayLike,
    *,
    gt_keep: ArrayLike | None = None,
    est_keep: ArrayLike | None = None,
    est_rank: ArrayLike | None = None,
) -> MotFrames:
    """:class:`MotFrames` from ground-truth and tracker box arrays.

    Parameters
    ----------
    gt : array_like of shape (T, K, 4)
        Ground-truth boxes ``[x, y, w, h]``; column k is one object, NaN where absent.
    est : array_like of shape (T, H, 4)
        Tracker boxes; column h is one track, NaN where it has no box.
    gt_keep : array_like of bool, shape (T, K), optional
        Ground-truth detections to score (default: every finite box).
    est_keep : array_like of bool, shape (T, H), optional
        Tracker detections to score (default: every finite box).
    est_rank : array_like of int, shape (T, H), optional
        Order of each frame's tracker boxes (``read_mot_tracker_rows``' rank: the rows'
        order in the tracker file); default: column order.

    Returns
    -------
    MotFrames
        Within a frame, objects keep their column order and tracks the order of
        ``est_rank`` (TrackEval keeps the row order of its files, which breaks ties in
        its matchings; scenegen's exports list boxes in column order).

    Raises
    ------
    ValueError
        If ``gt`` and ``est`` are not of shapes (T, K, 4) and (T, H, 4) with the same T.
    """
    g, e = _frames_of_boxes(gt, est)
    gp = np.all(np.isfinite(g), axis=-1)
    ep = np.all(np.isfinite(e), axis=-1)
    if gt_keep is not None:
        gp &= np.asarray(gt_keep, dtype=bool)
    if est_keep is not None:
        ep &= np.asarray(est_keep, dtype=bool)
    gl, el = _relabel(gp), _relabel(ep)
    gt_ids, trk_ids, sims = [], [], []
    for t in range(g.shape[0]):
        gi, ej = np.flatnonzero(gp[t]), _in_order(ep[t], est_rank, t)
        gt_ids.append(gl[gi])
        trk_ids.append(el[ej])
        sims.append(box_iou(g[t, gi], e[t, ej]))
    return MotFrames(
        gt_ids=tuple(gt_ids),
        tracker_ids=tuple(trk_ids),
        similarity=tuple(sims),
        n_gt_ids=int(gl.max(initial=-1) + 1),
        n_tracker_ids=int(el.max(initial=-1) + 1),
    )


def _in_order(present: NDArray[np.bool_], rank: ArrayLike | None, t: int) -> NDArray[np.intp]:
    """The columns where ``present`` (H,) is True, in the order of ``rank[t]`` if given."""
    cols = np.flatnonzero(present)
    if rank is None:
        return cols
    return cols[np.argsort(np.asarray(rank)[t, cols], kind="stable")]


def _frames_of_boxes(
    gt: ArrayLike, est: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Ground truth (T, K, 4) and tracker boxes (T, H, 4) as float arrays of the same T.

    Raises
    ------
    ValueError
        If either is not of shape (T, ·, 4) or their frame counts differ.
    """
    g = np.asarray(gt, dtype=np.float64)
    e = np.asarray(est, dtype=np.float64)
    if (g.ndim != 3 or e.ndim != 3 or g.shape[0] != e.shape[0]
            or g.shape[2:] != (4,) or e.shape[2:] != (4,)):
        raise ValueError(f"gt (T, K, 4) and est (T, H, 4) disagree: {g.shape}, {e.shape}")
    return g, e


def remove_distractor_matches(
    gt: ArrayLike, distractor: ArrayLike, est: ArrayLike, est_rank: ArrayLike | None = None
) -> NDArray[np.bool_]:
    """Tracker boxes MOTChallenge keeps: those not matched to a distractor.

    TrackEval's MOTChallenge preprocessing matches, per frame, every tracker box to every
    ground-truth row of the file (whatever its class or ``conf``) by the Hungarian
    algorithm on IoU (pairs below 0.5 excluded) and drops the tracker boxes matched to a
    row of a distractor class; they count neither as true nor as false positives.

    Parameters
    ----------
    gt : array_like of shape (T, K, 4)
        Every ground-truth row of the file, in file order (NaN where absent).
    distractor : array_like of bool, shape (K,) or (T, K)
        Rows of a distractor class.
    est : array_like of shape (T, H, 4)
        Tracker boxes.
    est_rank : array_like of int, shape (T, H), optional
        Order of each frame's tracker boxes in the file (as in :func:`mot_frames`).

    Returns
    -------
    ndarray of bool, shape (T, H)
        True for the tracker boxes to keep (and for absent ones).

    Raises
    ------
    ValueError
        If ``gt`` and ``est`` are not of shapes (T, K, 4) and (T, H, 4) with the same T.
    """
    g, e = _frames_of_boxes(gt, est)
    dis = np.broadcast_to(np.asarray(distractor, dtype=bool), g.shape[:2])
    keep = np.ones(e.shape[:2], dtype=bool)
    gp = np.all(np.isfinite(g), axis=-1)
    ep = np.all(np.isfinite(e), axis=-1)
    for t in range(g.shape[0]):
        gi, ej = np.flatnonzero(gp[t]), _in_order(ep[t], est_rank, t)
        if gi.size == 0 or ej.size == 0:
            continue
        score = box_iou(g[t, gi], e[t, ej])
        score[score < 0.5 - _EPS] = 0
        rows, cols = linear_sum_assignment(-score)
        ok = score[rows, cols] > _EPS
        rows, cols = rows[ok], cols[ok]
        keep[t, ej[cols[dis[t, gi[rows]]]]] = False
    return keep


@dataclass(frozen=True)
class ClearScores:
    """CLEAR MOT scores of one sequence (TrackEval's ``CLEAR``).

    Attributes
    ----------
    mota : float
        (TP − FP − IDSW) / max(1, TP + FN).
    motp : float
        Mean IoU of the matches (0 without matches).
    moda : float
        (TP − FP) / max(1, TP + FN).
    tp, fn, fp, idsw : int
        Matches, misses, false positives, identity switches.
    mt, pt, ml : int
        Objects tracked in more than 80 %, 20–80 %, less than 20 % of their frames.
    frag : int
        Times an object's track resumes after an interruption.
    motp_sum : float
        Summed IoU of the matches (TrackEval's ``MOTP_sum``; what :func:`combine` adds up).
    """

    mota: float
    motp: float
    moda: float
    tp: int
    fn: int
    fp: int
    idsw: int
    mt: int
    pt: int
    ml: int
    frag: int
    motp_sum: float = 0.0


def _clear_final(tp: int, fn: int, fp: int, idsw: int, motp_sum: float, mt: int, pt: int,
                 ml: int, frag: int) -> ClearScores:  # fmt: skip
    n = max(1.0, tp + fn)
    return ClearScores(
        mota=(tp - fp - idsw) / n,
        motp=motp_sum / max(1.0, tp),
        moda=(tp - fp) / n,
        tp=tp, fn=fn, fp=fp, idsw=idsw, mt=mt, pt=pt, ml=ml, frag=frag, motp_sum=motp_sum,
    )  # fmt: skip


def check_threshold(threshold: float) -> None:
    """Raise ValueError unless the match IoU ``threshold`` is in (0, 1].

    A threshold of 0 would count every pair of boxes, overlapping or not, as a match (IoU
    is never negative), which no metric intends; above 1 nothing ever matches.

    Parameters
    ----------
    threshold : float
        Match IoU threshold to check.

    Raises
    ------
    ValueError
        If ``threshold`` is not in (0, 1].
    """
    if not 0.0 < float(threshold) <= 1.0:
        raise ValueError(f"iou_threshold must be in (0, 1], got {threshold}")


def clear(data: MotFrames, *, threshold: float = 0.5) -> ClearScores:
    """CLEAR MOT of one sequence, as TrackEval's ``CLEAR.eval_sequence``.

    Per frame the Hungarian algorithm maximises first the number of objects that keep the
    track of the previous frame, then the summed IoU, among pairs with IoU ≥ ``threshold``.
    An object matched to a different track than at its last match (any number of frames
    earlier) is an identity switch.

    Parameters
    ----------
    data : MotFrames
        Detections and similarities of the sequence (e.g. from :func:`mot_frames`).
    threshold : float
        Smallest IoU of a match, in (0, 1].

    Returns
    -------
    ClearScores
        With no tracker detection, every object is missed (all FN, all ML); with no
        ground-truth detection, every tracker detection is a false positive.

    Raises
    ------
    ValueError
        If ``threshold`` is not in (0, 1].
    """
    check_threshold(threshold)
    if data.n_tracker_dets == 0:
        return ClearScores(0.0, 0.0, 0.0, 0, data.n_gt_dets, 0, 0, 0, 0, data.n_gt_ids, 0)
    if data.n_gt_dets == 0:
        return ClearScores(0.0, 0.0, 0.0, 0, 0, data.n_tracker_dets, 0, 0, 0, 0, 0)
    n_ids = data.n_gt_ids
    id_count = np.zeros(n_ids)
    matched_count = np.zeros(n_ids)
    frag_count = np.zeros(n_ids)
    prev_id = np.full(n_ids, np.nan)
    prev_step_id = np.full(n_ids, np.nan)
    tp = fn = fp = idsw = 0
    motp_sum = 0.0
    for gt_ids, trk_ids, sim in zip(data.gt_ids, data.tracker_ids, data.similarity, strict=True):
        if len(gt_ids) == 0:
            fp += len(trk_ids)
            continue
        if len(trk_ids) == 0:
            fn += len(gt_ids)
            id_count[gt_ids] += 1
            continue
        score = 1000.0 * (trk_ids[None, :] == prev_step_id[gt_ids[:, None]]) + sim
        score[sim < threshold - _EPS] = 0
        rows, cols = linear_sum_assignment(-score)
        ok = score[rows, cols] > _EPS
        rows, cols = rows[ok], cols[ok]
        m_gt, m_trk = gt_ids[rows], trk_ids[cols]
        prev = prev_id[m_gt]
        idsw += int(np.sum(~np.isnan(prev) & (m_trk != prev)))
        id_count[gt_ids] += 1
        matched_count[m_gt] += 1
        not_tracked = np.isnan(prev_step_id)
        prev_id[m_gt] = m_trk
        prev_step_id[:] = np.nan
        prev_step_id[m_gt] = m_trk
        frag_count += not_tracked & ~np.isnan(prev_step_id)
        tp += len(m_gt)
        fn += len(gt_ids) - len(m_gt)
        fp += len(trk_ids) - len(m_gt)
        if len(m_gt):
            motp_sum += sum(sim[rows, cols])
    ratio = matched_count[id_count > 0] / id_count[id_count > 0]
    mt = int(np.sum(ratio > 0.8))
    pt = int(np.sum(ratio >= 0.2)) - mt
    frag = int(np.sum(frag_count[frag_count > 0] - 1))
    return _clear_final(tp, fn, fp, idsw, motp_sum, mt, pt, n_ids - mt - pt, frag)


@dataclass(frozen=True)
class IdentityScores:
    """Identity scores of one sequence (Ristani et al. 2016; TrackEval's ``Identity``).

    Attributes
    ----------
    idf1, idp, idr : float
        IDTP / max(1, IDTP + (IDFP + IDFN) / 2), IDTP / max(1, IDTP + IDFP),
        IDTP / max(1, IDTP + IDFN).
    idtp, idfn, idfp : int
    """

    idf1: float
    idp: float
    idr: float
    idtp: int
    idfn: int
    idfp: int


def _identity_final(idtp: int, idfn: int, idfp: int) -> IdentityScores:
    return IdentityScores(
        idf1=idtp / max(1.0, idtp + 0.5 * idfp + 0.5 * idfn),
        idp=idtp / max(1.0, idtp + idfp),
        idr=idtp / max(1.0, idtp + idfn),
        idtp=idtp,
        idfn=idfn,
        idfp=idfp,
    )


def identity(data: MotFrames, *, threshold: float = 0.5) -> IdentityScores:
    """IDF1, IDP, IDR of one sequence, as TrackEval's ``Identity.eval_sequence``.

    Each object is matched to at most one track for the whole sequence, minimising
    IDFN + IDFP by the Hungarian algorithm; a frame where both exist with IoU ≥
    ``threshold`` is an identity true positive.

    TrackEval solves it as a square problem of side (objects + tracks), with dummy rows
    and columns for "unmatched": 300,000 track ids asked for 671 GiB. For any matching,
    IDFN = (object detections) − IDTP and IDFP = (track detections) − IDTP, with IDTP the
    frames the matched pairs share, so minimising IDFN + IDFP is maximising IDTP: the
    rectangular problem on the shared-frame counts (objects x tracks) has the same optimum,
    in integers, and the same IDTP, IDFN and IDFP.

    Parameters
    ----------
    data : MotFrames
        Detections and similarities of the sequence (e.g. from :func:`mot_frames`).
    threshold : float
        Smallest IoU of a match, in (0, 1].

    Returns
    -------
    IdentityScores
        All rates 0 when either side has no detection.

    Raises
    ------
    ValueError
        If ``threshold`` is not in (0, 1].
    """
    check_threshold(threshold)
    if data.n_tracker_dets == 0:
        return IdentityScores(0.0, 0.0, 0.0, 0, data.n_gt_dets, 0)
    if data.n_gt_dets == 0:
        return IdentityScores(0.0, 0.0, 0.0, 0, 0, data.n_tracker_dets)
    ng, nt = data.n_gt_ids, data.n_tracker_ids
    potential = np.zeros((ng, nt))
    gt_count = np.zeros(ng)
    trk_count = np.zeros(nt)
    for gt_ids, trk_ids, sim in zip(data.gt_ids, data.tracker_ids, data.similarity, strict=True):
        r, c = np.nonzero(np.greater_equal(sim, threshold))
        np.add.at(potential, (gt_ids[r], trk_ids[c]), 1)
        gt_count[gt_ids] += 1
        trk_count[trk_ids] += 1
    rows, cols = linear_sum_assignment(potential, maximize=True)
    idtp = int(potential[rows, cols].sum())
    return _identity_final(idtp, int(gt_count.sum()) - idtp, int(trk_count.sum()) - idtp)


@dataclass(frozen=True)
class HotaScores:
    """HOTA of one sequence (Luiten et al. 2021; TrackEval's ``HOTA``).

    The scalar fields are the means over the 19 thresholds :data:`HOTA_ALPHAS`, as
    TrackEval reports them; ``*_alpha`` hold the per-threshold values, shape (19,).

    Attributes
    ----------
    hota, deta, assa, loca : float
        HOTA = sqrt(DetA · AssA) per threshold; detection, association and localisation
        accuracy.
    detre, detpr, assre, asspr : float
        Detection and association recall and precision.
    hota_alpha, deta_alpha, assa_alpha, loca_alpha : ndarray of shape (19,)
    assre_alpha, asspr_alpha : ndarray of shape (19,)
        Association recall and precision per threshold.
    tp_alpha, fn_alpha, fp_alpha : ndarray of shape (19,)
        Detection true positives, misses and false positives per threshold (TrackEval's
        ``HOTA_TP``, ``HOTA_FN``, ``HOTA_FP``; what :func:`combine` adds up).
    """

    hota: float
    deta: float
    assa: float
    loca: float
    detre: float
    detpr: float
    assre: float
    asspr: float
    hota_alpha: NDArray[np.float64]
    deta_alpha: NDArray[np.float64]
    assa_alpha: NDArray[np.float64]
    loca_alpha: NDArray[np.float64]
    assre_alpha: NDArray[np.float64]
    asspr_alpha: NDArray[np.float64]
    tp_alpha: NDArray[np.float64]
    fn_alpha: NDArray[np.float64]
    fp_alpha: NDArray[np.float64]


def _hota_final(tp: NDArray, fn: NDArray, fp: NDArray, assa: NDArray, assre: NDArray,
                asspr: NDArray, loca: NDArray) -> HotaScores:  # fmt: skip
    detre = tp / np.maximum(1, tp + fn)
    detpr = tp / np.maximum(1, tp + fp)
    deta = tp / np.maximum(1, tp + fn + fp)
    h = np.sqrt(deta * assa)
    return HotaScores(
        hota=float(np.mean(h)), deta=float(np.mean(deta)), assa=float(np.mean(assa)),
        loca=float(np.mean(loca)), detre=float(np.mean(detre)), detpr=float(np.mean(detpr)),
        assre=float(np.mean(assre)), asspr=float(np.mean(asspr)),
        hota_alpha=h, deta_alpha=deta, assa_alpha=assa, loca_alpha=loca,
        assre_alpha=assre, asspr_alpha=asspr, tp_alpha=tp, fn_alpha=fn, fp_alpha=fp,
    )  # fmt: skip


def hota(data: MotFrames) -> HotaScores:
    """HOTA of one sequence, as TrackEval's ``HOTA.eval_sequence``.

    A global alignment score between each object and track (their IoU-weighted co-occurrence
    Jaccard index) weights the per-frame IoU; the Hungarian algorithm maximises that
    product, and each threshold α in :data:`HOTA_ALPHAS` keeps the matches with IoU ≥ α.

    Parameters
    ----------
    data : MotFrames
        Detections and similarities of the sequence (e.g. from :func:`mot_frames`).

    Returns
    -------
    HotaScores
        When either side has no detection, every score is 0 but LocA, 1 (as TrackEval).
    """
    n_a = len(HOTA_ALPHAS)
    zeros = np.zeros(n_a)
    if data.n_tracker_dets == 0 or data.n_gt_dets == 0:
        # TrackEval returns before computing the final fields: all 0 but LocA = 1; every
        # ground-truth detection is a miss and every tracker detection a false positive.
        fn = np.full(n_a, float(data.n_gt_dets))
        fp = np.full(n_a, float(data.n_tracker_dets))
        return HotaScores(0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, zeros, zeros, zeros,
                          np.ones(n_a), zeros, zeros, zeros, fn, fp)  # fmt: skip
    ng, nt = data.n_gt_ids, data.n_tracker_ids
    potential = np.zeros((ng, nt))
    gt_count = np.zeros((ng, 1))
    trk_count = np.zeros((1, nt))
    for gt_ids, trk_ids, sim in zip(data.gt_ids, data.tracker_ids, data.similarity, strict=True):
        denom = sim.sum(0)[None, :] + sim.sum(1)[:, None] - sim
        sim_iou = np.zeros_like(sim)
        mask = denom > 0 + _EPS
        sim_iou[mask] = sim[mask] / denom[mask]
        potential[gt_ids[:, None], trk_ids[None, :]] += sim_iou
        gt_count[gt_ids] += 1
        trk_count[0, trk_ids] += 1
    with np.errstate(invalid="ignore", divide="ignore"):
        alignment = potential / (gt_count + trk_count - potential)
    matches = [np.zeros_like(potential) for _ in range(n_a)]
    tp, fn, fp, loca = zeros.copy(), zeros.copy(), zeros.copy(), zeros.copy()
    for gt_ids, trk_ids, sim in zip(data.gt_ids, data.tracker_ids, data.similarity, strict=True):
        if len(gt_ids) == 0:
            fp += len(trk_ids)
            continue
        if len(trk_ids) == 0:
            fn += len(gt_ids)
            continue
        score = alignment[gt_ids[:, None], trk_ids[None, :]] * sim
        rows, cols = linear_sum_assignment(-score)
        for a, alpha in enumerate(HOTA_ALPHAS):
            ok = sim[rows, cols] >= alpha - _EPS
            r, c = rows[ok], cols[ok]
            tp[a] += len(r)
            fn[a] += len(gt_ids) - len(r)
            fp[a] += len(trk_ids) - len(r)
            if len(r):
                loca[a] += sum(sim[r, c])
                matches[a][gt_ids[r], trk_ids[c]] += 1
    assa, assre, asspr = zeros.copy(), zeros.copy(), zeros.copy()
    for a in range(n_a):
        mc = matches[a]
        ass_a = mc / np.maximum(1, gt_count + trk_count - mc)
        assa[a] = np.sum(mc * ass_a) / np.maximum(1, tp[a])
        assre[a] = np.sum(mc * (mc / np.maximum(1, gt_count))) / np.maximum(1, tp[a])
        asspr[a] = np.sum(mc * (mc / np.maximum(1, trk_count))) / np.maximum(1, tp[a])
    loca = np.maximum(1e-10, loca) / np.maximum(1e-10, tp)
    return _hota_final(tp, fn, fp, assa, assre, asspr, loca)


@dataclass(frozen=True)
class MotScores:
    """CLEAR MOT, identity and HOTA scores of one sequence.

    Attributes
    ----------
    clear : ClearScores
        CLEAR MOT scores (:func:`clear`).
    identity : IdentityScores
        IDF1, IDP, IDR (:func:`identity`).
    hota : HotaScores
        HOTA and its components (:func:`hota`).
    """

    clear: ClearScores
    identity: IdentityScores
    hota: HotaScores


def score_all(data: MotFrames, *, threshold: float = 0.5) -> MotScores:
    """:func:`clear`, :func:`identity` (both at ``threshold``) and :func:`hota` of ``data``.

    Parameters
    ----------
    data : MotFrames
        Detections and similarities of the sequence (e.g. from :func:`mot_frames`).
    threshold : float
        Smallest IoU of a match for CLEAR MOT and the identity scores, in (0, 1]; HOTA
        uses its own thresholds :data:`HOTA_ALPHAS`.

    Returns
    -------
    MotScores

    Raises
    ------
    ValueError
        If ``threshold`` is not in (0, 1].
    """
    return MotScores(
        clear=clear(data, threshold=threshold),
        identity=identity(data, threshold=threshold),
        hota=hota(data),
    )


_CLEAR_COUNTS = ("tp", "fn", "fp", "idsw", "motp_sum", "mt", "pt", "ml", "frag")
_IDENTITY_COUNTS = ("idtp", "idfn", "idfp")
HOTA_COUNT_KEYS = ("hota_tp", "hota_fn", "hota_fp", "assa_tp", "assre_tp", "asspr_tp", "loca_tp")
"""The keys of :func:`mot_counts` that hold one value per HOTA threshold (19)."""
COUNT_KEYS = (*_CLEAR_COUNTS, *_IDENTITY_COUNTS, *HOTA_COUNT_KEYS)
"""The keys of :func:`mot_counts`: CLEAR's, the identity scores', then HOTA's (per threshold)."""


def mot_counts(scores: MotScores) -> dict[str, Any]:
    """The additive counts behind ``scores``: what TrackEval adds up over sequences.

    Parameters
    ----------
    scores : MotScores
        The scores of one sequence (:func:`score_all`), or of several (:func:`combine`).

    Returns
    -------
    dict of str to int, float or list of float
        One entry per :data:`COUNT_KEYS`: CLEAR's ``tp``, ``fn``, ``fp``, ``idsw``,
        ``motp_sum`` (the matches' summed IoU), ``mt``, ``pt``, ``ml``, ``frag``; the
        identity scores' ``idtp``, ``idfn``, ``idfp``; and HOTA's per-threshold lists
        (19 values) ``hota_tp``, ``hota_fn``, ``hota_fp`` and AssA, AssRe, AssPr and LocA
        each multiplied by that threshold's TP (``assa_tp`` ...). Plain JSON types:
        :func:`from_counts` of the sum of several is :func:`combine` of their scores.

    Examples
    --------
    >>> import numpy as np
    >>> gt = np.array([[[0, 0, 10, 10.]], [[1, 0, 10, 10.]]])      # (T=2, K=1, 4)
    >>> counts = mot_counts(score_all(mot_frames(gt, gt)))
    >>> counts["tp"], counts["idtp"], counts["hota_tp"][0]
    (2, 2, 2.0)
    """
    c, i, h = scores.clear, scores.identity, scores.hota
    out: dict[str, Any] = {k: getattr(c, k) for k in _CLEAR_COUNTS}
    out["motp_sum"] = float(c.motp_sum)
    out.update({k: getattr(i, k) for k in _IDENTITY_COUNTS})
    tp = np.asarray(h.tp_alpha, dtype=np.float64)
    out.update(hota_tp=tp.tolist(), hota_fn=np.asarray(h.fn_alpha, float).tolist(),
               hota_fp=np.asarray(h.fp_alpha, float).tolist(),
               assa_tp=(h.assa_alpha * tp).tolist(), assre_tp=(h.assre_alpha * tp).tolist(),
               asspr_tp=(h.asspr_alpha * tp).tolist(), loca_tp=(h.loca_alpha * tp).tolist())
    return out


def add_counts(counts: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """The sum of several :func:`mot_counts`, key by key, in the given order.

    Parameters
    ----------
    counts : sequence of dict
        :func:`mot_counts` of each sequence, at least one.

    Returns
    -------
    dict
        The same keys: ints and floats added from 0 in order, as TrackEval's
        ``_combine_sum`` adds; per-threshold lists added element by element.

    Raises
    ------
    ValueError
        If ``counts`` is empty or an entry lacks a key of :data:`COUNT_KEYS` or has a
        per-threshold list of another length than 19.
    """
    counts = list(counts)
    if not counts:
        raise ValueError("add_counts: no counts to add (give one per sequence)")
    n_a = len(HOTA_ALPHAS)
    for c in counts:
        bad = next((k for k in COUNT_KEYS if not isinstance(c, dict) or k not in c
                    or (k in HOTA_COUNT_KEYS and len(c[k]) != n_a)), None)  # fmt: skip
        if bad is not None:
            raise ValueError(f"add_counts: an entry has no {bad!r} "
                             f"(mot_counts gives {', '.join(COUNT_KEYS)})")  # fmt: skip
    out: dict[str, Any] = {}
    for k in COUNT_KEYS:
        if k in HOTA_COUNT_KEYS:
            out[k] = sum(np.asarray(c[k], dtype=np.float64) for c in counts).tolist()
        else:
            out[k] = sum(c[k] for c in counts)
    return out


def from_counts(counts: dict[str, Any]) -> MotScores:
    """The scores of counts (:func:`mot_counts`, or :func:`add_counts` of several).

    Parameters
    ----------
    counts : dict
        Every key of :data:`COUNT_KEYS`.

    Returns
    -------
    MotScores
        The rates computed from the counts as TrackEval's ``_compute_final_fields`` does:
        AssA, AssRe and AssPr the TP-weighted sums over max(1, TP), LocA the weighted sum
        over TP (each at least 1e-10).
    """
    c = counts
    clear_ = _clear_final(*(float(c[k]) if k == "motp_sum" else int(c[k])
                            for k in _CLEAR_COUNTS))  # fmt: skip
    identity_ = _identity_final(*(int(c[k]) for k in _IDENTITY_COUNTS))
    tp, fn, fp = (np.asarray(c[k], dtype=np.float64) for k in ("hota_tp", "hota_fn", "hota_fp"))
    share = {k: np.asarray(c[k], dtype=np.float64) / np.maximum(1.0, tp)
             for k in ("assa_tp", "assre_tp", "asspr_tp")}  # fmt: skip
    loca = np.maximum(1e-10, np.asarray(c["loca_tp"], dtype=np.float64)) / np.maximum(1e-10, tp)
    hota_ = _hota_final(tp, fn, fp, share["assa_tp"], share["assre_tp"], share["asspr_tp"], loca)
    return MotScores(clear=clear_, identity=identity_, hota=hota_)


def combine(scores: Sequence[MotScores]) -> MotScores:
    """The scores of several sequences taken as one, as TrackEval's ``COMBINED_SEQ``.

    CLEAR MOT and the identity scores add up their counts over the sequences (TP, FN, FP,
    IDSW, MT/PT/ML, Frag, the matches' summed IoU; IDTP, IDFN, IDFP) and compute the
    rates from the sums. HOTA adds up its per-threshold TP, FN and FP and takes AssA,
    AssRe, AssPr and LocA as means over the sequences weighted by their TP at each
    threshold (:func:`mot_counts`, :func:`add_counts`, :func:`from_counts`). So a long or
    crowded sequence weighs more than a short one, unlike the mean of the sequences'
    rates; a sequence without any detection still adds its misses or false positives.

    Parameters
    ----------
    scores : sequence of MotScores
        One per sequence (:func:`score_all`), at least one, in the order to add them
        (TrackEval adds in its sequence list's order; the sums' last bits depend on it).

    Returns
    -------
    MotScores
        The combined scores; for a single sequence, the same numbers.

    Raises
    ------
    ValueError
        If ``scores`` is empty or holds anything but :class:`MotScores`.

    Examples
    --------
    >>> import numpy as np
    >>> gt = np.array([[[0, 0, 10, 10.]], [[1, 0, 10, 10.]]])      # (T=2, K=1, 4)
    >>> perfect = score_all(mot_frames(gt, gt))
    >>> missed = score_all(mot_frames(gt, np.full_like(gt, np.nan)))
    >>> both = combine([perfect, missed])
    >>> both.clear.mota, both.clear.tp, both.clear.fn, both.identity.idf1
    (0.5, 2, 2, 0.6666666666666666)
    """
    if isinstance(scores, MotScores) or not isinstance(scores, Iterable):
        raise ValueError(f"combine: scores must be a sequence of MotScores (one per "
                         f"sequence), not {type(scores).__name__}")  # fmt: skip
    scores = list(scores)
    if not scores:
        raise ValueError("combine: scores is empty (give one MotScores per sequence)")
    bad = next((s for s in scores if not isinstance(s, MotScores)), None)
    if bad is not None:
        raise ValueError(f"combine: scores must be MotScores (from score_all), "
                         f"not {type(bad).__name__}")  # fmt: skip

    return from_counts(add_counts([mot_counts(s) for s in scores]))
