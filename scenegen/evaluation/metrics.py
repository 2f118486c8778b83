"""Tracking metrics: the DPS measures, OTB curves, KAMS failure frames, McNemar, CLEAR MOT, IDF1.

Everything here is pure numpy (CLEAR MOT and IDF1 use the TrackEval-exact matchings of
:mod:`scenegen.evaluation.mot`) and works on boxes ``[x, y, w, h]`` in pixels
(docs/format.md, "Conventions"). A box with any NaN coordinate means "no box": an absent
ground-truth entity or a missing estimate.

Frame conventions
-----------------
* Per-frame measures (``iou``, ``centre_error``, ``track_state``, ``precision_recall``)
  broadcast over leading axes, e.g. (T, K, 4) against (T, K, 4) gives (T, K).
* Per-run aggregates take a track-state array ``state`` of shape (R, T) (runs, frames) for
  one object and return percentages, as the DPS paper reports them.

Examples
--------
>>> import numpy as np
>>> float(iou(np.array([0, 0, 10, 10.]), np.array([5, 0, 10, 10.])))
0.3333333333333333
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from scenegen.config.limits import MAX_SIDE
from scenegen.evaluation import mot

__all__ = [
    "ClearMot",
    "McNemar",
    "OtbCurves",
    "box_area",
    "centre_error",
    "centres",
    "clear_mot",
    "effective_dynamics_percent",
    "failure_frame",
    "idf1",
    "intersection_area",
    "iou",
    "mcnemar",
    "mcnemar_counts",
    "mean_over_tracked",
    "depth_order_accuracy",
    "ordering_index",
    "overlap_fraction",
    "overlapping_pairs",
    "otb_curves",
    "precision_recall",
    "recovery_rate",
    "success_rate",
    "track_state",
    "tracked_fraction",
    "uniqueness_percent",
]

FloatArray = NDArray[np.float64]


def _boxes(b: ArrayLike) -> FloatArray:
    arr = np.asarray(b, dtype=np.float64)
    if arr.ndim < 1 or arr.shape[-1] != 4:
        raise ValueError(f"boxes must have a last axis of length 4, got shape {arr.shape}")
    return arr


def box_area(boxes: ArrayLike) -> FloatArray:
    """Area w·h of boxes of shape (..., 4); NaN for a missing box.

    Parameters
    ----------
    boxes : array_like of float, shape (..., 4)
        Boxes ``[x, y, w, h]``, pixels.

    Returns
    -------
    ndarray of float, shape (...)
        Area in pixels².

    Raises
    ------
    ValueError
        If the last axis of ``boxes`` is not of length 4.
    """
    b = _boxes(boxes)
    return b[..., 2] * b[..., 3]


def intersection_area(a: ArrayLike, b: ArrayLike) -> FloatArray:
    """Area of the intersection of boxes ``a`` and ``b`` (broadcast, shape (..., 4) each).

    Parameters
    ----------
    a, b : array_like of float, shape (..., 4)
        Boxes ``[x, y, w, h]``, pixels; NaN for a missing box.

    Returns
    -------
    ndarray of shape (...)
        Intersection area in pixels² (0 for disjoint boxes, NaN if either box is missing).

    Raises
    ------
    ValueError
        If the last axis of ``a`` or ``b`` is not of length 4.
    """
    a, b = _boxes(a), _boxes(b)
    x0 = np.maximum(a[..., 0], b[..., 0])
    y0 = np.maximum(a[..., 1], b[..., 1])
    x1 = np.minimum(a[..., 0] + a[..., 2], b[..., 0] + b[..., 2])
    y1 = np.minimum(a[..., 1] + a[..., 3], b[..., 1] + b[..., 3])
    return np.clip(x1 - x0, 0.0, None) * np.clip(y1 - y0, 0.0, None)


def iou(a: ArrayLike, b: ArrayLike) -> FloatArray:
    """Intersection over union of boxes ``a`` and ``b`` (broadcast, shape (..., 4) each).

    Parameters
    ----------
    a, b : array_like of float, shape (..., 4)
        Boxes ``[x, y, w, h]``, pixels; NaN for a missing box.

    Returns
    -------
    ndarray of shape (...)
        IoU in [0, 1]; NaN if either box is missing; 0 if both boxes have zero area.

    Raises
    ------
    ValueError
        If the last axis of ``a`` or ``b`` is not of length 4.

    Examples
    --------
    >>> import numpy as np
    >>> iou(np.array([[0, 0, 10, 10.], [0, 0, 4, 4.]]), np.array([0, 0, 10, 5.]))
    array([0.5 , 0.32])
    """
    inter = intersection_area(a, b)
    union = box_area(a) + box_area(b) - inter
    with np.errstate(invalid="ignore", divide="ignore"):
        out = np.where(union > 0, inter / np.where(union > 0, union, 1.0), 0.0)
    return np.where(np.isnan(inter), np.nan, out)


def centres(boxes: ArrayLike) -> FloatArray:
    """Centres (x, y) of boxes of shape (..., 4), shape (..., 2).

    Parameters
    ----------
    boxes : array_like of float, shape (..., 4)
        Boxes ``[x, y, w, h]``, pixels.

    Returns
    -------
    ndarray of float, shape (..., 2)
        Centres ``(x + w/2, y + h/2)``, pixels; NaN for a missing box.

    Raises
    ------
    ValueError
        If the last axis of ``boxes`` is not of length 4.
    """
    b = _boxes(boxes)
    return np.stack([b[..., 0] + b[..., 2] / 2, b[..., 1] + b[..., 3] / 2], axis=-1)


def centre_error(est: ArrayLike, gt: ArrayLike) -> FloatArray:
    """Euclidean distance in pixels between box centres, shape (...) from (..., 4) each.

    NaN where either box is missing.

    Parameters
    ----------
    est, gt : array_like of float, shape (..., 4)
        Estimated and ground-truth boxes ``[x, y, w, h]``, pixels (broadcast).

    Returns
    -------
    ndarray of float, shape (...)
        Centre error, pixels.

    Raises
    ------
    ValueError
        If the last axis of ``est`` or ``gt`` is not of length 4.
    """
    d = centres(est) - centres(gt)
    return np.sqrt(np.sum(d * d, axis=-1))


def track_state(est: ArrayLike, gt: ArrayLike) -> NDArray[np.bool_]:
    """DPS track state T (§3.1): True where the estimated region meets the ground truth.

    "Meets" means a non-empty intersection of positive area (boxes that only touch along an
    edge do not meet). A missing box on either side gives False.

    Parameters
    ----------
    est, gt : array_like of shape (..., 4)
        Estimated and ground-truth boxes.

    Returns
    -------
    ndarray of bool, shape (...)
    """
    inter = intersection_area(est, gt)
    return np.nan_to_num(inter, nan=0.0) > 0.0


def precision_recall(est: ArrayLike, gt: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """DPS precision |E∩G|/|E| and recall |E∩G|/|G| per frame, as fractions in [0, 1].

    Parameters
    ----------
    est, gt : array_like of shape (..., 4)

    Returns
    -------
    precision, recall : ndarray of shape (...)
        NaN where either box is missing or has zero area.
    """
    inter = intersection_area(est, gt)
    ae, ag = box_area(est), box_area(gt)
    with np.errstate(invalid="ignore", divide="ignore"):
        p = np.where(ae > 0, inter / np.where(ae > 0, ae, 1.0), np.nan)
        r = np.where(ag > 0, inter / np.where(ag > 0, ag, 1.0), np.nan)
    return p, r


def _count(value: Any, name: str) -> int:
    """``value`` as an int >= 1 (an int or numpy integer, not a bool); else ValueError
    naming ``name`` (a fractional count was compared with an int count and never met)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(f"{name} must be an integer >= 1, got {value!r}")
    return int(value)


def _state(state: ArrayLike) -> NDArray[np.bool_]:
    s = np.asarray(state, dtype=bool)
    if s.ndim != 2 or s.shape[1] < 1:
        raise ValueError(f"state must have shape (R, T) with T >= 1, got {s.shape}")
    return s


def success_rate(state: ArrayLike) -> float:
    """Percentage of runs in which the object is tracked (T = 1) in every frame (DPS §3.1).

    Parameters
    ----------
    state : array_like of bool, shape (R, T)
        Track state per run and frame. Frames where the object is absent should be left
        out by the caller.

    Returns
    -------
    float
        Success rate in percent; NaN for R = 0.

    Raises
    ------
    ValueError
        If ``state`` is not of shape (R, T) with T ≥ 1.
    """
    s = _state(state)
    if s.shape[0] == 0:
        return float("nan")
    return 100.0 * float(np.mean(np.all(s, axis=1)))


def recovery_rate(state: ArrayLike, *, last_k: int = 5) -> float:
    """Percentage of runs in which the object is tracked throughout or recovered (DPS §3.1).

    (open) "Recovered" is not defined in the paper; here a run counts as recovered when the
    object is tracked (T = 1) in each of the last ``last_k`` frames, whatever happened
    before. A run tracked in every frame is also recovered, so the recovery rate is never
    below the success rate. The default, 5 frames, is one fifth of the 25-frame DPS
    synthetic sequence: long enough that a track drifting back across the object by chance
    does not count.

    Parameters
    ----------
    state : array_like of bool, shape (R, T)
    last_k : int
        Number of final frames that must all be tracked, 1 ≤ last_k (clipped to T).

    Returns
    -------
    float
        Recovery rate in percent; NaN for R = 0.

    Raises
    ------
    ValueError
        If ``state`` is not of shape (R, T) with T ≥ 1, or ``last_k`` is not an integer ≥ 1.
    """
    s = _state(state)
    last_k = _count(last_k, "last_k")
    if s.shape[0] == 0:
        return float("nan")
    k = min(last_k, s.shape[1])
    ok = np.all(s, axis=1) | np.all(s[:, -k:], axis=1)
    return 100.0 * float(np.mean(ok))


def mean_over_tracked(values: ArrayLike, state: ArrayLike | None = None) -> float:
    """Mean of a per-frame measure over the frames where the object is tracked, in percent.

    The DPS paper averages the precision and recall of the distracted object over frames
    with T = 1 only (Table 2). With ``state=None`` every finite value is used.

    Parameters
    ----------
    values : array_like of shape (...)
        A fraction per frame (e.g. precision), NaN where undefined.
    state : array_like of bool of the same shape, optional
        Track state; frames with False are left out.

    Returns
    -------
    float
        Mean in percent; NaN if no frame qualifies.
    """
    v = np.asarray(values, dtype=np.float64)
    keep = np.isfinite(v)
    if state is not None:
        keep &= np.asarray(state, dtype=bool)
    if not np.any(keep):
        return float("nan")
    return 100.0 * float(np.mean(v[keep]))


def uniqueness_percent(uniqueness: ArrayLike) -> FloatArray:
    """Mean uniqueness per object in percent, from per-frame values of shape (..., T, K).

    ``uniqueness`` holds U/N (distinct hypotheses of the object's sub-state over the number
    of particles) per frame, as PF trackers report it; NaN frames (frame 0, before the first
    step) are ignored. Leading axes (e.g. runs) are averaged too.

    Parameters
    ----------
    uniqueness : array_like of float, shape (..., T, K)
        U/N per frame and object, in [0, 1]; NaN where undefined.

    Returns
    -------
    ndarray of shape (K,)
        Mean uniqueness in percent; NaN for an object with no finite value.

    Raises
    ------
    ValueError
        If ``uniqueness`` has fewer than 2 axes.
    """
    u = np.asarray(uniqueness, dtype=np.float64)
    if u.ndim < 2:
        raise ValueError(f"uniqueness must have shape (..., T, K), got {u.shape}")
    flat = u.reshape(-1, u.shape[-1])
    return 100.0 * _nanmean0(flat)


def effective_dynamics_percent(
    effective_dynamics: ArrayLike, *, components: bool = False
) -> FloatArray:
    """Mean effective dynamics per object (and component) in percent.

    ``effective_dynamics`` holds, per frame, the variance of an object's parameter over the
    particle set at the end of the step divided by σ² of the tracking dynamics for that
    parameter (DPS §3.1), as PF trackers report it. Frames with NaN are ignored; leading
    axes (e.g. runs) are averaged too. Values may exceed 100 %.

    Parameters
    ----------
    effective_dynamics : array_like of shape (..., T, K), or (..., T, K, C) with
        ``components=True`` (one column per parameter, e.g. C = 2 for u and v)
    components : bool
        Whether the last axis holds parameters.

    Returns
    -------
    ndarray of shape (K,) or (K, C)
        Mean in percent; NaN where no frame is finite.

    Raises
    ------
    ValueError
        If ``effective_dynamics`` has fewer than 2 axes (3 with ``components=True``).
    """
    e = np.asarray(effective_dynamics, dtype=np.float64)
    tail = 2 if components else 1
    if e.ndim < tail + 1:
        raise ValueError(
            f"effective_dynamics must have at least {tail + 1} axes, got shape {e.shape}"
        )
    return 100.0 * _nanmean0(e.reshape(-1, *e.shape[e.ndim - tail:]))


def _nanmean0(a: FloatArray) -> FloatArray:
    finite = np.isfinite(a)
    n = finite.sum(axis=0)
    s = np.where(finite, a, 0.0).sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 0, s / np.maximum(n, 1), np.nan)


@dataclass(frozen=True)
class OtbCurves:
    """OTB success and precision curves of one or more runs.

    Attributes
    ----------
    overlap_thresholds : ndarray of shape (S,)
        IoU thresholds, 0 to 1.
    success : ndarray of shape (S,)
        Fraction of evaluated frames with IoU > threshold.
    auc : float
        Area under the success curve (its mean over the thresholds).
    error_thresholds : ndarray of shape (P,)
        Centre-error thresholds in pixels, 0 to 50.
    precision : ndarray of shape (P,)
        Fraction of evaluated frames with centre error ≤ threshold.
    precision_20 : float
        Precision at 20 px.
    """

    overlap_thresholds: FloatArray
    success: FloatArray
    auc: float
    error_thresholds: FloatArray
    precision: FloatArray
    precision_20: float


_MAX_OVERLAP_THRESHOLDS = 10001
_MAX_ERROR = 2 * MAX_SIDE  # pixels: beyond the diagonal of the largest frame


def _pixels(value: Any, name: str, upper: float) -> float:
    """``value`` as a float in [0, upper] (a real number, not a bool, finite); else
    ValueError naming ``name`` and the value."""
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(
        value, (bool, np.bool_)) and math.isfinite(value) and 0 <= value <= upper  # fmt: skip
    if not ok:
        bound = f"in [0, {upper:g}]" if math.isfinite(upper) else ">= 0 and finite"
        raise ValueError(f"{name} must be a number {bound}, pixels, got {value!r}")
    return float(value)


def otb_curves(
    est: ArrayLike,
    gt: ArrayLike,
    *,
    n_overlap: int = 21,
    max_error: float = 50.0,
    precision_at: float = 20.0,
) -> OtbCurves:
    """OTB success curve with its AUC, and the precision curve with precision at 20 px.

    Frames where the ground truth is missing are left out; a missing estimate on a frame
    with ground truth counts as IoU 0 and an infinite centre error. Following the OTB
    toolkit, a frame succeeds at threshold θ when IoU > θ, the overlap thresholds are
    ``n_overlap`` evenly spaced values in [0, 1] (21 in OTB: 0, 0.05, …, 1) and the AUC is
    the mean of the success curve.

    Parameters
    ----------
    est, gt : array_like of shape (..., 4)
        Estimated and ground-truth boxes (any leading axes, e.g. (T, K) or (R, T)).
    n_overlap : int
        Number of overlap thresholds, 2 … 10001 (a step of 0.0001, finer than any AUC is
        reported; each threshold is compared with every frame, so more only costs memory).
    max_error : float
        Largest centre-error threshold, pixels, 0 … 16384; thresholds are the whole pixels
        0, 1, …, up to ``max_error`` (51 values, 0 … 50, by default, as in OTB). The bound
        is twice the largest frame side (:data:`scenegen.config.limits.MAX_SIDE`), beyond
        the diagonal of any frame, so no threshold that tells two runs apart is left out;
        each threshold is compared with every frame, so a larger one would only cost memory.
    precision_at : float
        Centre-error threshold of the headline precision, pixels (finite, ≥ 0: a missing
        estimate's error is infinite).

    Returns
    -------
    OtbCurves

    Raises
    ------
    ValueError
        For ``est`` and ``gt`` of different shapes, or ``n_overlap``, ``max_error`` or
        ``precision_at`` not a number in its range above (a bool is not one); the message
        names the parameter and its value.
    """
    if (isinstance(n_overlap, bool) or not isinstance(n_overlap, (int, np.integer))
            or not 2 <= n_overlap <= _MAX_OVERLAP_THRESHOLDS):  # fmt: skip
        raise ValueError(
            f"n_overlap must be an integer in [2, {_MAX_OVERLAP_THRESHOLDS}], got {n_overlap!r}"
        )
    _pixels(max_error, "max_error", _MAX_ERROR)
    _pixels(precision_at, "precision_at", math.inf)
    e, g = _boxes(est), _boxes(gt)
    if e.shape != g.shape:  # a broadcast would score one box against every frame
        raise ValueError(f"est has shape {e.shape} and gt {g.shape}: one box per frame each")
    has_gt = np.all(np.isfinite(g), axis=-1)
    ov = np.nan_to_num(iou(e, g), nan=0.0)[has_gt]
    err = np.nan_to_num(centre_error(e, g), nan=np.inf)[has_gt]
    ths = np.linspace(0.0, 1.0, n_overlap)
    eths = np.arange(0.0, np.floor(float(max_error)) + 1.0, 1.0)
    if ov.size == 0:
        success = np.full(ths.shape, np.nan)
        precision = np.full(eths.shape, np.nan)
        p20 = float("nan")
    else:
        success = np.mean(ov[None, :] > ths[:, None], axis=1)
        precision = np.mean(err[None, :] <= eths[:, None], axis=1)
        p20 = float(np.mean(err <= precision_at))
    return OtbCurves(
        overlap_thresholds=ths,
        success=success,
        auc=float(np.mean(success)),
        error_thresholds=eths,
        precision=precision,
        precision_20=p20,
    )


def failure_frame(error: ArrayLike, threshold: float, *, persist: int = 10) -> int:
    """Frame at which a run fails (KAMS §3.1, docs/algorithms.md §5), or -1 if it never does.

    (open) A run "fails when the error stays above a threshold". Here it fails at the first
    frame t that starts ``persist`` consecutive frames whose error is above ``threshold``
    (a NaN error, i.e. a missing estimate, counts as above). A stretch above the threshold
    shorter than ``persist`` frames is a transient, not a failure, even at the very end of
    the sequence. ``persist = 1`` fails at the first frame above. The default, 10 frames
    (0.4 s at 25 fps, 7 % of a KAMS sequence), lets a tracker that drifts off for a few
    frames and comes back keep its run, as the KAMS paper's "tracks the sequence" does.

    Parameters
    ----------
    error : array_like of shape (T,)
        Centre error per frame, pixels.
    threshold : float
        Error above which the target is lost (e.g. the target radius), pixels.
    persist : int
        Frames the error must stay above the threshold (≥ 1).

    Returns
    -------
    int
        The failure frame, or -1.

    Raises
    ------
    ValueError
        If ``error`` is not 1-D or ``persist`` is not an integer ≥ 1.
    """
    e = np.asarray(error, dtype=np.float64)
    if e.ndim != 1:
        raise ValueError(f"error must have shape (T,), got {e.shape}")
    persist = _count(persist, "persist")
    above = ~(e <= threshold)
    run = 0
    for t, a in enumerate(above):
        run = run + 1 if a else 0
        if run == persist:
            return t - persist + 1
    return -1


def tracked_fraction(error: ArrayLike, threshold: float, *, persist: int = 10) -> float:
    """Proportion of the sequence tracked before failure: failure frame / T, or 1.

    Used as the KAMS robustness score in :func:`mcnemar_counts`.

    Parameters
    ----------
    error : array_like of float, shape (T,)
        Centre error per frame, pixels (NaN, a missing estimate, counts as above).
    threshold : float
        Error above which the target is lost, pixels.
    persist : int
        Frames the error must stay above the threshold (≥ 1); see :func:`failure_frame`.

    Returns
    -------
    float
        Tracked proportion in [0, 1]; 1 if the run never fails.

    Raises
    ------
    ValueError
        If ``error`` is not 1-D or ``persist`` is not an integer ≥ 1.
    """
    e = np.asarray(error, dtype=np.float64)
    f = failure_frame(e, threshold, persist=persist)
    return 1.0 if f < 0 else f / e.shape[0]


def mcnemar_counts(score_a: ArrayLike, score_b: ArrayLike) -> tuple[int, int]:
    """Discordant pair counts (N_sf, N_fs) of trackers A and B over paired cases (KAMS §3.2).

    Following the KAMS paper, in each case the tracker that keeps tracking for the larger
    proportion of the sequence succeeds and the other fails; equal proportions are a
    concordant pair (both succeed).

    Parameters
    ----------
    score_a, score_b : array_like of shape (n,)
        Tracked proportion per case (e.g. :func:`tracked_fraction`).

    Returns
    -------
    n_sf, n_fs : int
        Cases where A succeeded and B failed, and the reverse.

    Raises
    ------
    ValueError
        If the scores are not two 1-D arrays of the same length.
    """
    a = np.asarray(score_a, dtype=np.float64)
    b = np.asarray(score_b, dtype=np.float64)
    if a.shape != b.shape or a.ndim != 1:
        raise ValueError(f"scores must be two (n,) arrays, got {a.shape} and {b.shape}")
    return int(np.sum(a > b)), int(np.sum(a < b))


@dataclass(frozen=True)
class McNemar:
    """McNemar's statistic: ``chi2`` (eq. 9) and the signed ``z`` score (eq. 10).

    Attributes
    ----------
    chi2 : float
        Continuity-corrected χ² (≥ 0).
    z : float
        Signed z score; z > 0 means tracker A is more robust than B.
    """

    chi2: float
    z: float


def mcnemar(n_sf: int, n_fs: int) -> McNemar:
    """McNemar χ² and z for matched pairs (KAMS eq. 9–10).

    χ² = (|N_sf − N_fs| − 1)² / (N_sf + N_fs), z = (|N_sf − N_fs| − 1) / sqrt(N_sf + N_fs).
    The continuity-corrected difference is clipped at 0 (no evidence either way when the
    counts are equal), and z carries the sign of N_sf − N_fs so that z > 0 means A is more
    robust than B. With no discordant pairs both are 0.

    Parameters
    ----------
    n_sf, n_fs : int
        Cases where A succeeded and B failed, and the reverse (≥ 0), e.g. from
        :func:`mcnemar_counts`.

    Returns
    -------
    McNemar
        ``chi2`` and ``z``.

    Raises
    ------
    ValueError
        If a count is negative.

    Examples
    --------
    >>> m = mcnemar(10, 2)
    >>> round(m.chi2, 4), round(m.z, 4)
    (4.0833, 2.0207)
    """
    if n_sf < 0 or n_fs < 0:
        raise ValueError(f"counts must be >= 0, got {n_sf}, {n_fs}")
    n = n_sf + n_fs
    if n == 0:
        return McNemar(0.0, 0.0)
    d = max(abs(n_sf - n_fs) - 1, 0)
    sign = 1.0 if n_sf >= n_fs else -1.0
    return McNemar(chi2=d * d / n, z=sign * d / float(np.sqrt(n)))


@dataclass(frozen=True)
class ClearMot:
    """CLEAR MOT scores (Bernardin & Stiefelhagen 2008).

    Attributes
    ----------
    mota : float
        1 − (FN + FP + IDSW) / n_gt.
    motp : float
        Mean IoU of the matched pairs (overlap form of MOTP; higher is better).
    n_gt, matches, fn, fp, idsw : int
        Ground-truth objects over all frames, matched pairs, misses, false positives,
        identity switches.
    """

    mota: float
    motp: float
    n_gt: int
    matches: int
    fn: int
    fp: int
    idsw: int


def _present(b: FloatArray) -> NDArray[np.bool_]:
    return np.all(np.isfinite(b), axis=-1)


def _check_tracks(gt: ArrayLike, est: ArrayLike) -> tuple[FloatArray, FloatArray]:
    g, e = _boxes(gt), _boxes(est)
    if g.ndim != 3 or e.ndim != 3 or g.shape[0] != e.shape[0]:
        raise ValueError(
            f"gt and est must have shapes (T, K, 4) and (T, M, 4), got {g.shape} and {e.shape}"
        )
    return g, e


def clear_mot(gt: ArrayLike, est: ArrayLike, *, iou_threshold: float = 0.5) -> ClearMot:
    """CLEAR MOT: MOTA and MOTP with IoU matching, computed as TrackEval does.

    Per frame the Hungarian algorithm maximises first the number of objects that keep
    their hypothesis of the previous frame, then the summed IoU, among pairs with IoU ≥
    ``iou_threshold``. A ground-truth object matched to a different hypothesis than at its
    last match is an identity switch. See :func:`scenegen.evaluation.mot.clear` (which
    also gives MT/PT/ML and Frag).

    Parameters
    ----------
    gt : array_like of shape (T, K, 4)
        Ground-truth boxes, NaN where the object is absent.
    est : array_like of shape (T, M, 4)
        Hypothesis boxes (track j is column j), NaN where there is none.
    iou_threshold : float
        Smallest IoU of a match, in (0, 1].

    Returns
    -------
    ClearMot
        MOTA is NaN when there is no ground-truth object at all, MOTP when nothing matches.

    Raises
    ------
    ValueError
        If ``gt`` and ``est`` are not of shapes (T, K, 4) and (T, M, 4) with the same T,
        or ``iou_threshold`` is not in (0, 1].
    """
    g, e = _check_tracks(gt, est)
    mot.check_threshold(iou_threshold)
    c = mot.clear(mot.mot_frames(g, e), threshold=iou_threshold)
    n_gt = c.tp + c.fn
    return ClearMot(
        mota=c.mota if n_gt else float("nan"),
        motp=c.motp if c.tp else float("nan"),
        n_gt=n_gt,
        matches=c.tp,
        fn=c.fn,
        fp=c.fp,
        idsw=c.idsw,
    )


def idf1(gt: ArrayLike, est: ArrayLike, *, iou_threshold: float = 0.5) -> float:
    """IDF1 (Ristani et al. 2016): identity F1 under the best one-to-one track matching.

    Each ground-truth trajectory is matched to at most one hypothesis trajectory so as to
    minimise IDFN + IDFP (the identity true positives IDTP are the frames where both
    exist with IoU ≥ ``iou_threshold``), by the Hungarian algorithm, as TrackEval does
    (:func:`scenegen.evaluation.mot.identity`). IDF1 = 2·IDTP / (ground-truth detections +
    hypothesis detections).

    Parameters
    ----------
    gt : array_like of shape (T, K, 4)
        Ground-truth boxes, NaN where the object is absent.
    est : array_like of shape (T, M, 4)
        Hypothesis boxes (track j is column j), NaN where there is none.
    iou_threshold : float
        Smallest IoU of a match, in (0, 1].

    Returns
    -------
    float
        IDF1 in [0, 1]; NaN when there are no detections on either side (0 when only one
        side has none).

    Raises
    ------
    ValueError
        If ``gt`` and ``est`` are not of shapes (T, K, 4) and (T, M, 4) with the same T,
        or ``iou_threshold`` is not in (0, 1].
    """
    mot.check_threshold(iou_threshold)
    g, e = _check_tracks(gt, est)
    if int(_present(g).sum()) + int(_present(e).sum()) == 0:
        return float("nan")
    return mot.identity(mot.mot_frames(g, e), threshold=iou_threshold).idf1


def ordering_index(depth: ArrayLike, orderings: ArrayLike) -> NDArray[np.intp]:
    """Index of the true depth ordering per frame, for SHM's ordering probabilities.

    Parameters
    ----------
    depth : array_like of int, shape (T, M)
        Depth rank of each target per frame (0 = nearest), e.g. ``gt.depth`` of the targets.
    orderings : array_like of int, shape (L, M)
        Each row lists target positions (indices into M), nearest first.

    Returns
    -------
    ndarray of int, shape (T,)
        Row of ``orderings`` equal to the targets sorted nearest first (ties keep target
        order), or -1 where no row matches.

    Raises
    ------
    ValueError
        If ``depth`` and ``orderings`` are not 2-D with the same number of targets M.
    """
    d = np.asarray(depth)
    o = np.asarray(orderings)
    if d.ndim != 2 or o.ndim != 2 or o.shape[1] != d.shape[1]:
        raise ValueError(f"depth (T, M) and orderings (L, M) disagree: {d.shape}, {o.shape}")
    true = np.argsort(d, axis=1, kind="stable")
    eq = np.all(true[:, None, :] == o[None, :, :], axis=2)
    return np.where(eq.any(axis=1), np.argmax(eq, axis=1), -1)


def overlap_fraction(a: ArrayLike, b: ArrayLike) -> FloatArray:
    """Intersection area over the smaller box's area (broadcast, (..., 4) each); 0 if none.

    "None" covers a missing box on either side and a smaller box of zero area.

    Parameters
    ----------
    a, b : array_like of float, shape (..., 4)
        Boxes ``[x, y, w, h]``, pixels; NaN for a missing box.

    Returns
    -------
    ndarray of float, shape (...)
        Overlap fraction in [0, 1].

    Raises
    ------
    ValueError
        If the last axis of ``a`` or ``b`` is not of length 4.
    """
    inter = np.nan_to_num(intersection_area(a, b), nan=0.0)
    small = np.nan_to_num(np.minimum(box_area(a), box_area(b)), nan=0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(small > 0, inter / np.where(small > 0, small, 1.0), 0.0)


def overlapping_pairs(boxes: ArrayLike, *, min_overlap: float = 0.1) -> NDArray[np.bool_]:
    """Which pairs of distinct targets overlap, per frame: the depth-order criterion.

    (open) Two boxes "overlap" when their intersection covers at least ``min_overlap`` of
    the smaller box's area: a grazing contact of a few pixels says nothing about depth.

    Parameters
    ----------
    boxes : array_like of shape (T, M, 4)
        Boxes of the targets (NaN where absent: an absent box overlaps nothing).
    min_overlap : float
        Smallest intersection / smaller-box area that counts, in (0, 1].

    Returns
    -------
    ndarray of bool, shape (T, M, M)
        Symmetric, False on the diagonal.

    Raises
    ------
    ValueError
        If ``min_overlap`` is not in (0, 1], or the last axis of ``boxes`` is not of
        length 4.
    """
    if not 0.0 < min_overlap <= 1.0:
        raise ValueError(f"min_overlap must be in (0, 1], got {min_overlap}")
    b = _boxes(boxes)
    over = overlap_fraction(b[:, :, None, :], b[:, None, :, :])
    return (over >= min_overlap) & ~np.eye(b.shape[1], dtype=bool)


def depth_order_accuracy(
    order_prob: ArrayLike,
    orderings: ArrayLike,
    depth: ArrayLike,
    boxes: ArrayLike,
    *,
    min_overlap: float = 0.1,
) -> float:
    """Percentage of overlapping target pairs whose depth order the MAP ordering gets right.

    Depth order is only observable where targets overlap (SHM §5: non-overlapping objects
    give identical measurements under every ordering), so the score counts, over frames
    and unordered target pairs whose ground-truth boxes overlap, how often the most
    probable ordering puts the pair in the true front/back order. "Overlap" is
    :func:`overlapping_pairs` (at least ``min_overlap`` of the smaller box). Frames whose
    probabilities are NaN (frame 0) are skipped.

    Parameters
    ----------
    order_prob : array_like of shape (T, L)
        P(ordering) per frame.
    orderings : array_like of int, shape (L, M)
        Target positions, nearest first.
    depth : array_like of int, shape (T, M)
        True depth rank per target (0 = nearest).
    boxes : array_like of shape (T, M, 4)
        Ground-truth boxes of the targets (NaN where absent).
    min_overlap : float
        Smallest intersection / smaller-box area of a pair that counts, in (0, 1].

    Returns
    -------
    float
        Accuracy in percent; NaN if no pair ever overlaps.

    Raises
    ------
    ValueError
        If the shapes disagree (T, L and M as above) or ``min_overlap`` is not in (0, 1].
    """
    p = np.asarray(order_prob, dtype=np.float64)
    o = np.asarray(orderings)
    d = np.asarray(depth)
    b = _boxes(boxes)
    t_n, m_n = d.shape
    if p.shape[0] != t_n or b.shape[:2] != (t_n, m_n) or o.shape[1] != m_n:
        raise ValueError(
            f"shapes disagree: order_prob {p.shape}, orderings {o.shape}, depth {d.shape}, "
            f"boxes {b.shape}"
        )
    rank = np.argsort(o, axis=1)  # rank[l, m]: position of target m in ordering l
    pairs = overlapping_pairs(b, min_overlap=min_overlap)
    right = total = 0
    for t in range(t_n):
        if not np.all(np.isfinite(p[t])):
            continue
        best = rank[int(np.argmax(p[t]))]
        for i in range(m_n):
            for j in range(i + 1, m_n):
                if pairs[t, i, j] and d[t, i] != d[t, j]:
                    total += 1
                    right += int((best[i] < best[j]) == (d[t, i] < d[t, j]))
    return 100.0 * right / total if total else float("nan")
