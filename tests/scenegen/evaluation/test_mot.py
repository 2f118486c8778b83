"""scenegen.evaluation.mot on hand-worked cases (TrackEval's numbers: test_trackeval_oracle)."""

from __future__ import annotations

import numpy as np
import pytest

from scenegen.evaluation import metrics
from scenegen.evaluation.mot import (
    HOTA_ALPHAS,
    MotScores,
    add_counts,
    box_iou,
    clear,
    combine,
    hota,
    identity,
    mot_counts,
    mot_frames,
    remove_distractor_matches,
    score_all,
)


def test_hota_of_half_overlap_is_ten_of_nineteen_thresholds():
    gt = np.array([[[0, 0, 10, 10.0]], [[0, 0, 10, 10.0]]])
    est = np.array([[[0, 0, 10, 5.0]], [[0, 0, 10, 5.0]]])  # IoU 0.5 in both frames
    h = hota(mot_frames(gt, est))
    assert len(HOTA_ALPHAS) == 19 and HOTA_ALPHAS[0] == 0.05
    assert h.hota == pytest.approx(10 / 19) and h.deta == pytest.approx(10 / 19)
    assert h.assa == pytest.approx(10 / 19)
    assert h.loca == pytest.approx((10 * 0.5 + 9 * 1.0) / 19)  # unmatched thresholds: LocA 1


def test_hota_association_of_a_switch():
    # one object, tracked by track 0 in frames 0-1 and track 1 in frames 2-3, IoU 1
    gt = np.tile(np.array([0, 0, 10, 10.0]), (4, 1, 1))
    est = np.full((4, 2, 4), np.nan)
    est[:2, 0] = est[2:, 1] = [0, 0, 10, 10]
    h = hota(mot_frames(gt, est))
    # DetA 1; each match's association Jaccard is 2 / (4 + 2 - 2) = 0.5
    assert h.deta == 1.0 and h.assa == pytest.approx(0.5) and h.hota == pytest.approx(0.5**0.5)
    c = clear(mot_frames(gt, est))
    assert (c.idsw, c.frag, c.mt, c.mota) == (1, 0, 1, 0.75)
    i = identity(mot_frames(gt, est))
    assert (i.idtp, i.idfn, i.idfp, i.idf1) == (2, 2, 2, 0.5)


def test_clear_frag_mt_pt_ml():
    gt = np.tile(np.array([0, 0, 10, 10.0]), (10, 2, 1))
    gt[:, 1, 0] = 50
    est = gt.copy()
    est[[3, 6], 0] = np.nan  # object 0: two interruptions, 80 % tracked
    est[2:, 1] = np.nan  # object 1: tracked 20 %
    c = clear(mot_frames(gt, est))
    # As in TrackEval, a frame without any tracker box does not end a track: no fragment.
    assert (c.frag, c.mt, c.pt, c.ml, c.fn, c.fp, c.idsw) == (0, 0, 2, 0, 10, 0, 0)
    far = np.tile(np.array([200, 200, 5, 5.0]), (10, 1, 1))  # a false positive every frame
    c = clear(mot_frames(gt, np.concatenate([est, far], axis=1)))
    assert (c.frag, c.mt, c.pt, c.ml, c.fn, c.fp, c.idsw) == (2, 0, 2, 0, 10, 10, 0)
    assert metrics.clear_mot(gt, est).mota == pytest.approx(0.5)


def test_empty_sides_follow_trackeval():
    gt = np.tile(np.array([0, 0, 10, 10.0]), (3, 1, 1))
    none = np.full((3, 1, 4), np.nan)
    c = clear(mot_frames(gt, none))
    assert (c.fn, c.ml, c.mota) == (3, 1, 0.0)
    h = hota(mot_frames(gt, none))
    assert (h.hota, h.loca) == (0.0, 1.0)
    c = clear(mot_frames(none, gt))
    assert (c.fp, c.mota) == (3, 0.0)


def test_box_iou_guards_and_distractor_matches():
    assert box_iou([[0, 0, 0, 5]], [[0, 0, 0, 5]])[0, 0] == 0.0  # zero area
    assert box_iou([[0, 0, 10, 10]], [[5, 0, 10, 10]])[0, 0] == pytest.approx(1 / 3)
    gt = np.array([[[0, 0, 10, 10], [40, 0, 10, 10]]], dtype=float)  # target, distractor
    est = np.array([[[0, 0, 10, 10], [41, 0, 10, 10], [80, 0, 5, 5]]], dtype=float)
    keep = remove_distractor_matches(gt, [False, True], est)
    assert keep.tolist() == [[True, False, True]]


def test_identity_of_twenty_thousand_track_ids_fits_in_memory():
    # TrackEval's square (objects + tracks) problem asked for 3.2 GB per matrix here (a
    # MOT file with 300,000 ids: 671 GiB, an internal MemoryError); the rectangular one
    # has the same optimum. Run under a 1.5 GB address-space limit.
    import subprocess
    import sys
    import textwrap

    code = textwrap.dedent("""
        import resource
        import numpy as np
        resource.setrlimit(resource.RLIMIT_AS, (1536 * 2**20, 1536 * 2**20))
        from scenegen.evaluation.mot import identity, mot_frames
        t_n, h_n = 10, 20_000
        gt = np.zeros((t_n, 2, 4))
        gt[:, 0] = [10, 10, 10, 10]
        gt[:, 1] = [60, 10, 10, 10]
        est = np.full((t_n, h_n, 4), np.nan)
        h = np.arange(h_n)
        est[h % t_n, h] = gt[0, h % 2]
        s = identity(mot_frames(gt, est))
        print(s.idtp, s.idfn, s.idfp)
    """)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300)  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    # Each object shares one frame with each of its tracks: one pair each is matched.
    assert done.stdout.split() == ["2", "18", str(20_000 - 2)]


def _part(rng: np.random.Generator, kind: str) -> tuple[np.ndarray, np.ndarray]:
    """A short seeded sequence (gt (T, K, 4), tracks (T, H, 4)): objects on random walks
    with gaps; tracks that follow them with noise, drop boxes, swap and add clutter."""
    t, k = int(rng.integers(3, 9)), int(rng.integers(1, 4))
    gt = np.cumsum(rng.normal(0, 3, (t, k, 4)), axis=0) + [40, 40, 20, 20]
    gt[..., 2:] = np.abs(gt[..., 2:]) + 5
    gt[rng.random((t, k)) < 0.15] = np.nan
    est = np.concatenate([gt + rng.normal(0, 2, gt.shape), gt[:, :1] + 30], axis=1)
    est[rng.random(est.shape[:2]) < 0.2] = np.nan
    est[t // 2:, :k] = est[t // 2:, rng.permutation(k)]
    if kind == "no-tracks":
        est[:] = np.nan
    elif kind == "no-gt":
        gt[:] = np.nan
    return gt, est


def _joined(parts):
    """The parts one after another in time, each with its own object and track ids."""
    t = sum(g.shape[0] for g, _ in parts)
    gt = np.full((t, sum(g.shape[1] for g, _ in parts), 4), np.nan)
    est = np.full((t, sum(e.shape[1] for _, e in parts), 4), np.nan)
    t0 = k0 = h0 = 0
    for g, e in parts:
        gt[t0:t0 + len(g), k0:k0 + g.shape[1]] = g
        est[t0:t0 + len(e), h0:h0 + e.shape[1]] = e
        t0, k0, h0 = t0 + len(g), k0 + g.shape[1], h0 + e.shape[1]
    return gt, est


@pytest.mark.parametrize("seed", range(12))
def test_combine_equals_the_sequences_scored_as_one(seed):
    """TrackEval's COMBINED_SEQ (mot.combine) is the score of the sequences joined in time
    with disjoint ids: the CLEAR and identity counts add, HOTA's per-threshold TP/FN/FP add
    and its association and localisation are TP-weighted means. Parts without any track
    or any object (TrackEval's early returns) add their misses or false positives."""
    rng = np.random.default_rng(seed)
    kinds = ["plain"] * int(rng.integers(1, 4)) + [["no-tracks", "no-gt", "plain"][seed % 3]]
    parts = [_part(rng, kind) for kind in kinds]
    got = combine([score_all(mot_frames(g, e), threshold=0.3) for g, e in parts])
    want = score_all(mot_frames(*_joined(parts)), threshold=0.3)
    for part in ("clear", "identity", "hota"):
        a, b = getattr(got, part), getattr(want, part)
        for name in a.__dataclass_fields__:
            np.testing.assert_allclose(getattr(a, name), getattr(b, name), rtol=0,
                                       atol=1e-12, err_msg=f"{part}.{name}")  # fmt: skip
    assert want.clear.tp > 0 and want.clear.fn > 0


def test_combine_of_one_sequence_and_bad_input():
    gt, est = _part(np.random.default_rng(5), "plain")
    one = score_all(mot_frames(gt, est))
    again = combine([one])
    assert again.clear == one.clear and again.identity == one.identity
    assert again.hota.hota == one.hota.hota
    with pytest.raises(ValueError, match="scores is empty"):
        combine([])
    with pytest.raises(ValueError, match="sequence of MotScores"):
        combine(one)
    with pytest.raises(ValueError, match="not dict"):
        combine([one, {}])
    for bad in (None, 3.5):  # neither a sequence nor one MotScores
        with pytest.raises(ValueError, match="sequence of MotScores"):
            combine(bad)
    assert isinstance(again, MotScores)


@pytest.mark.parametrize("kind", ["no-gt", "no-tracks", "empty"])
def test_combine_of_sequences_without_objects_or_tracks_divides_by_at_least_one(kind):
    """TrackEval's combined final fields divide by max(1, count), unlike one sequence,
    which returns early: sequences with no ground truth combine to MOTA = MODA = -FP
    (one such sequence alone scores 0), and DetRe, DetPr and DetA are 0, not 0 / 0."""
    rng = np.random.default_rng(11)
    parts = [_part(rng, "no-gt" if kind == "empty" else kind) for _ in range(2)]
    if kind == "empty":
        parts = [(g, np.full_like(e, np.nan)) for g, e in parts]
    got = combine([score_all(mot_frames(g, e)) for g, e in parts])
    fp = sum(int(np.sum(~np.isnan(e[..., 0]))) for g, e in parts if np.isnan(g).all())
    c, h = got.clear, got.hota
    assert (c.tp, c.fp, c.motp) == (0, fp, 0.0) and (fp > 0) == (kind == "no-gt")
    assert c.mota == c.moda == (-fp if c.fn == 0 else 0.0)
    assert (c.fn > 0) == (kind == "no-tracks")
    for name in ("hota", "deta", "detre", "detpr", "assa", "assre", "asspr"):
        assert getattr(h, name) == 0.0, name
    np.testing.assert_array_equal(h.deta_alpha, 0.0)
    assert h.loca == 1.0


def test_add_counts_adds_key_by_key_and_refuses_counts_it_cannot_add():
    """add_counts sums mot_counts entries key by key (the per-threshold lists element by
    element) and names the first key an entry lacks, or whose list has not one value per
    HOTA threshold (a list of 1 would broadcast), instead of a KeyError or a wrong sum."""
    rng = np.random.default_rng(7)
    a, b = (mot_counts(score_all(mot_frames(*_part(rng, "plain")))) for _ in range(2))
    both = add_counts([a, b])
    assert both["tp"] == a["tp"] + b["tp"] and both["idfp"] == a["idfp"] + b["idfp"]
    np.testing.assert_array_equal(both["hota_fn"], np.add(a["hota_fn"], b["hota_fn"]))
    missing = {k: v for k, v in b.items() if k != "tp"}
    short = {**b, "hota_fn": [float(b["hota_fn"][0])]}
    for entries, key in (([a, missing], "tp"), ([a, short], "hota_fn"),
                         ([a, score_all(mot_frames(*_part(rng, "plain")))], "tp")):
        with pytest.raises(ValueError, match=f"an entry has no '{key}'"):
            add_counts(entries)
    with pytest.raises(ValueError, match="no counts to add"):
        add_counts([])
