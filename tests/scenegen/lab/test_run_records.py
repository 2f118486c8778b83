"""The runs an experiment plans and what each run records, checked independently.

``summarize`` judges the papers' claims from run records (test_summary_oracle.py checks
that step); this file checks the step before it: that ``plan_tasks`` plans every
(method, value, preset, scene, run) once, that the seeds pair the methods on the same
scenes and give every run its own tracker stream, and that ``run_task`` records what
the sequence and the tracker say. Each record is recomputed here from the generated
sequence and the tracker's own run, with plain loops over frames, targets and pairs.
"""

from __future__ import annotations

import hashlib
import itertools
import math

import numpy as np
import pytest

import scenegen
from scenegen.errors import ConfigError
from scenegen.lab.experiments import get, names
from scenegen.lab.experiments.runner import (
    Task,
    derive_seed,
    plan_tasks,
    run_task,
    scene_seed,
    tracker_params,
)
from scenegen.lab.run import run

TOL = 2e-6  # records round floats to 6 decimals


def _derive(*parts) -> int:
    # The documented recipe, written out: SHA-256 of the parts joined by U+001F, its eight
    # little-endian 32-bit words as SeedSequence entropy, the first 64-bit state >> 1.
    text = "\x1f".join(str(p) for p in parts).encode("utf-8")
    digest = hashlib.sha256(text).digest()
    words = [int.from_bytes(digest[i : i + 4], "little") for i in range(0, 32, 4)]
    state = np.random.SeedSequence(words).generate_state(1, dtype=np.uint64)[0]
    return int(state) // 2


def test_seeds_follow_the_documented_recipe():
    for parts in [
        ("a",),
        (0, "dps-occlusion", "scene", "dps-occlusion-2", 7),
        (31, "x", "dps", "p", "lam=20", 3, 4),
    ]:
        assert derive_seed(*parts) == _derive(*parts)
        assert 0 <= derive_seed(*parts) < 2**63
    assert scene_seed(5, "e", "p", 2) == _derive(5, "e", "scene", "p", 2)
    t = Task("dps-synthetic", "dps", "dps-synthetic", "lam", 20.0, 2, 3, 5, False)
    assert t.scene_seed() == _derive(5, "dps-synthetic", "scene", "dps-synthetic", 2)
    assert t.tracker_seed() == _derive(5, "dps-synthetic", "dps", "dps-synthetic", "lam=20", 2, 3)
    plain = Task("shm-depth", "kalman", "shm-crossing", "", None, 0, 1, 0, True)
    assert plain.sweep_label == ""
    assert plain.tracker_seed() == _derive(0, "shm-depth", "kalman", "shm-crossing", "", 0, 1)


@pytest.mark.parametrize("name", names())
def test_every_run_is_planned_once_with_paired_scenes(name):
    exp = get(name)
    runs, scenes, seed = 2, 3, 11
    tasks = plan_tasks(exp, runs=runs, scenes=scenes, seed=seed, quick=False)
    slugs = [m.slug for m in exp.methods]
    values = [v for _, v in exp.sweep_values(False)]
    expected = list(itertools.product(slugs, values, exp.presets, range(scenes), range(runs)))
    got = [(t.method, t.value, t.preset, t.scene, t.run) for t in tasks]
    assert got == expected  # every combination once, in the documented order
    assert all(t.seed == seed and not t.quick and t.overrides == () for t in tasks)
    assert all(t.experiment == name for t in tasks)
    # One scene seed per (preset, scene), whatever the method, value or run...
    by_case: dict[tuple[str, int], set[int]] = {}
    for t in tasks:
        by_case.setdefault((t.preset, t.scene), set()).add(t.scene_seed())
    assert all(len(s) == 1 for s in by_case.values())
    assert len({next(iter(s)) for s in by_case.values()}) == len(by_case)
    # ...and one tracker stream per run, none equal to a scene's seed.
    tracker_seeds = [t.tracker_seed() for t in tasks]
    assert len(set(tracker_seeds)) == len(tasks)
    assert not set(tracker_seeds) & {next(iter(s)) for s in by_case.values()}
    assert len({t.filename() for t in tasks}) == len(tasks)
    # Another base seed gives other scenes.
    other = plan_tasks(exp, runs=1, scenes=1, seed=seed + 1, quick=False)
    assert other[0].scene_seed() != tasks[0].scene_seed()


def test_a_restricted_plan_is_the_full_plan_s_subset_with_the_same_seeds():
    exp = get("dps-synthetic")
    full = plan_tasks(exp, runs=2, scenes=2, seed=0, quick=False)
    values = [v for _, v in exp.sweep_values(False)]
    assert len(values) > 1
    part = plan_tasks(
        exp, runs=2, scenes=2, seed=0, quick=False, methods=["dps", "nonps"], values=[values[-1]]
    )
    assert [(t.method, t.value) for t in part] == (
        [("dps", values[-1])] * 4 + [("nonps", values[-1])] * 4
    )  # in the order asked
    index = {t.filename(): t for t in full}
    for t in part:
        assert index[t.filename()] == t
        assert t.tracker_seed() == index[t.filename()].tracker_seed()
    # Overrides do not enter the seeds: a run with them is paired with the default run.
    over = plan_tasks(
        exp,
        runs=1,
        scenes=1,
        seed=0,
        quick=False,
        methods=["dps"],
        values=[values[0]],
        overrides={"n_particles": 90},
    )
    assert over[0].overrides == (("n_particles", 90),)
    assert over[0].scene_seed() == full[0].scene_seed()
    same = next(
        t
        for t in full
        if t.method == "dps" and t.value == values[0] and t.scene == 0 and t.run == 0
    )
    assert over[0].tracker_seed() == same.tracker_seed()
    assert tracker_params(exp, over[0])["n_particles"] == 90


@pytest.mark.parametrize(
    "name, kw, match",
    [
        ("dps-synthetic", {"runs": 0}, "runs must be >= 1, got 0"),
        ("dps-synthetic", {"scenes": 0}, "scenes must be >= 1, got 0"),
        ("dps-synthetic", {"seed": -1}, "seed must be a non-negative integer, got -1"),
        ("dps-synthetic", {"values": [20.0, 7.0]}, r"value 7 .*; valid values: 20, 30, 40, 50$"),
        ("shm-depth", {"values": [1.0]}, r"valid values: none \(no sweep\)$"),
        ("shm-depth", {"methods": ["kalman", "nope"]}, "unknown method 'nope'"),
    ],
)
def test_a_plan_rejects_what_cannot_run(name, kw, match):
    args = {"runs": 1, "scenes": 1, "seed": 0, "quick": False, **kw}
    with pytest.raises(ConfigError, match=match):
        plan_tasks(get(name), **args)
    # The smallest valid plan of the same shape runs.
    fixed = {"runs": 1, "scenes": 1, "seed": 0, "values": None, "methods": None}
    assert plan_tasks(get(name), **{**args, **{k: fixed[k] for k in kw}})


def test_quick_runs_take_the_smaller_particle_count_and_the_sweep_value():
    exp = get("dps-synthetic")
    value = exp.sweep_values(True)[0][1]
    t = Task(exp.name, "dps", "dps-synthetic", "lam", value, 0, 0, 0, True)
    params = tracker_params(exp, t)
    assert params["lam"] == value
    full = exp.method("dps").param_dict()["n_particles"]
    assert params["n_particles"] == min(full, exp.quick_particles)
    assert (
        tracker_params(exp, Task(exp.name, "dps", "dps-synthetic", "lam", value, 0, 0, 0, False))[
            "n_particles"
        ]
        == full
    )


# ------------------------------------------------------------------ what a run records
def _box_measures(e, g):
    """State, precision, recall, IoU and centre error of one estimate against one box."""
    ex, ey, ew, eh = (float(v) for v in e)
    gx, gy, gw, gh = (float(v) for v in g)
    iw = min(ex + ew, gx + gw) - max(ex, gx)
    ih = min(ey + eh, gy + gh) - max(ey, gy)
    inter = max(iw, 0.0) * max(ih, 0.0)
    union = ew * eh + gw * gh - inter
    dx = (ex + ew / 2) - (gx + gw / 2)
    dy = (ey + eh / 2) - (gy + gh / 2)
    return (inter > 0, inter / (ew * eh), inter / (gw * gh), inter / union, math.hypot(dx, dy))


def _close(recorded, value):
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return recorded is None
    return recorded is not None and abs(recorded - value) <= TOL * max(1.0, abs(value))


def _independent_run(task):
    exp = get(task.experiment)
    seq = scenegen.generate(
        task.preset, seed=task.scene_seed(), frames=exp.quick_frames if task.quick else None
    )
    params = tracker_params(exp, task)
    done = run(seq, exp.method(task.method).tracker, params, task.tracker_seed())
    return exp, seq, params, done


TASKS = {
    # A DPS run (uniqueness, effective dynamics), a KAMS run (the noise-free
    # path), a fast-SHM run on the crossing (ordering probabilities and depth order).
    "dps": Task("dps-synthetic", "dps", "dps-synthetic", "lam", 20.0, 1, 2, 3, True),
    "kams": Task("kams-accuracy", "kams", "kams-b", "", None, 0, 1, 4, True),
    "shm": Task("shm-depth", "shm-fast", "shm-crossing", "", None, 2, 0, 5, True),
}


@pytest.fixture(scope="module", params=sorted(TASKS))
def recorded(request):
    task = TASKS[request.param]
    return task, run_task(task), _independent_run(task)


def test_the_record_names_its_run(recorded):
    task, rec, (exp, seq, params, done) = recorded
    assert rec["key"] == {**task.key(), "value": task.value}
    assert rec["tracker"] == exp.method(task.method).tracker
    assert rec["params"] == params
    assert rec["scene_seed"] == task.scene_seed()
    assert rec["tracker_seed"] == task.tracker_seed()
    assert rec["n_frames"] == len(seq.gt.box) == len(rec["targets"][0]["state"])
    assert len(rec["targets"]) == len(done.targets) >= 1


def test_every_frame_s_measures_are_the_boxes(recorded):
    task, rec, (exp, seq, params, done) = recorded
    est = np.asarray(done.result.boxes, dtype=np.float64)
    gt = np.asarray(seq.gt.box, dtype=np.float64)
    names_ = list(seq.entities.name)
    checked = 0
    for m, k in enumerate(done.targets):
        target = rec["targets"][m]
        assert target["name"] == names_[k]
        for t in range(len(gt)):
            g = gt[t, k]
            if not np.all(np.isfinite(g)):
                assert target["state"][t] is None
                continue
            state, precision, recall, iou, err = _box_measures(est[t, m], g)
            assert target["state"][t] == int(state), (m, t)
            assert _close(target["precision"][t], precision), (m, t)
            assert _close(target["recall"][t], recall), (m, t)
            assert _close(target["iou"][t], iou), (m, t)
            assert _close(target["centre_error"][t], err), (m, t)
            checked += 1
    assert checked > 20
    # The states are not all alike, so a swapped state would show.
    states = {s for target in rec["targets"] for s in target["state"] if s is not None}
    assert 1 in states


def test_the_path_error_and_the_failure_threshold(recorded):
    task, rec, (exp, seq, params, done) = recorded
    est = np.asarray(done.result.boxes, dtype=np.float64)
    path = np.asarray(seq.gt.path_center, dtype=np.float64)
    gt = np.asarray(seq.gt.box, dtype=np.float64)
    for m, k in enumerate(done.targets):
        x, y, w, h = est[:, m].T
        for t in range(len(est)):
            err = math.hypot(x[t] + w[t] / 2 - path[t, k, 0], y[t] + h[t] / 2 - path[t, k, 1])
            assert _close(rec["targets"][m]["path_error"][t], err), (m, t)
        sizes = [
            (gt[t, k, 2] + gt[t, k, 3]) / 2 for t in range(len(gt)) if np.all(np.isfinite(gt[t, k]))
        ]
        assert _close(rec["failure_threshold"][m], sum(sizes) / len(sizes))
    if task.experiment == "kams-accuracy":
        # The path is not the drawn position: the two errors differ.
        drawn = [v for v in rec["targets"][0]["centre_error"] if v is not None]
        assert drawn != rec["targets"][0]["path_error"][: len(drawn)]


def test_particle_diagnostics(recorded):
    task, rec, (exp, seq, params, done) = recorded
    if "uniqueness" not in done.extras:
        assert "uniqueness" not in rec and "effective_dynamics" not in rec
        return
    u = np.asarray(done.extras["uniqueness"], dtype=np.float64)  # (T, K)
    ed = np.asarray(done.extras["effective_dynamics"], dtype=np.float64)  # (T, K): mean of u, v
    assert ed.shape == u.shape and u.shape[1] == len(done.targets)
    for k in range(u.shape[1]):
        vals = [u[t, k] for t in range(len(u)) if math.isfinite(u[t, k])]
        assert len(vals) == len(u) - 1  # frame 0 has none
        assert _close(rec["uniqueness"][k], 100 * sum(vals) / len(vals))
        vals = [ed[t, k] for t in range(len(ed)) if math.isfinite(ed[t, k])]
        assert _close(rec["effective_dynamics"][k], 100 * sum(vals) / len(vals))
    assert len({round(v, 3) for v in rec["uniqueness"]}) > 1  # objects differ


def test_ordering_probabilities_and_depth_order(recorded):
    task, rec, (exp, seq, params, done) = recorded
    if "order_prob" not in done.extras:
        assert not {
            "order_prob",
            "orderings",
            "true_order",
            "depth_order_accuracy",
            "overlap",
        } & set(rec)
        return
    idx = list(done.targets)
    orderings = [list(map(int, o)) for o in done.tracker.orderings]
    prob = np.asarray(done.extras["order_prob"], dtype=np.float64)
    depth = np.asarray(seq.gt.depth)[:, idx]
    gt = np.asarray(seq.gt.box, dtype=np.float64)[:, idx]
    assert rec["orderings"] == orderings
    n_t, n_m = depth.shape
    right = total = 0
    for t in range(n_t):
        assert all(_close(a, b) for a, b in zip(rec["order_prob"][t], prob[t], strict=True))
        nearest_first = sorted(range(n_m), key=lambda m, t=t: (depth[t, m], m))
        true = orderings.index(nearest_first) if nearest_first in orderings else -1
        assert rec["true_order"][t] == true
        overlapping = False
        for i in range(n_m):
            for j in range(n_m):
                if i == j or not (np.all(np.isfinite(gt[t, i])) and np.all(np.isfinite(gt[t, j]))):
                    continue
                inter = _box_measures(gt[t, i], gt[t, j])[1] * gt[t, i, 2] * gt[t, i, 3]
                small = min(gt[t, i, 2] * gt[t, i, 3], gt[t, j, 2] * gt[t, j, 3])
                if inter / small < 0.1:
                    continue
                overlapping = True
                # Frame 0 (initial boxes, no probabilities yet) is not scored.
                if i < j and t > 0 and depth[t, i] != depth[t, j]:
                    best = orderings[int(np.argmax(prob[t]))]
                    total += 1
                    right += (best.index(i) < best.index(j)) == (depth[t, i] < depth[t, j])
        assert rec["overlap"][t] == overlapping, t
    assert total > 0 and any(rec["overlap"]) and not all(rec["overlap"])
    assert _close(rec["depth_order_accuracy"], 100 * right / total)
    assert len(set(rec["true_order"])) > 1  # the order changes in the crossing
