"""scenegen.evaluation.mot against brute-force references of TrackEval's definitions.

The mutation run of the module (``tools/mutation/mutate.py mot``) found these cases
unguarded. The references below are written from TrackEval's ``clear.py``,
``identity.py``, ``hota.py`` and the MOTChallenge preprocessing (``mot_challenge_2d_box.py``)
with plain Python loops: scalar IoU, matchings found by trying every assignment instead of
the Hungarian algorithm, counters keyed by the columns of the box arrays instead of
relabelled ids. They never call the module under test. Scenes are drawn from fixed seeds
with continuous coordinates, so no two matchings tie; ties, exact thresholds and empty
sides have hand-worked cases of their own.
"""

from __future__ import annotations

import math
from collections import Counter
from itertools import permutations

import numpy as np
import pytest

from scenegen.evaluation.mot import (
    HOTA_ALPHAS,
    MotFrames,
    box_iou,
    clear,
    hota,
    identity,
    mot_frames,
    remove_distractor_matches,
    score_all,
)

EPS = float(np.finfo("float").eps)
ALPHAS = np.arange(0.05, 0.99, 0.05)  # TrackEval's HOTA array_labels
TOL = 1e-12


# --- references ----------------------------------------------------------------------


def _iou(a, b) -> float:
    """TrackEval's box IoU of two [x, y, w, h] boxes (zero area or union: 0)."""
    ax0, ay0, ax1, ay1 = a[0], a[1], a[0] + a[2], a[1] + a[3]
    bx0, by0, bx1, by1 = b[0], b[1], b[0] + b[2], b[1] + b[3]
    inter = max(min(ax1, bx1) - max(ax0, bx0), 0) * max(min(ay1, by1) - max(ay0, by0), 0)
    area_a = (ax1 - ax0) * (ay1 - ay0)
    area_b = (bx1 - bx0) * (by1 - by0)
    union = area_a + area_b - inter
    if area_a <= EPS or area_b <= EPS or union <= EPS:
        return 0.0
    return inter / union


def _best(score: list[list[float]]) -> list[tuple[int, int]]:
    """A full assignment (min(n, m) pairs) of largest total ``score``, by trying all."""
    n = len(score)
    m = len(score[0]) if n else 0
    best, arg = -math.inf, []
    if n <= m:
        for perm in permutations(range(m), n):
            s = sum(score[i][perm[i]] for i in range(n))
            if s > best + 1e-9:
                best, arg = s, [(i, perm[i]) for i in range(n)]
    else:
        for perm in permutations(range(n), m):
            s = sum(score[perm[j]][j] for j in range(m))
            if s > best + 1e-9:
                best, arg = s, [(perm[j], j) for j in range(m)]
    return arg


def _frames(gt, est, rank=None):
    """Per frame: present ground-truth columns, present tracker columns (in ``rank``
    order if given), and their IoU matrix as lists."""
    out = []
    for t in range(gt.shape[0]):
        g = [k for k in range(gt.shape[1]) if np.all(np.isfinite(gt[t, k]))]
        h = [j for j in range(est.shape[1]) if np.all(np.isfinite(est[t, j]))]
        if rank is not None:
            h.sort(key=lambda j: rank[t][j])
        out.append((g, h, [[_iou(gt[t, k], est[t, j]) for j in h] for k in g]))
    return out


def ref_clear(gt, est, threshold=0.5):
    frames = _frames(gt, est)
    n_gt = sum(len(g) for g, _, _ in frames)
    n_trk = sum(len(h) for _, h, _ in frames)
    n_ids = len({k for g, _, _ in frames for k in g})
    r = dict(tp=0, fn=0, fp=0, idsw=0, mt=0, pt=0, ml=0, frag=0, mota=0.0, motp=0.0,
             moda=0.0)  # fmt: skip
    if n_trk == 0:
        return {**r, "fn": n_gt, "ml": n_ids}
    if n_gt == 0:
        return {**r, "fp": n_trk}
    last = {}       # object -> track of its last match
    step = {}       # object -> track it was matched to in the last scored frame
    seen, tracked, starts = Counter(), Counter(), Counter()
    tp = fn = fp = idsw = 0
    motp = 0.0
    for g, h, s in frames:
        if not g:
            fp += len(h)
            continue
        if not h:
            fn += len(g)
            seen.update(g)
            continue
        score = [[0.0 if s[i][j] < threshold - EPS else 1000.0 * (step.get(g[i]) == h[j])
                  + s[i][j] for j in range(len(h))] for i in range(len(g))]  # fmt: skip
        pairs = [(i, j) for i, j in _best(score) if score[i][j] > EPS]
        new = {}
        for i, j in pairs:
            k = g[i]
            if k in last and last[k] != h[j]:
                idsw += 1
            last[k] = h[j]
            new[k] = h[j]
            if k not in step:
                starts[k] += 1
            tracked[k] += 1
            motp += s[i][j]
        step = new
        seen.update(g)
        tp += len(pairs)
        fn += len(g) - len(pairs)
        fp += len(h) - len(pairs)
    ratios = [tracked[k] / seen[k] for k in seen]
    mt = sum(q > 0.8 for q in ratios)
    pt = sum(0.2 <= q <= 0.8 for q in ratios)
    return dict(tp=tp, fn=fn, fp=fp, idsw=idsw, mt=mt, pt=pt, ml=n_ids - mt - pt,
                frag=sum(c - 1 for c in starts.values()),
                mota=(tp - fp - idsw) / max(1, tp + fn), motp=motp / max(1, tp),
                moda=(tp - fp) / max(1, tp + fn))  # fmt: skip


def ref_identity(gt, est, threshold=0.5):
    frames = _frames(gt, est)
    n_gt = sum(len(g) for g, _, _ in frames)
    n_trk = sum(len(h) for _, h, _ in frames)
    objs = sorted({k for g, _, _ in frames for k in g})
    trks = sorted({j for _, h, _ in frames for j in h})
    both = Counter()
    for g, h, s in frames:
        for i, k in enumerate(g):
            for j, c in enumerate(h):
                if s[i][j] >= threshold:
                    both[k, c] += 1
    # minimising IDFN + IDFP = maximising the frames the matched pairs share
    idtp = 0
    if objs and trks:
        pairs = _best([[both[k, c] for c in trks] for k in objs])
        idtp = sum(both[objs[i], trks[j]] for i, j in pairs)
    idfn, idfp = n_gt - idtp, n_trk - idtp
    return dict(idtp=idtp, idfn=idfn, idfp=idfp,
                idf1=idtp / max(1, idtp + 0.5 * idfp + 0.5 * idfn),
                idp=idtp / max(1, idtp + idfp), idr=idtp / max(1, idtp + idfn))  # fmt: skip


def ref_hota(gt, est, rank=None):
    frames = _frames(gt, est, rank)
    n_a = len(ALPHAS)
    if not sum(len(g) for g, _, _ in frames) or not sum(len(h) for _, h, _ in frames):
        z = [0.0] * n_a
        return dict(hota=0.0, deta=0.0, assa=0.0, loca=1.0, detre=0.0, detpr=0.0, assre=0.0,
                    asspr=0.0, hota_alpha=z, deta_alpha=z, assa_alpha=z,
                    loca_alpha=[1.0] * n_a)  # fmt: skip
    pot, gc, hc = Counter(), Counter(), Counter()
    for g, h, s in frames:
        rows = [sum(r) for r in s]
        cols = [sum(s[i][j] for i in range(len(g))) for j in range(len(h))]
        for i, k in enumerate(g):
            for j, c in enumerate(h):
                den = rows[i] + cols[j] - s[i][j]
                if den > EPS:
                    pot[k, c] += s[i][j] / den
        gc.update(g)
        hc.update(h)

    def align(k, c):
        return pot[k, c] / (gc[k] + hc[c] - pot[k, c])

    tp, fn, fp, loc = [0] * n_a, [0] * n_a, [0] * n_a, [0.0] * n_a
    matches = [Counter() for _ in range(n_a)]
    for g, h, s in frames:
        if not g or not h:
            for a in range(n_a):
                fp[a] += len(h) if not g else 0
                fn[a] += len(g) if not h else 0
            continue
        pairs = _best([[align(k, c) * s[i][j] for j, c in enumerate(h)]
                       for i, k in enumerate(g)])  # fmt: skip
        for a, alpha in enumerate(ALPHAS):
            ok = [(i, j) for i, j in pairs if s[i][j] >= alpha - EPS]
            tp[a] += len(ok)
            fn[a] += len(g) - len(ok)
            fp[a] += len(h) - len(ok)
            for i, j in ok:
                loc[a] += s[i][j]
                matches[a][g[i], h[j]] += 1
    out = {k: [] for k in ("hota", "deta", "assa", "loca", "detre", "detpr", "assre", "asspr")}
    for a in range(n_a):
        mc = matches[a]
        assa = sum(c * c / max(1, gc[k] + hc[t] - c) for (k, t), c in mc.items()) / max(1, tp[a])
        assre = sum(c * c / max(1, gc[k]) for (k, t), c in mc.items()) / max(1, tp[a])
        asspr = sum(c * c / max(1, hc[t]) for (k, t), c in mc.items()) / max(1, tp[a])
        deta = tp[a] / max(1, tp[a] + fn[a] + fp[a])
        out["hota"].append(math.sqrt(deta * assa))
        out["deta"].append(deta)
        out["assa"].append(assa)
        out["loca"].append(max(1e-10, loc[a]) / max(1e-10, tp[a]))
        out["detre"].append(tp[a] / max(1, tp[a] + fn[a]))
        out["detpr"].append(tp[a] / max(1, tp[a] + fp[a]))
        out["assre"].append(assre)
        out["asspr"].append(asspr)
    res = {k: float(np.mean(v)) for k, v in out.items()}
    res.update({f"{k}_alpha": out[k] for k in ("hota", "deta", "assa", "loca")})
    return res


def ref_keep(gt, distractor, est, rank=None):
    """MOTChallenge's preprocessing: tracker boxes matched (IoU >= 0.5) to a distractor
    row by the best assignment are dropped."""
    dis = np.broadcast_to(np.asarray(distractor, dtype=bool), gt.shape[:2])
    keep = np.ones(est.shape[:2], dtype=bool)
    for t, (g, h, s) in enumerate(_frames(gt, est, rank)):
        if not g or not h:
            continue
        score = [[v if v >= 0.5 - EPS else 0.0 for v in row] for row in s]
        for i, j in _best(score):
            if score[i][j] > EPS and dis[t, g[i]]:
                keep[t, h[j]] = False
    return keep


# --- scenes ----------------------------------------------------------------------------


def _scene(seed: int, n_frames: int = 8, n_obj: int = 3, n_trk: int = 3):
    """Objects moving near one another (so boxes overlap and matchings compete) and
    tracks that follow one object each, with noise, switching objects now and then;
    boxes missing at random, and one frame without ground truth or without tracks."""
    rng = np.random.default_rng(seed)
    pos = rng.uniform(0, 30, (n_obj, 2))
    vel = rng.uniform(-3, 3, (n_obj, 2))
    size = rng.uniform(8, 16, (n_obj, 2))
    t = np.arange(n_frames)[:, None, None]
    truth = np.concatenate([pos + t * vel, np.broadcast_to(size, (n_frames, n_obj, 2))], -1)
    src = np.empty((n_frames, n_trk), dtype=int)
    src[0] = rng.integers(0, n_obj, n_trk)
    for f in range(1, n_frames):
        switch = rng.random(n_trk) < 0.2
        src[f] = np.where(switch, rng.integers(0, n_obj, n_trk), src[f - 1])
    est = truth[np.arange(n_frames)[:, None], src].copy()
    est[..., :2] += rng.normal(0, 2.0, (n_frames, n_trk, 2))
    est[..., 2:] *= rng.uniform(0.7, 1.3, (n_frames, n_trk, 2))
    gt = truth.copy()
    gt[rng.random((n_frames, n_obj)) < 0.2] = np.nan
    est[rng.random((n_frames, n_trk)) < 0.2] = np.nan
    kind = seed % 3
    if kind == 1:
        gt[rng.integers(n_frames)] = np.nan
    elif kind == 2:
        est[rng.integers(n_frames)] = np.nan
    return gt, est


SHAPES = [(8, 3, 3), (7, 2, 4), (7, 4, 2), (6, 3, 2)]
SCENES = [_scene(seed, *SHAPES[seed % 4]) for seed in range(48)]


def _box(x, y, w=10.0, h=10.0):
    return [x, y, w, h]


def _seq(*frames, n_cols=None):
    """(T, K, 4) from per-frame lists of boxes (None: absent)."""
    n_cols = n_cols or max(len(f) for f in frames)
    out = np.full((len(frames), n_cols, 4), np.nan)
    for t, f in enumerate(frames):
        for k, b in enumerate(f):
            if b is not None:
                out[t, k] = b
    return out


# Small sequences at the edges of the formulas: one detection, no match, exact thresholds.
NAN = None
TINY = [
    (_seq([_box(0, 0)]), _seq([_box(0, 0)])),                     # one perfect match
    (_seq([_box(0, 0)]), _seq([_box(0, 0, 10, 5)])),              # one match at IoU 0.5
    (_seq([_box(0, 0)]), _seq([_box(0, 0, 10, 6)])),              # IoU 0.6 exactly
    (_seq([_box(0, 0, 1, 1)]), _seq([_box(0, 0, 1, 2 + 2.0**-50)])),  # IoU 0.5 - eps
    (_seq([_box(0, 0)]), _seq([_box(50, 0)])),                    # one FP and one FN
    (_seq([_box(0, 0)], [NAN]), _seq([NAN], [_box(0, 0)])),       # sides in other frames
    (_seq([_box(0, 0)], [_box(0, 0)]), _seq([_box(0, 0)], [_box(3, 0)])),
    (_seq([_box(0, 0), _box(4, 0)]), _seq([_box(1, 0), _box(30, 0)])),
    (_seq([_box(0, 0)], [_box(1, 0)], [_box(2, 0)]),
     _seq([_box(0, 0), NAN], [NAN, _box(1, 0)], [_box(2, 0), NAN])),
]


def _assert_fields(got, ref, what):
    for name, want in ref.items():
        value = getattr(got, name)
        np.testing.assert_allclose(np.asarray(value, dtype=float), want, rtol=0, atol=TOL,
                                   err_msg=f"{what}: {name}")  # fmt: skip


# --- tests -----------------------------------------------------------------------------


@pytest.mark.parametrize("threshold", [0.3, 0.5, 0.7])
def test_clear_equals_the_reference_on_drawn_scenes(threshold):
    for n, (gt, est) in enumerate(SCENES + TINY):
        ref = ref_clear(gt, est, threshold)
        _assert_fields(clear(mot_frames(gt, est), threshold=threshold), ref, f"scene {n}")


@pytest.mark.parametrize("threshold", [0.3, 0.5, 0.7])
def test_identity_equals_the_reference_on_drawn_scenes(threshold):
    for n, (gt, est) in enumerate(SCENES + TINY):
        ref = ref_identity(gt, est, threshold)
        got = identity(mot_frames(gt, est), threshold=threshold)
        _assert_fields(got, ref, f"scene {n}")


def test_hota_equals_the_reference_on_drawn_scenes():
    assert np.array_equal(HOTA_ALPHAS, ALPHAS)
    for n, (gt, est) in enumerate(SCENES + TINY):
        _assert_fields(hota(mot_frames(gt, est)), ref_hota(gt, est), f"scene {n}")


def test_the_drawn_scenes_reach_every_branch():
    """The scenes are only useful if they make every kind of event happen."""
    refs = [ref_clear(gt, est) for gt, est in SCENES]
    for key in ("tp", "fn", "fp", "idsw", "mt", "pt", "ml", "frag"):
        assert sum(r[key] > 0 for r in refs) >= 5, key
    assert any(not np.isfinite(gt[t]).any() for gt, _ in SCENES for t in range(gt.shape[0]))
    assert any(not np.isfinite(e[t]).any() for _, e in SCENES for t in range(e.shape[0]))
    hs = [ref_hota(gt, est) for gt, est in SCENES[:12]]
    assert all(0 < h["assa"] < 1 and 0 < h["deta"] < 1 for h in hs)


def test_score_all_scores_each_metric_at_the_threshold():
    gt, est = SCENES[0]
    s = score_all(mot_frames(gt, est), threshold=0.3)
    _assert_fields(s.clear, ref_clear(gt, est, 0.3), "clear")
    _assert_fields(s.identity, ref_identity(gt, est, 0.3), "identity")
    _assert_fields(s.hota, ref_hota(gt, est), "hota")
    assert ref_clear(gt, est, 0.3) != ref_clear(gt, est, 0.5)
    s = score_all(mot_frames(gt, est))  # default threshold 0.5
    _assert_fields(s.clear, ref_clear(gt, est, 0.5), "clear")
    _assert_fields(s.identity, ref_identity(gt, est, 0.5), "identity")


def test_empty_sequences_score_as_trackeval():
    gt = _seq([_box(0, 0), _box(30, 0)], [_box(0, 0), NAN])
    none = np.full((2, 2, 4), np.nan)
    for a, b in ((gt, none), (none, gt), (none, none)):
        data = mot_frames(a, b)
        _assert_fields(clear(data), ref_clear(a, b), "clear")
        _assert_fields(identity(data), ref_identity(a, b), "identity")
        _assert_fields(hota(data), ref_hota(a, b), "hota")
    c = clear(mot_frames(gt, none))
    assert (c.fn, c.ml, c.mt, c.pt, c.tp, c.fp, c.idsw, c.frag) == (3, 2, 0, 0, 0, 0, 0, 0)
    i = identity(mot_frames(none, gt))
    assert (i.idtp, i.idfn, i.idfp, i.idf1) == (0, 0, 3, 0.0)
    h = hota(mot_frames(gt, none))
    assert h.detre == h.detpr == h.assre == h.asspr == 0.0 and h.loca == 1.0
    assert np.array_equal(h.loca_alpha, np.ones(19)) and not h.deta_alpha.any()


def test_one_tracker_detection_is_not_an_empty_side():
    gt = _seq([_box(0, 0)], [_box(0, 0)])
    est = _seq([_box(0, 0)], [NAN])
    h = hota(mot_frames(gt, est))
    # every threshold: TP 1, FN 1; AssA 0.5 (one match, Jaccard 1 / (2 + 1 - 1))
    assert h.deta == pytest.approx(0.5) and h.assa == pytest.approx(0.5)
    assert h.detre == pytest.approx(0.5) and h.detpr == 1.0 and h.loca == 1.0


def test_mot_frames_relabels_and_keeps_the_rank_order():
    gt = _seq([NAN, _box(0, 0), NAN, _box(40, 0)], [NAN, NAN, NAN, _box(41, 0)])
    est = _seq([NAN, _box(40, 0), _box(0, 0)], [NAN, _box(41, 0), NAN])
    d = mot_frames(gt, est)
    assert (d.n_gt_ids, d.n_tracker_ids, d.n_gt_dets, d.n_tracker_dets) == (2, 2, 3, 3)
    assert [x.tolist() for x in d.gt_ids] == [[0, 1], [1]]
    assert [x.tolist() for x in d.tracker_ids] == [[0, 1], [0]]
    np.testing.assert_allclose(d.similarity[0], [[0, 1], [1, 0]], atol=TOL)
    np.testing.assert_allclose(d.similarity[1], [[1]], atol=TOL)
    # rank: the rows' order in a tracker file (here track 1's row before track 0's)
    r = mot_frames(gt, est, est_rank=[[0, 7, 3], [0, 0, 0]])
    assert [x.tolist() for x in r.tracker_ids] == [[1, 0], [0]]
    np.testing.assert_allclose(r.similarity[0], [[1, 0], [0, 1]], atol=TOL)
    assert [x.tolist() for x in r.gt_ids] == [[0, 1], [1]]


def test_mot_frames_keep_masks_drop_detections():
    gt = _seq([_box(0, 0), _box(40, 0)], [_box(0, 0), _box(40, 0)])
    est = _seq([_box(0, 0), _box(40, 0)], [_box(0, 0), _box(40, 0)])
    d = mot_frames(gt, est, gt_keep=[[True, False], [False, False]],
                   est_keep=[[False, True], [True, True]])  # fmt: skip
    assert (d.n_gt_ids, d.n_tracker_ids, d.n_gt_dets, d.n_tracker_dets) == (1, 2, 1, 3)
    assert [x.tolist() for x in d.gt_ids] == [[0], []]
    assert [x.tolist() for x in d.tracker_ids] == [[1], [0, 1]]
    np.testing.assert_allclose(d.similarity[0], [[0.0]], atol=TOL)
    assert d.similarity[1].shape == (0, 2)


def test_mot_frames_without_tracks_or_objects():
    gt = _seq([_box(0, 0)], [_box(1, 0)])
    for est in (np.full((2, 3, 4), np.nan), np.zeros((2, 0, 4))):
        d = mot_frames(gt, est)
        assert (d.n_gt_ids, d.n_tracker_ids, d.n_tracker_dets) == (1, 0, 0)
        d = mot_frames(est, gt)
        assert (d.n_gt_ids, d.n_tracker_ids, d.n_gt_dets) == (0, 1, 0)


def test_mot_frames_rejects_arrays_that_disagree():
    ok = np.zeros((2, 1, 4))
    for gt, est in ((np.zeros((2, 4)), ok), (ok, np.zeros((2, 4))), (ok, np.zeros((3, 1, 4))),
                    (np.zeros((2, 1, 5)), ok), (ok, np.zeros((2, 1, 5))),
                    (np.zeros((2, 1, 4, 1)), ok)):
        with pytest.raises(ValueError, match="disagree"):
            mot_frames(gt, est)
        with pytest.raises(ValueError, match="disagree"):
            remove_distractor_matches(gt, np.zeros(1, dtype=bool), est)
    d = mot_frames(ok, np.zeros((2, 3, 4)))  # boxes of zero area are detections (IoU 0)
    assert (d.n_tracker_ids, d.n_tracker_dets) == (3, 6) and not np.any(d.similarity)


def test_threshold_is_keyword_only_and_frames_must_agree():
    gt, est = SCENES[0]
    d = mot_frames(gt, est)
    for f in (clear, identity, score_all):
        with pytest.raises(TypeError):
            f(d, 0.5)
    with pytest.raises(TypeError):
        mot_frames(gt, est, np.ones(gt.shape[:2], dtype=bool))
    short = MotFrames(d.gt_ids, d.tracker_ids[:-1], d.similarity, d.n_gt_ids, d.n_tracker_ids)
    for f in (clear, identity, hota):
        with pytest.raises(ValueError):
            f(short)


def test_box_iou_of_boxes_and_guards():
    a = [[0, 0, 10, 10], [0, 0, 0, 5], [2, 3, 4, 0]]
    b = [[5, 0, 10, 10], [0, 0, 10, 10], [10, 0, 5, 5], [0, 10, 10, 2], [-3, -2, 4, 5],
         [0, 0, 0, 5]]
    got = box_iou(a, b)
    assert got.shape == (3, 6)
    for i, x in enumerate(a):
        for j, y in enumerate(b):
            assert got[i, j] == pytest.approx(_iou(x, y), abs=TOL)
    assert got[0, 0] == pytest.approx(1 / 3) and got[0, 4] == pytest.approx(3 / 117)
    assert got[1, 5] == 0.0 and not np.isnan(got).any()  # zero areas, zero union
    # half a pixel apart in one direction, overlapping in the other: no intersection
    apart = box_iou([[0, 0, 10, 10]], [[10.5, 2, 5, 5], [2, 10.5, 5, 5], [-5.5, 2, 5, 5]])
    assert apart.tolist() == [[0.0, 0.0, 0.0]]
    # a box of area exactly eps counts as empty (TrackEval: area <= eps), on either side
    tiny = [[0, 0, 2.0**-26, 2.0**-26]]
    assert box_iou(tiny, [[0, 0, 1, 1]])[0, 0] == 0.0
    assert box_iou([[0, 0, 1, 1]], tiny)[0, 0] == 0.0
    assert box_iou([[0, 0, 2.0**-25, 2.0**-26]], [[0, 0, 1, 1]])[0, 0] == 2.0**-51
    assert box_iou([0, 0, 4, 6], [1, 2, 4, 6])[0, 0] == pytest.approx(12 / 36)


@pytest.mark.parametrize("seed", range(12))
def test_distractor_matches_equal_the_reference(seed):
    gt, est = SCENES[seed]
    rng = np.random.default_rng(100 + seed)
    dis = rng.random(gt.shape[:2]) < 0.5
    assert np.array_equal(remove_distractor_matches(gt, dis, est), ref_keep(gt, dis, est))
    dis1 = rng.random(gt.shape[1]) < 0.5
    assert np.array_equal(remove_distractor_matches(gt, dis1, est), ref_keep(gt, dis1, est))


def test_distractor_matching_edges():
    gt = _seq([_box(0, 0), _box(40, 0)], [NAN, _box(40, 0)], [_box(0, 0), NAN])
    # frame 0: IoU exactly 0.5 with the distractor -> matched, dropped; frame 1: IoU < 0.5
    # (0.45) -> kept; frame 2: no distractor in the frame -> kept; a frame without tracks
    est = _seq([_box(40, 0, 10, 5), _box(0, 0)], [_box(40, 0, 9, 5), NAN], [_box(0, 0), NAN])
    est = np.concatenate([est, np.full((1, 2, 4), np.nan)])
    gt = np.concatenate([gt, gt[:1]])
    keep = remove_distractor_matches(gt, [False, True], est)
    assert keep.tolist() == [[False, True], [True, True], [True, True], [True, True]]
    # The distractor overlaps track 0 most (IoU 0.905, track 1: 0.6), but the assignment
    # maximises the summed IoU: target-track 0 (0.818) + distractor-track 1 (0.6) beats
    # distractor-track 0 alone (target-track 1 is 0.43, below 0.5). Track 1 is dropped.
    gt = _seq([_box(0, 0), _box(1.5, 0)])
    est = _seq([_box(1, 0), _box(4, 0)])
    keep = remove_distractor_matches(gt, [False, True], est)
    ref = ref_keep(gt, [False, True], est)
    assert keep.tolist() == ref.tolist() == [[True, False]]
    # an empty ground truth or no tracker box at all: everything kept
    assert remove_distractor_matches(np.full((1, 1, 4), np.nan), [True], est).all()
    assert remove_distractor_matches(gt, [True, True], np.full((1, 2, 4), np.nan)).all()


def test_distractor_ties_go_to_the_row_first_in_the_file():
    gt = _seq([_box(0, 0)])
    est = _seq([_box(1, 0), _box(1, 0)])  # two identical tracker boxes, tied
    keep = remove_distractor_matches(gt, [True], est)
    assert keep.tolist() == [[False, True]]
    keep = remove_distractor_matches(gt, [True], est, est_rank=[[5, 2]])
    assert keep.tolist() == [[True, False]]


def test_clear_ties_follow_the_rank_order():
    # One object, two identical tracks in frame 0 and only track 1 in frame 1. CLEAR's
    # frame 0 is a tie, which the Hungarian algorithm gives to the first column: the row
    # first in the file. Matched to track 0, frame 1 is a switch; to track 1, it is not.
    gt = _seq([_box(0, 0)], [_box(0, 0)])
    est = _seq([_box(0, 0), _box(0, 0)], [NAN, _box(0, 0)])
    # HOTA has no tie: frame 0's IoU is split (1 / (1 + 2 - 1) = 0.5 to each track's
    # potential), track 1 adds frame 1, so its alignment (1.5 / 2.5) beats track 0's (0.2)
    for rank in (None, [[1, 0], [0, 0]]):
        assert hota(mot_frames(gt, est, est_rank=rank)).assa == pytest.approx(1.0)
    c0 = clear(mot_frames(gt, est))
    c1 = clear(mot_frames(gt, est, est_rank=[[1, 0], [0, 0]]))
    assert (c0.idsw, c1.idsw) == (1, 0)


# IoU exactly machine epsilon: a box of area 2^52 and a unit box inside it.
HUGE = _box(0, 0, 2.0**26, 2.0**26)
UNIT = _box(0, 0, 1, 1)


def test_a_pair_at_iou_epsilon_is_no_clear_match_but_an_identity_one():
    gt, est = _seq([HUGE]), _seq([UNIT])
    assert mot_frames(gt, est).similarity[0][0, 0] == EPS
    # CLEAR keeps pairs whose score exceeds eps (clear.py: score > 0 + eps), even when the
    # threshold lets the pair into the score matrix; Identity compares IoU >= threshold.
    c = clear(mot_frames(gt, est), threshold=1e-300)
    assert (c.tp, c.fn, c.fp) == (0, 1, 1)
    i = identity(mot_frames(gt, est), threshold=1e-300)
    assert (i.idtp, i.idfn, i.idfp) == (1, 0, 0)
    assert ref_clear(gt, est, 1e-300)["tp"] == 0 and ref_identity(gt, est, 1e-300)["idtp"] == 1


def test_hota_potential_ignores_a_denominator_of_epsilon():
    # Object A; tracks X and Y share frame 0 with it (IoU 1 each), Y then covers A at IoU
    # eps in frames 1-2, X covers it again in frame 3. sim_iou is only taken where its
    # denominator exceeds eps (here it equals eps), so Y's potential is 0.5 and X's 1.5:
    # alignment X 1.5 / (4 + 2 - 1.5) = 1/3 beats Y 0.5 / (4 + 3 - 0.5), X wins frame 0.
    gt = _seq([HUGE], [HUGE], [HUGE], [HUGE])
    est = _seq([HUGE, HUGE], [None, UNIT], [None, UNIT], [HUGE, None])  # columns X, Y
    h = hota(mot_frames(gt, est, est_rank=[[1, 0]] * 4))  # Y's row first in frame 0
    # every threshold: TP 2 (frames 0, 3), FN 2, FP 3; A-X matched twice: 2 * 2 / 4 / 2
    assert h.deta == pytest.approx(2 / 7) and h.assa == pytest.approx(0.5)
    assert h.assre == pytest.approx(0.5) and h.asspr == pytest.approx(1.0)


def test_distractor_matching_sums_scores_zeroed_below_half():
    """Pairs below IoU 0.5 score 0 in the assignment (not a penalty): the target with its
    own track (IoU 1) plus a zero beats the two pairs just under 0.5 + 0.5 = 1."""
    b = 1 + 2.0**-51  # the boxes below have IoU 1 / (2 + 2^-51) = 0.5 - 2^-53
    gt = _seq([_box(0, 0, 1, 1), _box(0, -b, 1, 1 + b)])  # target, distractor
    est = _seq([_box(0, 0, 1, 1), _box(0, 0, 1, 1 + b)])
    sim = box_iou(gt[0], est[0])
    assert sim[0, 0] == 1.0 and 0.5 - EPS <= sim[0, 1] < 0.5 and sim[1, 0] == sim[0, 1]
    assert sim[1, 1] < 0.5 - EPS and sim[0, 1] + sim[1, 0] < 1.0
    # assignment: target-track 0; the distractor's pair (track 1, IoU 1/3) is no match
    assert remove_distractor_matches(gt, [False, True], est).tolist() == [[True, True]]
    assert ref_keep(gt, [False, True], est).tolist() == [[True, True]]


# Two pairs just under IoU 0.5 (0.5 - 2^-53, within eps of it) against one pair of IoU 1.
_B = 1 + 2.0**-51
NEAR_GT = _seq([_box(0, 0, 1, 1), _box(0, -_B, 1, 1 + _B)])
NEAR_EST = _seq([_box(0, 0, 1, 1), _box(0, 0, 1, 1 + _B)])


def test_clear_sums_scores_zeroed_below_the_threshold():
    """Below the threshold a pair scores 0 (no penalty): object 0 with track 0 (IoU 1) plus
    nothing beats object 0-track 1 plus object 1-track 0 (IoU 0.5 - 2^-53 each, sum < 1)."""
    sim = mot_frames(NEAR_GT, NEAR_EST).similarity[0]
    assert sim[0, 0] == 1.0 and 0.5 - EPS <= sim[0, 1] == sim[1, 0] < 0.5 and sim[1, 1] < 0.4
    c = clear(mot_frames(NEAR_GT, NEAR_EST))
    assert (c.tp, c.fn, c.fp, c.motp) == (1, 1, 1, 1.0)
    # at threshold 0.3 the fourth pair (IoU 1/3) counts, and the two-pair matching wins
    c = clear(mot_frames(NEAR_GT, NEAR_EST), threshold=0.3)
    assert (c.tp, c.fn, c.fp) == (2, 0, 0)


def test_pairs_at_exactly_half_minus_epsilon_are_matched():
    """TrackEval's thresholds allow eps: IoU 0.5 - eps matches at 0.5 (CLEAR, HOTA's
    alpha 0.5, the distractor preprocessing), but not Identity's IoU >= 0.5."""
    gt, est = _seq([_box(0, 0, 1, 1)]), _seq([_box(0, 0, 1, 2 + 2.0**-50)])
    assert mot_frames(gt, est).similarity[0][0, 0] == 0.5 - EPS
    assert clear(mot_frames(gt, est)).tp == 1
    assert identity(mot_frames(gt, est)).idtp == 0
    h = hota(mot_frames(gt, est))
    assert h.deta_alpha[:10].tolist() == [1.0] * 10 and not h.deta_alpha[10:].any()
    assert remove_distractor_matches(gt, [True], est).tolist() == [[False]]
