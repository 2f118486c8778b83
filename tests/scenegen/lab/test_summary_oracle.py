"""Every experiment's summary and claims, recomputed independently from hand-made runs.

Each test builds run records whose outcomes it controls (seeded draws of success, loss
and recovery frames, errors, ordering probabilities), passes them through
:func:`scenegen.lab.experiments.summary.summarize`, and recomputes here, with plain
loops over the records, what the report prints and judges by: rates and their Wilson
intervals, recovery, precision over tracked frames, the cases two methods share and
their discordant pairs, scene-paired effects, Cochran's Q, the KAMS failure frame, the
SHM measures, and the p-values (with ``scipy.stats`` as the oracle of the exact and χ²
tests). Frame 0 is made to disagree with the rest in every series, so that counting it
changes the answers. A summary that pairs the wrong runs, swaps the two arms of a
claim, reads the wrong object, field or frame, or judges with the wrong effect of
interest fails here.
"""

from __future__ import annotations

import math
from collections import defaultdict

import numpy as np
import pytest
from scipy import stats as sps

from scenegen.lab.experiments import get, stats
from scenegen.lab.experiments.definitions import PAPER
from scenegen.lab.experiments.summary import FAILURE_PERSIST, summarize

T = 30          # frames per run, frame 0 included
LAST_K = 5      # frames a recovered run ends tracked in (DEFAULT_RECOVER_FRAMES)
SCENES, RUNS = 10, 5


def _record(exp: str, method: str, preset: str, scene: int, run: int, targets: list,
            value: float | None = None, **extra) -> dict:
    return {"key": {"experiment": exp, "method": method, "param": "lam" if value else "",
                    "preset": preset, "quick": False, "run": run, "scene": scene, "seed": 0,
                    "value": value},
            "targets": targets, **extra}


def _target(name: str, state: list[bool], rng: np.random.Generator, **series) -> dict:
    t = {"name": name, "state": [bool(s) for s in state]}
    for field in ("precision", "recall", "iou", "centre_error", "path_error"):
        v = series.get(field)
        t[field] = (rng.random(len(state)).tolist() if v is None else list(v))
    return t


def _walker_state(rng: np.random.Generator, p_success: float, p_recover: float) -> list[bool]:
    """Tracked in frames 1..T-1 with probability ``p_success``; else lost at a random frame,
    and tracked again over the last LAST_K frames with probability ``p_recover``. Frame 0
    is never tracked: a summary that scored it would find no success at all."""
    s = [True] * T
    if rng.random() >= p_success:
        lost = int(rng.integers(1, T - LAST_K - 2))
        back = T - LAST_K if rng.random() < p_recover else T
        s[lost:back] = [False] * (back - lost)
    s[0] = False
    return s


def _wilson_pct(k: int, n: int) -> list[float]:
    ci = sps.binomtest(k, n).proportion_ci(0.95, method="wilson")
    return [100.0 * ci.low, 100.0 * ci.high]


def _one(claims: list[dict], text: str) -> dict:
    found = [c for c in claims if text in c["claim"]]
    assert len(found) == 1, (text, [c["claim"] for c in claims])
    return found[0]


def _tracked_mean(values: list[float], state: list[bool]) -> float:
    v = [x for x, s in zip(values[1:], state[1:], strict=True) if s]
    return 100.0 * float(np.mean(v)) if v else math.nan


def _check_verdict(c: dict, min_n: int) -> None:
    lo, hi = c["interval"]
    if c["p_value"] < stats.ALPHA and c["n"] >= min_n:
        assert c["verdict"] == "reproduced", c
    elif c["n"] >= stats.MIN_RUNS and (hi < c["delta"]):
        assert c["verdict"] == "not reproduced", c
    else:
        assert c["verdict"] == "inconclusive", c


# ---------------------------------------------------------------------------------------
# dps-occlusion (DPS Table 3): McNemar against each method, DPS against the pooled
# orderings over scenes, and whether the orderings differ


OCCLUSION_P = {"nonps": 0.35, "ps-123": 0.55, "ps-231": 0.75, "ps-312": 0.45, "dps": 0.85}


@pytest.fixture(scope="module")
def occlusion():
    exp = get("dps-occlusion")
    rng = np.random.default_rng(20261202)
    records = []
    for preset in exp.presets:
        for scene in range(SCENES):
            ease = rng.normal(0.0, 0.15)   # scenes differ, every method alike
            for run in range(RUNS):
                for slug, p in OCCLUSION_P.items():
                    walker = _walker_state(rng, min(1.0, max(0.0, p + ease)), 0.6)
                    # the walker is the second target: the summary must find it by name
                    person = [True] * T
                    targets = [_target("person1", person, rng),
                               _target("walker", walker, rng),
                               _target("person2", person, rng)]
                    records.append(_record(exp.name, slug, preset, scene, run, targets,
                                           uniqueness=[50.0, 60.0, 70.0],
                                           effective_dynamics=rng.uniform(
                                               50.0, 150.0, (3, 2)).tolist(),
                                           failure_threshold=[20.0] * 3))
    return exp, records, summarize(exp, records)


def _by(records, slug, preset):
    return {(r["key"]["scene"], r["key"]["run"]): r for r in records
            if r["key"]["method"] == slug and r["key"]["preset"] == preset}


def test_occlusion_rates_are_those_of_the_walker_without_frame_0(occlusion):
    exp, records, res = occlusion
    for preset in exp.presets:
        rows = res["summary"]["presets"][preset]
        for m in exp.methods:
            runs = list(_by(records, m.slug, preset).values())
            walker = [r["targets"][1] for r in runs]
            k = sum(all(t["state"][1:]) for t in walker)
            kr = sum(all(t["state"][-LAST_K:]) for t in walker)
            hard = rows[m.label]["hard"]
            assert (hard["success"]["k"], hard["success"]["n"]) == (k, len(runs))
            assert hard["success"]["ci"] == pytest.approx(_wilson_pct(k, len(runs)), abs=1e-6)
            assert hard["recovery"]["k"] == kr and kr >= k
            prec = [_tracked_mean(t["precision"], t["state"]) for t in walker]
            assert hard["precision"]["mean"] == pytest.approx(np.nanmean(prec), rel=1e-12)
            rec = [_tracked_mean(t["recall"], t["state"]) for t in walker]
            assert hard["recall"]["mean"] == pytest.approx(np.nanmean(rec), rel=1e-12)
            lo, hi = hard["precision"]["ci"]
            assert lo <= hard["precision"]["mean"] <= hi
            assert rows[m.label]["uniqueness"] == [50.0, 60.0, 70.0]
            assert np.array(rows[m.label]["effective_dynamics"]) == pytest.approx(
                np.mean([r["effective_dynamics"] for r in runs], axis=0))
            paper = PAPER[exp.name][preset][m.label]
            comp = {c["what"]: c for c in res["comparisons"]}
            c = comp[f"{preset} {m.label} occluded object success %"]
            assert c["paper"] == paper[0] and c["ours"] == pytest.approx(100 * k / len(runs))
            inside = hard["success"]["ci"][0] <= paper[0] <= hard["success"]["ci"][1]
            assert c["agree"] == (inside or abs(100 * k / len(runs) - paper[0]) <= 10.0)


def test_occlusion_mcnemar_claims_pair_the_same_scene_and_run(occlusion):
    exp, records, res = occlusion
    for preset in exp.presets:
        paper = PAPER[exp.name][preset]
        dps = _by(records, "dps", preset)
        for m in exp.methods:
            if m.slug == "dps":
                continue
            gap = paper["DPS"][0] - paper[m.label][0]
            text = f"{preset}: occluded object's success of DPS above {m.label}'s"
            if abs(gap) < 10:
                assert not [c for c in res["claims"] if text in c["claim"]]
                continue
            c = _one(res["claims"], text)
            other = _by(records, m.slug, preset)
            cases = sorted(dps)
            a = [all(dps[x]["targets"][1]["state"][1:]) for x in cases]
            b = [all(other[x]["targets"][1]["state"][1:]) for x in cases]
            n_sf = sum(x and not y for x, y in zip(a, b, strict=True))
            n_fs = sum(y and not x for x, y in zip(a, b, strict=True))
            n_ss = sum(x and y for x, y in zip(a, b, strict=True))
            n = len(cases)
            assert c["n"] == n and c["delta"] == gap
            assert c["statistic"] == n_sf
            p = sps.binomtest(n_sf, n_sf + n_fs, 0.5, alternative="greater").pvalue
            assert c["p_value"] == pytest.approx(p, rel=1e-9)
            assert c["effect"] == pytest.approx(100.0 * (sum(a) - sum(b)) / n)
            lo, hi = stats.newcombe_paired_diff(n_ss, n_sf, n_fs, n - n_ss - n_sf - n_fs)
            assert c["interval"] == pytest.approx([100 * lo, 100 * hi])
            assert c["ours"] == (f"DPS {100 * sum(a) / n:.0f}% vs {m.label} "
                                 f"{100 * sum(b) / n:.0f}% of {n} paired runs "
                                 f"(discordant {n_sf}/{n_fs})")
            _check_verdict(c, 0)


def test_occlusion_dps_against_the_pooled_orderings_is_paired_by_scene(occlusion):
    exp, records, res = occlusion
    ps = [m.slug for m in exp.methods if m.group == "PS"]
    for preset in exp.presets:
        c = _one(res["claims"], f"{preset}: occluded object's success of DPS above the PS "
                 "orderings' (pooled)")
        paper = PAPER[exp.name][preset]
        assert c["delta"] == pytest.approx(
            paper["DPS"][0] - np.mean([paper[f"PS({','.join(s[3:])})"][0] for s in ps]))
        diffs = []
        for scene in range(SCENES):
            mine = [all(r["targets"][1]["state"][1:]) for (s, _), r in
                    _by(records, "dps", preset).items() if s == scene]
            pool = [all(r["targets"][1]["state"][1:]) for slug in ps for (s, _), r in
                    _by(records, slug, preset).items() if s == scene]
            assert len(mine) == RUNS and len(pool) == RUNS * len(ps)
            diffs.append(100.0 * (np.mean(mine) - np.mean(pool)))
        assert c["effect"] == pytest.approx(np.mean(diffs))
        assert c["n"] == SCENES and c["test"] == "paired bootstrap over scenes (one-sided)"
        lo, hi = c["interval"]
        assert lo < np.mean(diffs) < hi
        # the percentile interval of resampled scene means: within the scenes' range,
        # about 4 standard errors wide
        se = np.std(diffs, ddof=1) / math.sqrt(SCENES)
        assert min(diffs) <= lo and hi <= max(diffs)
        assert 2.5 * se < hi - lo < 5.5 * se
        _check_verdict(c, stats.MIN_RUNS)


def _cochran_q(rows: np.ndarray) -> float:
    """Q in its textbook form k (k − 1) Σ_j (C_j − C̄)² / Σ_i R_i (k − R_i)."""
    k = rows.shape[1]
    c, r = rows.sum(axis=0), rows.sum(axis=1)
    return k * (k - 1) * float(np.sum((c - c.mean()) ** 2)) / float(np.sum(r * (k - r)))


def test_occlusion_orderings_claim_is_cochrans_q_over_shared_cases(occlusion):
    exp, records, res = occlusion
    ps = [m for m in exp.methods if m.group == "PS"]
    for preset in exp.presets:
        paper = PAPER[exp.name][preset]
        c = _one(res["claims"], f"{preset}: the PS orderings differ in the occluded object's "
                 "success")
        spread = max(paper[m.label][0] for m in ps) - min(paper[m.label][0] for m in ps)
        assert c["delta"] == spread
        runs = {m.slug: _by(records, m.slug, preset) for m in ps}
        cases = sorted(runs[ps[0].slug])
        rows = np.array([[all(runs[m.slug][x]["targets"][1]["state"][1:]) for m in ps]
                         for x in cases], dtype=float)
        q = _cochran_q(rows)
        assert c["statistic"] == pytest.approx(q)
        assert c["p_value"] == pytest.approx(sps.chi2.sf(q, len(ps) - 1), rel=1e-9)
        rates = 100.0 * rows.mean(axis=0)
        assert c["effect"] == pytest.approx(rates.max() - rates.min())
        ib, iw = int(np.argmax(rates)), int(np.argmin(rates))
        best, worst = ps[ib].label, ps[iw].label
        assert f"best {best}" in c["ours"] and f"worst {worst}" in c["ours"]
        b, w = rows[:, ib].astype(bool), rows[:, iw].astype(bool)
        lo, hi = stats.newcombe_paired_diff(int(np.sum(b & w)), int(np.sum(b & ~w)),
                                            int(np.sum(~b & w)), int(np.sum(~b & ~w)))
        assert c["interval"] == pytest.approx([100 * lo, 100 * hi])
        assert c["n"] == len(cases)
        _check_verdict(c, 0)


# ---------------------------------------------------------------------------------------
# kams-accuracy and kams-robustness: one failure criterion against the noise-free path


THRESHOLD = 12.0


def _kams_errors(rng: np.random.Generator, kind: str) -> tuple[list[float], list[float]]:
    """(path error, drawn-centre error) of a run of kind ``complete`` (below the threshold
    but in frame 0 and a transient of FAILURE_PERSIST − 1 frames after it: frames 0..9 above,
    a failure only if frame 0 were scored), ``fail`` (FAILURE_PERSIST frames above from a
    random frame), ``early`` (frames 1..10 above: fails at the first scored frame),
    ``lost`` (no estimate, NaN, from a random frame). The drawn-centre error
    is far above the threshold everywhere: a summary reading it would fail every run."""
    e = rng.uniform(1.0, THRESHOLD - 1.0, T)
    e[:FAILURE_PERSIST] = THRESHOLD + rng.uniform(1.0, 5.0, FAILURE_PERSIST)
    if kind == "fail":
        start = int(rng.integers(FAILURE_PERSIST + 2, T - FAILURE_PERSIST))
        e[start:start + FAILURE_PERSIST] = THRESHOLD + 1.0
    elif kind == "early":  # lost from the first scored frame: fails at frame 1
        e[FAILURE_PERSIST] = THRESHOLD + 1.0
    elif kind == "lost":
        e[int(rng.integers(FAILURE_PERSIST + 2, T - 2)):] = np.nan
    return e.tolist(), (e + 10 * THRESHOLD).tolist()


def _failure(err: list[float]) -> int:
    """First frame (counted from frame 1) that starts FAILURE_PERSIST frames above."""
    above = [not (x <= THRESHOLD) for x in err[1:]]  # NaN counts as above
    for t in range(len(above) - FAILURE_PERSIST + 1):
        if all(above[t:t + FAILURE_PERSIST]):
            return t
    return -1


# (complete, lost, early); the rest fail later
KAMS_P = {"hybrid": (0.3, 0.2, 0.2), "sok": (0.5, 0.1, 0.1), "kams": (0.85, 0.05, 0.05)}


@pytest.fixture(scope="module")
def kams():
    exp = get("kams-accuracy")
    rng = np.random.default_rng(7)
    records = []
    for preset in exp.presets:
        for scene in range(8):
            for run in range(2):
                for m in exp.methods:
                    pc, pl, pe = KAMS_P[m.slug]
                    u = rng.random()
                    kind = ("complete" if u < pc else "lost" if u < pc + pl else
                            "early" if u < pc + pl + pe else "fail")
                    path, drawn = _kams_errors(rng, kind)
                    t = _target("target", [True] * T, rng, path_error=path, centre_error=drawn)
                    records.append(_record(exp.name, m.slug, preset, scene, run, [t],
                                           failure_threshold=[THRESHOLD]))
    return exp, records, summarize(exp, records)


def test_kams_completion_and_errors_follow_the_one_failure_criterion(kams):
    exp, records, res = kams
    assert res["summary"]["error_against"] == "path centre"
    seen_fail = seen_early = False
    for m in exp.methods:
        for pi, preset in enumerate(exp.presets):
            runs = [r for r in records if r["key"]["method"] == m.slug
                    and r["key"]["preset"] == preset]
            fails = [_failure(r["targets"][0]["path_error"]) for r in runs]
            done = [f < 0 for f in fails]
            st = res["summary"]["methods"][m.label][preset]
            assert (st["completed"]["k"], st["completed"]["n"]) == (sum(done), len(runs))
            errs = [float(np.nanmean(r["targets"][0]["path_error"][1:])) for r in runs]
            kept = [e for e, d in zip(errs, done, strict=True) if d]
            assert st["mean_error_completed"]["mean"] == pytest.approx(np.mean(kept))
            assert st["mean_error"]["mean"] == pytest.approx(np.mean(errs))
            failed = [f for f in fails if f >= 0]
            seen_early |= 0 in failed
            if failed:
                seen_fail = True
                assert st["median_failure_frame"] == pytest.approx(np.median(failed))
            else:
                assert st["median_failure_frame"] is None
            assert len(st["error_per_frame"]) == T - 1
            paper = PAPER["kams-accuracy"][m.label][pi]
            comp = [c for c in res["comparisons"] if c["what"] ==
                    f"{preset} {m.label} mean centre error px"]
            if paper is None:
                assert not comp
            else:
                assert comp[0]["tolerance"] == pytest.approx(max(3.0, 0.25 * paper))
    assert seen_fail and seen_early


def test_kams_claims_binomial_and_mcnemar_on_completion(kams):
    exp, records, res = kams
    done = {(r["key"]["method"], r["key"]["preset"], r["key"]["scene"], r["key"]["run"]):
            _failure(r["targets"][0]["path_error"]) < 0 for r in records}
    for pi, preset in enumerate(exp.presets):
        keys = sorted((s, r) for (m, p, s, r) in done if m == "kams" and p == preset)
        k = sum(done[("kams", preset, *x)] for x in keys)
        n = len(keys)
        c = _one(res["claims"], f"{preset}: KAMS completes the sequence")
        assert c["p_value"] == pytest.approx(
            sps.binomtest(k, n, 0.5, alternative="greater").pvalue, rel=1e-9)
        assert c["effect"] == pytest.approx(100 * k / n - 50) and c["delta"] == 25.0
        assert c["interval"] == pytest.approx([x - 50.0 for x in _wilson_pct(k, n)])
        _check_verdict(c, 0)
        for label, slug in (("Hybrid", "hybrid"), ("SOK", "sok")):
            text = f"{preset}: KAMS completes more often than {label}"
            if PAPER["kams-accuracy"][label][pi] is not None:
                assert not [x for x in res["claims"] if text in x["claim"]]
                continue
            c = _one(res["claims"], text)
            n_sf = sum(done[("kams", preset, *x)] and not done[(slug, preset, *x)]
                       for x in keys)
            n_fs = sum(done[(slug, preset, *x)] and not done[("kams", preset, *x)]
                       for x in keys)
            assert c["statistic"] == n_sf and c["n"] == n and c["delta"] == 50.0
            assert c["p_value"] == pytest.approx(
                sps.binomtest(n_sf, n_sf + n_fs, 0.5, alternative="greater").pvalue, rel=1e-9)


def test_kams_robustness_pairs_every_sequence_and_scene():
    exp = get("kams-robustness")
    rng = np.random.default_rng(11)
    p = {"kams": 0.8, "condensation": 0.5, "meanshift": 0.3, "annealed": 0.6,
         "hybrid": 0.4, "sok": 0.55}
    records, done = [], {}
    for preset in exp.presets:
        for scene in range(9):
            for m in exp.methods:
                u = rng.random()
                kind = "complete" if u < p[m.slug] else "early" if u < p[m.slug] + 0.1 \
                    else "fail"
                path, drawn = _kams_errors(rng, kind)
                t = _target("target", [True] * T, rng, path_error=path, centre_error=drawn)
                records.append(_record(exp.name, m.slug, preset, scene, 0, [t],
                                       failure_threshold=[THRESHOLD]))
                done[(m.slug, preset, scene)] = kind == "complete"
    res = summarize(exp, records)
    cases = [(p_, s) for p_ in exp.presets for s in range(9)]
    for m in exp.methods[1:]:
        row = res["summary"]["pairs"][m.label]
        n_sf = sum(done[("kams", *c)] and not done[(m.slug, *c)] for c in cases)
        n_fs = sum(done[(m.slug, *c)] and not done[("kams", *c)] for c in cases)
        assert (row["cases"], row["n_sf"], row["n_fs"]) == (len(cases), n_sf, n_fs)
        d = max(abs(n_sf - n_fs) - 1, 0)
        assert row["z"] == pytest.approx(math.copysign(d / math.sqrt(n_sf + n_fs),
                                                       n_sf - n_fs + 0.5))
        assert row["z_paper"] == PAPER["kams-robustness"][m.label]
        c = _one(res["claims"], f"KAMS more robust than {m.label}")
        assert c["delta"] == 20.0 and c["n"] == len(cases)
        assert c["p_value"] == pytest.approx(
            sps.binomtest(n_sf, n_sf + n_fs, 0.5, alternative="greater").pvalue, rel=1e-9)


# ---------------------------------------------------------------------------------------
# shm-depth: both targets kept, centre error, the ordering probabilities


SHM_P = {"kalman": 0.4, "shm": 0.7, "shm-fast": 0.8}


def _shm_record(exp, rng, slug, preset, scene):
    both = rng.random() < SHM_P[slug]
    states = [[True] * T, [True] * T]
    if not both:
        i = int(rng.integers(0, 2))
        lost = int(rng.integers(2, T - 2))
        states[i][lost:] = [False] * (T - lost)
    for s in states:
        s[0] = False                 # frame 0 never counts
    errs = [rng.uniform(0, 8 if slug != "kalman" else 14, T) for _ in range(2)]
    for e in errs:
        e[0] = 1000.0                # ... nor its error
        e[int(rng.integers(1, T))] = np.nan
    targets = [_target(f"hand-{c}", s, rng, centre_error=e.tolist())
               for c, s, e in zip("ab", states, errs, strict=True)]
    extra = {"failure_threshold": [20.0, 20.0]}
    if slug != "kalman":
        overlap = [False] * T
        lo = int(rng.integers(8, 15))
        overlap[lo:lo + 6] = [True] * 6
        prob = []
        for t in range(T):
            if overlap[t]:
                p0 = rng.uniform(0.6, 1.0)
            else:
                p0 = 0.5 + rng.uniform(-0.08, 0.08)
            prob.append([p0, 1.0 - p0])
        prob[0] = [1.0, 0.0]         # frame 0: far from equal, must not count
        prob[3] = [None, None]       # no estimate that frame
        extra |= {"order_prob": prob, "true_order": [0] * T, "overlap": overlap,
                  "depth_order_accuracy": float(rng.uniform(40.0, 100.0))}
    return _record(exp.name, slug, preset, scene, 0, targets, **extra)


def _apart_dev(r: dict) -> float:
    devs = [max(abs(x - 0.5) for x in p) for p, o in
            zip(r["order_prob"][1:], r["overlap"][1:], strict=True)
            if not o and None not in p]
    return float(np.mean(devs))


def test_shm_measures_and_claims():
    exp = get("shm-depth")
    rng = np.random.default_rng(3)
    records = [_shm_record(exp, rng, m.slug, preset, scene) for preset in exp.presets
               for scene in range(20) for m in exp.methods]
    res = summarize(exp, records)
    for preset in exp.presets:
        runs = {m.slug: {r["key"]["scene"]: r for r in records if r["key"]["method"] == m.slug
                         and r["key"]["preset"] == preset} for m in exp.methods}
        both = {s: {c: all(all(t["state"][1:]) for t in r["targets"]) for c, r in rs.items()}
                for s, rs in runs.items()}
        err = {s: {c: float(np.nanmean(np.concatenate([np.array(t["centre_error"][1:], float)
                                                       for t in r["targets"]])))
                   for c, r in rs.items()} for s, rs in runs.items()}
        rows = res["summary"]["presets"][preset]
        for m in exp.methods:
            st = rows[m.label]
            assert st["both_tracked"]["k"] == sum(both[m.slug].values())
            assert st["mean_centre_error"]["mean"] == pytest.approx(np.mean(
                list(err[m.slug].values())))
            tracked = [100 * np.mean([s for t in r["targets"] for s in t["state"][1:]])
                       for r in runs[m.slug].values()]
            assert st["tracked_frames"]["mean"] == pytest.approx(np.mean(tracked))
            if m.slug == "kalman":
                assert "depth_order_accuracy" not in st
                continue
            acc = [r["depth_order_accuracy"] for r in runs[m.slug].values()]
            assert st["depth_order_accuracy"]["mean"] == pytest.approx(np.mean(acc))
            devs = [_apart_dev(r) for r in runs[m.slug].values()]
            assert st["apart_max_deviation"]["mean"] == pytest.approx(np.mean(devs))
            c = _one(res["claims"], f"{preset}: {m.label}'s true ordering dominates")
            assert c["effect"] == pytest.approx(np.mean(acc) - 50.0) and c["delta"] == 10.0
            c = _one(res["claims"], f"{preset}: {m.label}'s ordering probabilities are equal")
            assert c["effect"] == pytest.approx(0.1 - np.mean(devs)) and c["delta"] == 0.05
            assert c["verdict"] == "reproduced"      # deviations of at most 0.08
            c = _one(res["claims"], f"{preset}: {m.label} keeps both targets throughout")
            n_sf = sum(both[m.slug][s] and not both["kalman"][s] for s in range(20))
            n_fs = sum(both["kalman"][s] and not both[m.slug][s] for s in range(20))
            assert c["statistic"] == n_sf and c["n"] == 20 and c["delta"] == 20.0
            assert c["p_value"] == pytest.approx(
                sps.binomtest(n_sf, n_sf + n_fs, 0.5, alternative="greater").pvalue, rel=1e-9)
            c = _one(res["claims"], f"{preset}: {m.label}'s mean centre error below Kalman's")
            assert c["effect"] == pytest.approx(
                np.mean([err["kalman"][s] - err[m.slug][s] for s in range(20)]))
            assert c["effect"] > 0 and c["delta"] == 5.0


# ---------------------------------------------------------------------------------------
# dps-synthetic (DPS Tables 1 and 2): object 1's recovery, the orderings, objects 2–7


SYNTH_P = {"nonps": (0.05, 0.10), "dps": (0.3, 0.6)}   # (success, recovery if lost)


@pytest.fixture(scope="module")
def synthetic():
    exp = get("dps-synthetic")
    rng = np.random.default_rng(5)
    ps = [m.slug for m in exp.methods if m.group == "PS"]
    p = SYNTH_P | {s: (0.1, 0.1 + 0.07 * i) for i, s in enumerate(ps)}
    records = []
    for lam in (20.0, 30.0):
        for scene in range(SCENES):
            for run in range(3):
                for m in exp.methods:
                    ps_, pr = p[m.slug]
                    targets = [_target("object1", _walker_state(rng, ps_, pr), rng)]
                    for i in range(2, 8):
                        s = [True] * T
                        if rng.random() < 0.1:
                            lost = int(rng.integers(1, T - 3))
                            s[lost:lost + 3] = [False] * 3
                        targets.append(_target(f"object{i}", s, rng))
                    uniq = rng.uniform(10.0, 100.0, 7).tolist()
                    records.append(_record(exp.name, m.slug, exp.presets[0], scene, run,
                                           targets, lam, uniqueness=uniq,
                                           effective_dynamics=[[80.0, 90.0]] * 7,
                                           failure_threshold=[20.0] * 7))
    return exp, records, summarize(exp, records)


def test_synthetic_recovery_pool_and_worst_ordering(synthetic):
    exp, records, res = synthetic
    ps = [m.slug for m in exp.methods if m.group == "PS"]
    for lam in (20.0, 30.0):
        row = res["summary"]["by_value"][f"{lam:g}"]

        def runs(slug, lam=lam):
            return [r for r in records if r["key"]["method"] == slug
                    and r["key"]["value"] == lam]

        rec = {s: [all(r["targets"][0]["state"][-LAST_K:]) for r in runs(s)] for s in ps}
        pooled = [x for s in ps for x in rec[s]]
        assert row["ps_mean"]["hard"]["recovery"]["k"] == sum(pooled)
        assert row["ps_mean"]["hard"]["recovery"]["n"] == len(pooled)
        worst = min(ps, key=lambda s: (np.mean(rec[s]), s))
        assert row["ps_worst"]["method"] == worst
        for m in exp.methods:
            st = row["methods"][m.slug]
            objs = [[r["targets"][i] for r in runs(m.slug)] for i in range(7)]
            assert st["hard"]["recovery"]["k"] == sum(all(t["state"][-LAST_K:])
                                                      for t in objs[0])
            others = [t for i in range(1, 7) for t in objs[i]]
            assert st["others"]["success"]["k"] == sum(all(t["state"][1:]) for t in others)
            assert st["others"]["success"]["n"] == len(others)
            # objects 2–7: a lost frame counts 0 (over all frames, not the tracked ones)
            prec = [np.mean([100 * np.mean(r["targets"][i]["precision"][1:])
                             for i in range(1, 7)]) for r in runs(m.slug)]
            assert st["others"]["precision"]["mean"] == pytest.approx(np.mean(prec))
            rec = [np.mean([100 * np.mean(r["targets"][i]["recall"][1:])
                            for i in range(1, 7)]) for r in runs(m.slug)]
            assert st["others"]["recall"]["mean"] == pytest.approx(np.mean(rec))
        # PS mean: object 1's precision is the mean of the orderings' means; objects 2–7's
        # the mean over runs of the orderings' mean on that (scene, run)
        hard = [row["methods"][s]["hard"]["precision"]["mean"] for s in ps]
        assert row["ps_mean"]["hard"]["precision"]["mean"] == pytest.approx(np.mean(hard))
        hard = [row["methods"][s]["hard"]["recall"]["mean"] for s in ps]
        assert row["ps_mean"]["hard"]["recall"]["mean"] == pytest.approx(np.mean(hard))
        per_case = defaultdict(list)
        for s in ps:
            for r in runs(s):
                per_case[(r["key"]["scene"], r["key"]["run"])].append(np.mean(
                    [100 * np.mean(r["targets"][i]["precision"][1:]) for i in range(1, 7)]))
        assert row["ps_mean"]["others"]["precision"]["mean"] == pytest.approx(
            np.mean([np.mean(v) for v in per_case.values()]))


def test_synthetic_claims(synthetic):
    exp, records, res = synthetic
    ps = [m.slug for m in exp.methods if m.group == "PS"]
    t2 = PAPER["dps-synthetic"]["table2"]
    t1 = PAPER["dps-synthetic"]["table1"]
    for lam in (20.0, 30.0):
        cases = defaultdict(dict)
        for r in records:
            if r["key"]["value"] == lam:
                cases[r["key"]["method"]][(r["key"]["scene"], r["key"]["run"])] = r
        c = _one(res["claims"], f"λ={lam:g}: object 1 recovery of DPS above the PS orderings'")
        assert c["delta"] == t2[lam]["recovery"][3] - t2[lam]["recovery"][1]
        diffs = []
        for scene in range(SCENES):
            d = [all(r["targets"][0]["state"][-LAST_K:]) for (s, _), r in
                 cases["dps"].items() if s == scene]
            p = [all(r["targets"][0]["state"][-LAST_K:]) for slug in ps for (s, _), r in
                 cases[slug].items() if s == scene]
            diffs.append(100 * (np.mean(d) - np.mean(p)))
        assert c["effect"] == pytest.approx(np.mean(diffs)) and c["n"] == SCENES
        c = _one(res["claims"], f"λ={lam:g}: object 1 recovery of the PS orderings above")
        assert c["delta"] == t2[lam]["recovery"][1] - t2[lam]["recovery"][0]
        c = _one(res["claims"], f"λ={lam:g}: the PS orderings differ in object 1 recovery")
        assert c["delta"] == 2 * (t2[lam]["recovery"][1] - t2[lam]["recovery"][2])
        rows = np.array([[all(cases[s][x]["targets"][0]["state"][-LAST_K:]) for s in ps]
                         for x in sorted(cases["dps"])], dtype=float)
        assert c["statistic"] == pytest.approx(_cochran_q(rows))
        assert c["p_value"] == pytest.approx(sps.chi2.sf(_cochran_q(rows), len(ps) - 1))

        def others(r):
            return np.mean([100 * np.mean(r["targets"][i]["precision"][1:])
                            for i in range(1, 7)])

        c = _one(res["claims"], f"λ={lam:g}: objects 2–7 precision of DPS above Non-PS's")
        assert c["delta"] == t1[lam]["pr"][2][0] - t1[lam]["pr"][0][0]
        assert c["effect"] == pytest.approx(np.mean(
            [others(cases["dps"][x]) - others(cases["nonps"][x]) for x in cases["dps"]]))
        c = _one(res["claims"], f"λ={lam:g}: objects 2–7 precision of PS above Non-PS's")
        assert c["delta"] == t1[lam]["pr"][1][0] - t1[lam]["pr"][0][0]
        assert c["effect"] == pytest.approx(np.mean(
            [np.mean([others(cases[s][x]) for s in ps]) - others(cases["nonps"][x])
             for x in cases["dps"]]))
    # uniqueness at the first λ: the object of the last stage minus that of the first
    c = _one(res["claims"], "λ=20: PS impoverishes the object of its first stage")
    gaps = []
    for r in records:
        slug = r["key"]["method"]
        if slug in ps and r["key"]["value"] == 20.0:
            order = [int(ch) - 1 for ch in slug[3:]]
            gaps.append(r["uniqueness"][order[-1]] - r["uniqueness"][order[0]])
    assert c["effect"] == pytest.approx(np.mean(gaps)) and c["n"] == len(gaps)
    assert c["delta"] == 10.0


def test_shm_claims_without_the_full_shm():
    """`--method kalman --method shm-fast`: fast SHM's claims are made without SHM's runs."""
    exp = get("shm-depth")
    rng = np.random.default_rng(9)
    records = [_shm_record(exp, rng, slug, "shm-clutter", scene) for scene in range(12)
               for slug in ("kalman", "shm-fast")]
    res = summarize(exp, records)
    assert set(res["summary"]["presets"]["shm-clutter"]) == {"Kalman", "Fast SHM"}
    assert len([c for c in res["claims"] if "Fast SHM" in c["claim"]]) == 4
    assert not [c for c in res["claims"] if "SHM's" in c["claim"] and "Fast" not in c["claim"]]


# ---------------------------------------------------------------------------------------
# the building blocks the claims share


def test_paired_claims_use_only_the_cases_both_methods_ran(occlusion):
    """An interrupted sweep: some runs of one method are missing. McNemar pairs the cases
    both ran, never a run with another scene's or seed's."""
    from scenegen.lab.experiments import summary

    exp, records, _ = occlusion
    preset = exp.presets[0]
    dps = _by(records, "dps", preset)
    ps = _by(records, "ps-231", preset)
    kept = {x: r for x, r in ps.items() if x[1] != 4 and x[0] != 3}  # 9 scenes x 4 runs
    out: list = []
    summary._mcnemar_claim(out, "DPS above PS",
                           [summary.drop_first_frame(r) for r in dps.values()],
                           [summary.drop_first_frame(r) for r in kept.values()],
                           lambda r: summary.succeeded(r["targets"][1]), 50.0, "DPS", "PS",
                           delta_source="stated")
    (c,) = out
    a = [all(dps[x]["targets"][1]["state"][1:]) for x in sorted(kept)]
    b = [all(kept[x]["targets"][1]["state"][1:]) for x in sorted(kept)]
    n_sf = sum(x and not y for x, y in zip(a, b, strict=True))
    n_fs = sum(y and not x for x, y in zip(a, b, strict=True))
    assert c["n"] == len(kept) == 36 and c["statistic"] == n_sf
    assert f"(discordant {n_sf}/{n_fs})" in c["ours"]
    assert c["effect"] == pytest.approx(100.0 * (sum(a) - sum(b)) / 36)


def test_paper_numbers_agree_inside_our_interval_or_within_the_tolerance():
    from scenegen.lab.experiments import summary

    rate = {"pct": 45.0, "k": 9, "n": 20, "ci": [30.0, 62.0]}
    cases = [  # paper, ours, (inside, agree)
        (50.0, rate, (True, True)),
        (70.0, rate, (False, False)),                            # 25 off, outside
        (54.0, {**rate, "ci": [40.0, 50.0]}, (False, True)),     # 9 points off
        (60.0, {**rate, "ci": [30.0, 62.0]}, (True, True)),      # 15 off, inside
        (56.0, {**rate, "ci": [40.0, 50.0]}, (False, False)),    # 11 off, outside
        (50.0, None, (False, False)),
        (30.0, {**rate, "pct": 10.0}, (True, True)),             # on the lower bound
        (62.0, {**rate, "pct": 80.0}, (True, True)),             # on the upper bound
        (55.0, {**rate, "ci": [40.0, 50.0]}, (False, True)),     # exactly 10 off
    ]
    for paper, ours, (inside, agree) in cases:
        out: list = []
        summary._compare(out, "x", paper, ours)
        (c,) = out
        assert (c["inside_interval"], c["agree"]) == (inside, agree), (paper, ours)
        assert c["tolerance"] == 10.0 and c["paper"] == paper
    out = []
    summary._compare(out, "x", None, rate)
    assert out == []
    # pixels: 3 px, or 25 % of the paper's number when larger
    mean = {"mean": 10.0, "n": 5, "ci": [9.0, 11.0]}
    for paper, agree in ((12.9, True), (13.4, False), (16.0, False)):
        out = []
        summary._compare(out, "x", paper, mean, kind="px")
        assert out[0]["agree"] is agree and out[0]["tolerance"] == max(3.0, 0.25 * paper)
    out = []
    summary._compare(out, "x", 40.0, {"mean": 31.0, "n": 5, "ci": [29.0, 33.0]}, kind="px")
    assert out[0]["tolerance"] == 10.0 and out[0]["agree"] is True
    assert summary._mean([np.nan], ("k",)) == {"mean": None, "n": 0, "ci": [None, None]}


def test_pooled_claims_read_the_papers_success_column():
    """Which claims exist depends on the paper's success rates (column 0) alone: the
    orderings claim from a best − worst spread of 10 points, the pool "above DPS" from
    orderings 10 or more points above DPS."""
    from scenegen.lab.experiments import summary

    exp = get("dps-dancers")
    labels = [m.label for m in exp.methods if m.group == "PS"]
    rng = np.random.default_rng(1)
    recs = {lab: [_record(exp.name, "x", "dps-dancers", s, r,
                          [_target("dancer4", [True] * 5, rng)])
                  for s in range(10) for r in range(2)] for lab in [*labels, "DPS"]}
    rows = {lab: {"hard": {"success": {"k": 20, "n": 20, "pct": 100.0}}} for lab in recs}
    paper = {"DPS": (40, 70, 50, 80), labels[0]: (30, 20, 50, 80),
             labels[1]: (50, 55, 50, 80), labels[2]: (50, 60, 50, 80),
             labels[3]: (45, 50, 50, 80)}
    claims: list = []
    summary._pooled_ps_claims(claims, exp, "dps-dancers", rows, recs, paper, 0)
    order = [c for c in claims if "the ordering matters" in c["claim"]]
    assert len(order) == 1 and order[0]["delta"] == 20
    above = [c for c in claims if "the paper finds above DPS" in c["claim"]]
    assert len(above) == 1 and f"({labels[1]}, {labels[2]}, pooled)" in above[0]["claim"]
    assert above[0]["delta"] == pytest.approx(50 - 40)
    # a pool needs two of them, and not every ordering (then it is the pooled PS claim)
    for firsts in ((30, 50, 45, 45), (50, 50, 50, 55)):
        one = {**paper, **{lab: (f, 20, 50, 80) for lab, f in zip(labels, firsts,
                                                                    strict=True)}}
        claims = []
        summary._pooled_ps_claims(claims, exp, "dps-dancers", rows, recs, one, 0)
        assert not [c for c in claims if "the paper finds above DPS" in c["claim"]]
    paper[labels[0]] = (40, 20, 50, 80)        # spread 50 − 40 = 10: still a claim
    claims = []
    summary._pooled_ps_claims(claims, exp, "dps-dancers", rows, recs, paper, 0)
    assert [c["delta"] for c in claims if "the ordering matters" in c["claim"]] == [10]
    paper[labels[0]] = (41, 20, 50, 80)        # spread 9: none
    claims = []
    summary._pooled_ps_claims(claims, exp, "dps-dancers", rows, recs, paper, 0)
    assert not [c for c in claims if "the ordering matters" in c["claim"]]


def test_synthetic_comparisons_put_each_paper_column_beside_ours(synthetic):
    exp, records, res = synthetic
    comp = {c["what"]: c for c in res["comparisons"]}
    t1, t2 = PAPER["dps-synthetic"]["table1"], PAPER["dps-synthetic"]["table2"]
    for lam in (20.0, 30.0):
        row = res["summary"]["by_value"][f"{lam:g}"]
        lam_s = f"λ={lam:g}"
        cols1 = (("Non-PS", row["methods"]["nonps"]), ("PS", row["ps_mean"]),
                 ("DPS", row["methods"]["dps"]))
        for i, (label, st) in enumerate(cols1):
            c = comp[f"Table 1 {lam_s} {label} objects 2–7 success %"]
            assert c["paper"] == t1[lam]["success"][i]
            assert c["ours"] == st["others"]["success"]["pct"]
            c = comp[f"Table 1 {lam_s} {label} objects 2–7 precision %"]
            assert c["paper"] == t1[lam]["pr"][i][0]
            assert c["ours"] == st["others"]["precision"]["mean"]
            c = comp[f"Table 1 {lam_s} {label} objects 2–7 recall %"]
            assert c["paper"] == t1[lam]["pr"][i][1]
            assert c["ours"] == st["others"]["recall"]["mean"]
        cols2 = (("Non-PS", row["methods"]["nonps"]["hard"]), ("PS mean", row["ps_mean"]["hard"]),
                 ("PS worst", row["ps_worst"]), ("DPS", row["methods"]["dps"]["hard"]))
        for i, (label, st) in enumerate(cols2):
            c = comp[f"Table 2 {lam_s} {label} object 1 recovery %"]
            assert c["paper"] == t2[lam]["recovery"][i] and c["ours"] == st["recovery"]["pct"]
            c = comp[f"Table 2 {lam_s} {label} object 1 precision %"]
            assert c["paper"] == t2[lam]["pr"][i][0] and c["ours"] == st["precision"]["mean"]
            c = comp[f"Table 2 {lam_s} {label} object 1 recall %"]
            assert c["paper"] == t2[lam]["pr"][i][1] and c["ours"] == st["recall"]["mean"]
    assert len(comp) == 2 * (3 * 3 + 4 * 3)


def test_the_summary_does_not_depend_on_the_order_runs_finished_in(occlusion):
    """Workers finish runs in any order: the records' order must not change a number."""
    exp, records, res = occlusion
    shuffled = [records[i] for i in np.random.default_rng(0).permutation(len(records))]
    assert summarize(exp, shuffled) == res


def test_a_sweep_over_some_methods_judges_what_it_ran(occlusion, synthetic):
    """`--method` runs a subset: claims need both of their arms, the rest are left out."""
    exp, records, _ = occlusion

    def only(recs, slugs):
        return [r for r in recs if r["key"]["method"] in slugs]

    res = summarize(exp, only(records, {"nonps", "dps"}))
    assert set(res["summary"]["presets"]["dps-occlusion"]) == {"Non-PS", "DPS"}
    assert sorted(c["claim"].split(": ")[1] for c in res["claims"]
                  if c["claim"].startswith("dps-occlusion:")) == \
        ["occluded object's success of DPS above Non-PS's"]
    res = summarize(exp, only(records, {"nonps", "ps-123", "ps-312"}))
    claims = [c["claim"] for c in res["claims"] if c["claim"].startswith("dps-occlusion:")]
    assert len(claims) == 1 and "the ordering matters" in claims[0]  # needs no DPS
    res = summarize(exp, only(records, {"ps-123", "ps-312", "dps"}))
    claims = [c["claim"] for c in res["claims"] if c["claim"].startswith("dps-occlusion:")]
    assert len(claims) == 4 and any("the ordering matters" in c for c in claims)
    assert any("PS orderings' (pooled)" in c for c in claims)

    exp, records, _ = synthetic
    for slugs, orderings in (({"nonps", "dps", "ps-1234567", "ps-3456712"}, True),
                             ({"dps", "ps-1234567"}, False),
                             ({"nonps", "ps-1234567", "ps-4567123"}, True)):
        res = summarize(exp, only(records, slugs))
        row = res["summary"]["by_value"]["20"]
        assert set(row["methods"]) == slugs
        claims = [c["claim"] for c in res["claims"] if c["claim"].startswith("λ=20:")]
        assert any("the ordering matters" in c for c in claims) is orderings
        assert any("precision of DPS above" in c for c in claims) is \
            ({"dps", "nonps"} <= slugs)
        assert any("precision of PS above" in c for c in claims) is ("nonps" in slugs)
        assert any("recovery of DPS above" in c for c in claims) is ("dps" in slugs)
        assert any("above Non-PS's" in c and "recovery" in c for c in claims) is \
            ("nonps" in slugs)
        # each method that ran has its columns beside the paper's, whichever did not
        shown = {c["what"].split(" objects")[0].split(" object 1")[0].split(" ", 3)[3]
                 for c in res["comparisons"] if c["what"].startswith(("Table 1 λ=20 ",
                                                                      "Table 2 λ=20 "))}
        want = {"Non-PS"} if "nonps" in slugs else set()
        want |= {"DPS"} if "dps" in slugs else set()
        want |= {"PS", "PS mean", "PS worst"}
        assert shown == want, shown


def test_kams_accuracy_of_kams_alone(kams):
    exp, records, res = kams
    alone = summarize(exp, [r for r in records if r["key"]["method"] == "kams"])
    assert set(alone["summary"]["methods"]) == {"KAMS"}
    assert alone["summary"]["methods"]["KAMS"] == res["summary"]["methods"]["KAMS"]
    assert [c["claim"] for c in alone["claims"]] == \
        [c["claim"] for c in res["claims"] if "completes the sequence" in c["claim"]]


def test_dps_dancers_claims_follow_the_papers_table_4():
    """Table 4: DPS 36 % against PS(1,2,3,4) 26 % (a gap of exactly 10 points is a claim),
    the three other orderings 70–84 % (claims that they beat DPS), Non-PS 4 %."""
    exp = get("dps-dancers")
    rng = np.random.default_rng(12)
    records = []
    for scene in range(SCENES):
        for run in range(2):
            for m in exp.methods:
                targets = [_target(f"dancer{i}", [True] * T, rng) for i in (1, 2, 3)]
                targets.append(_target("dancer4", _walker_state(rng, 0.5, 0.5), rng))
                records.append(_record(exp.name, m.slug, "dps-dancers", scene, run, targets,
                                       uniqueness=[50.0] * 4,
                                       effective_dynamics=[[90.0, 95.0]] * 4,
                                       failure_threshold=[20.0] * 4))
    res = summarize(exp, records)
    mc = sorted(c["claim"].split(": ", 1)[1] for c in res["claims"]
                if c["test"].startswith("paired McNemar"))
    assert mc == sorted(["occluded object's success of DPS above Non-PS's",
                         "occluded object's success of DPS above PS(1,2,3,4)'s",
                         "occluded object's success of PS(2,3,4,1) above DPS's",
                         "occluded object's success of PS(3,4,1,2) above DPS's",
                         "occluded object's success of PS(4,1,2,3) above DPS's"])
    c = _one(res["claims"], "success of DPS above PS(1,2,3,4)'s")
    assert c["delta"] == 10
    c = _one(res["claims"], "success of PS(2,3,4,1) above DPS's")
    assert c["delta"] == 82 - 36
    hard = res["summary"]["presets"]["dps-dancers"]["DPS"]["hard"]
    k = sum(all(r["targets"][3]["state"][1:]) for r in records if r["key"]["method"] == "dps")
    assert hard["success"]["k"] == k


def test_claims_over_the_cases_or_scenes_both_arms_hold(occlusion):
    from scenegen.lab.experiments import summary

    exp, records, _ = occlusion
    recs = [summary.drop_first_frame(r) for r in records
            if r["key"]["preset"] == exp.presets[0]]
    dps = [r for r in recs if r["key"]["method"] == "dps"]
    ps = [r for r in recs if r["key"]["method"] == "ps-123"]

    def ok(r):
        return summary.succeeded(r["targets"][1])

    # scenes: a pool missing two scenes is compared on the other eight
    out: list = []
    summary._scene_claim(out, "c", dps, [r for r in ps if r["key"]["scene"] not in (2, 5)],
                         ok, 10.0, "A", "B", ("k",), delta_source="stated")
    assert out[0]["n"] == SCENES - 2 and f"of {RUNS * (SCENES - 2)} runs on 8 scenes" in \
        out[0]["ours"]
    # paired means: the cases both hold
    a = {(r["key"]["scene"], r["key"]["run"]): 1.0 for r in dps}
    b = {k: 0.0 for k in list(a)[:7]}
    out = []
    summary._boot_claim(out, "c", a, b, 0.5, "{mean:.1f} over {n}", ("k",),
                        delta_source="stated")
    assert out[0]["n"] == 7 and out[0]["ours"] == "1.0 over 7"
    # McNemar: no shared case, no claim; one shared case, a claim
    out = []
    summary._mcnemar_claim(out, "c", dps[:3], ps[3:6], ok, 10.0, "A", "B",
                           delta_source="stated")
    assert out == []
    summary._mcnemar_claim(out, "c", dps[:3], ps[2:6], ok, 10.0, "A", "B",
                           delta_source="stated")
    assert len(out) == 1 and out[0]["n"] == 1
    # Cochran's Q: orderings that share no case make no claim
    rates = {m: {"pct": 50.0, "n": 3} for m in ("x", "y")}
    out = []
    summary._orderings_claim(out, "c", {"x": dps[:3], "y": ps[3:6]}, rates, ok, 10.0,
                             delta_source="stated")
    assert out == []
