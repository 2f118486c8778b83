"""`--param`: tracker parameters set on every method of an experiment, paired with the
default runs and recorded; and the paired comparison of two settings (kernel_quality)."""

from __future__ import annotations

import json

import pytest

from scenegen.cli.experiment import parse_overrides
from scenegen.errors import ConfigError, DataError
from scenegen.lab import kernel_quality as kq
from scenegen.lab.experiments import get, run_experiment
from scenegen.lab.experiments.outputs import write_record
from scenegen.lab.experiments.runner import (
    MAX_FILENAME,
    Task,
    load_record,
    plan_tasks,
    tracker_params,
)

NAME = "dps-synthetic"
EXP = get(NAME)
EXP_KEY = {"experiment": "shm-depth", "method": "shm", "preset": "shm-depth", "param": "",
           "value": None, "scene": 0, "run": 0, "seed": 0, "quick": False}


def test_parse_overrides_reads_json_and_keeps_words():
    assert parse_overrides(["kernel=box", "box_levels=4", "sigma=[1, 1, 0.01]",
                            "n_parts=null"]) == {
        "kernel": "box", "box_levels": 4, "sigma": [1, 1, 0.01], "n_parts": None}
    assert parse_overrides(None) == {}
    with pytest.raises(ConfigError, match="KEY=VALUE"):
        parse_overrides(["kernel"])
    with pytest.raises(ConfigError, match="given twice"):
        parse_overrides(["kernel=box", "kernel=uniform"])


def test_overridden_tasks_keep_the_default_seeds_and_carry_the_parameter():
    kw = {"runs": 2, "scenes": 2, "seed": 0, "quick": True, "methods": ["dps"]}
    plain = plan_tasks(EXP, **kw)
    boxed = plan_tasks(EXP, **kw, overrides={"kernel": "box", "box_levels": 4})
    assert len(plain) == len(boxed)
    for a, b in zip(plain, boxed, strict=True):
        assert b.overrides == (("box_levels", 4), ("kernel", "box"))
        assert (a.scene_seed(), a.tracker_seed()) == (b.scene_seed(), b.tracker_seed())
        assert a.filename() != b.filename() and "kernel-box" in b.filename()
        assert "overrides" not in a.key() and b.key()["overrides"] == b.overrides
        params = tracker_params(EXP, b)
        assert params["kernel"] == "box" and params["box_levels"] == 4
        assert "kernel" not in tracker_params(EXP, a)


def test_list_values_make_hashable_tasks():
    (task,) = plan_tasks(EXP, runs=1, scenes=1, seed=0, quick=True, methods=["dps"],
                         overrides={"sigma": [1.0, 1.0, 0.01]})
    assert task.overrides == (("sigma", (1.0, 1.0, 0.01)),)
    assert hash(task) == hash(task)
    assert tracker_params(EXP, task)["sigma"] == (1.0, 1.0, 0.01)


@pytest.mark.parametrize(("over", "match"), [
    ({"kernl": "box"}, "has no parameter 'kernl'"),
    ({"lam": 30.0}, "cannot override the swept parameter 'lam'"),
    ({"kernel": "boxx"}, "unknown kernel 'boxx'"),
    ({"box_levels": 0}, "box_levels must be"),
])
def test_overrides_a_method_does_not_accept_are_refused_before_running(over, match):
    with pytest.raises(ConfigError, match=match):
        plan_tasks(EXP, runs=1, seed=0, quick=True, overrides=over)


def test_a_parameter_only_some_methods_have_names_those_methods():
    # resample_scope belongs to PS and DPS, not to Non-PS: the line says which to name.
    occ = get("dps-occlusion")
    with pytest.raises(ConfigError) as err:
        plan_tasks(occ, runs=1, seed=0, quick=True, overrides={"resample_scope": "placed"})
    assert str(err.value).startswith(
        "method 'nonps' (tracker 'joint-pf') has no parameter 'resample_scope'; of "
        "dps-occlusion's methods only ps-123, ps-231, ps-312, dps have it: name them, "
        "--method ps-123 --method ps-231 --method ps-312 --method dps; its parameters: ")
    named = ["ps-123", "ps-231", "ps-312", "dps"]
    tasks = plan_tasks(occ, runs=1, scenes=1, seed=0, quick=True, methods=named,
                       overrides={"resample_scope": "placed"})
    assert sorted({t.method for t in tasks}) == sorted(named)
    # DPS's mixture belongs to DPS alone: one method, named in the singular.
    with pytest.raises(ConfigError, match="only dps has it: name it, --method dps; its "):
        plan_tasks(occ, runs=1, seed=0, quick=True, overrides={"mixture": "prior"})
    with pytest.raises(ConfigError, match="; no method of dps-occlusion has it; its param"):
        plan_tasks(occ, runs=1, seed=0, quick=True, overrides={"kernl": "box"})


def test_kams_trackers_refuse_the_box_kernel():
    with pytest.raises(ConfigError, match="method 'kams'"):
        plan_tasks(get("kams-robustness"), runs=1, seed=0, quick=True,
                   overrides={"kernel": "box"})


def test_an_overridden_run_is_recorded_and_stale_for_the_default(tmp_path):
    res = run_experiment(NAME, tmp_path, runs=1, scenes=1, quick=True, methods=["dps"],
                         jobs=1, progress=False, figures=False, overrides={"kernel": "box"})
    assert res["overrides"] == {"kernel": "box"}
    stored = json.loads((tmp_path / "results.json").read_text())
    assert stored["overrides"] == {"kernel": "box"}
    (task,) = plan_tasks(EXP, runs=1, scenes=1, seed=0, quick=True, methods=["dps"],
                         overrides={"kernel": "box"})
    record = load_record(tmp_path / "runs" / task.filename(), task)
    assert record is not None and record["params"]["kernel"] == "box"
    (plain,) = plan_tasks(EXP, runs=1, scenes=1, seed=0, quick=True, methods=["dps"])
    # The default run's file is another one, and the overridden record does not pass for it.
    assert not (tmp_path / "runs" / plain.filename()).exists()
    assert load_record(tmp_path / "runs" / task.filename(), plain) is None


def _name(**overrides) -> str:
    (task,) = plan_tasks(EXP, runs=1, scenes=1, seed=0, quick=True, methods=["dps"],
                         overrides=overrides)
    return task.filename()


def test_equal_override_values_name_the_same_run_file():
    # n_particles=100.0 is the run of n_particles=100 (an equal task, the same tracker
    # parameters) but was stored in another file: computed again, and both files counted
    # by the readers of runs/*.json (kernel_quality).
    assert _name(n_particles=100.0) == _name(n_particles=100) == \
        "dps__dps-synthetic__lam20__n_particles-100__s000__r000.json"
    assert _name(sigma=[1, 1, 0.01]) == _name(sigma=[1.0, 1.0, 0.01])
    assert _name(sigma=[1.0, 1.0, 0.01]) != _name(sigma=[1.0, 1.0, 0.02])
    on = Task(**{**EXP_KEY, "overrides": (("use_mse", True),)})
    assert on.filename() == Task(**{**EXP_KEY, "overrides": (("use_mse", 1),)}).filename()


def test_many_or_long_overrides_keep_the_run_file_name_short():
    # Every value passes the tracker's checks; the name was 269 characters long, beyond
    # the file system's 255: "internal error: OSError: File name too long".
    over = {"sigma": [2.0000000000000004, 2.0000000000000004, 0.0010000000000000002],
            "assignment": "interleaved", "box_levels": 3, "kernel": "epanechnikov",
            "mixture": "evidence", "model": "hsv", "n_groups": 2, "n_particles": 40,
            "resample_scope": "joint", "weighting": "stage"}
    name = _name(**over)
    assert len(name) <= MAX_FILENAME
    assert name.startswith("dps__dps-synthetic__lam20__params-") and name.endswith("__r000.json")
    assert _name(**{**over, "n_groups": 3}) != name
    assert _name(**{**over, "n_particles": 40.0}) == name


def test_a_list_valued_override_resumes_and_validates(tmp_path, capsys):
    # Read back from a record, the key gives the override as a JSON list; the task must
    # still name the file it was stored in, or every resume recomputes every run (with a
    # warning each) and results.json lists files that do not exist.
    from scenegen.cli import main

    kw = dict(runs=1, scenes=1, quick=True, methods=["dps"], jobs=1, progress=False,
              overrides={"sigma": [1.0, 1.0, 0.01]})  # fmt: skip
    run_experiment(NAME, tmp_path, **kw)
    (path,) = (tmp_path / "runs").iterdir()
    (task,) = plan_tasks(EXP, runs=1, scenes=1, seed=0, quick=True, methods=["dps"],
                         overrides={"sigma": [1.0, 1.0, 0.01]})
    record = json.loads(path.read_text())
    assert path.name == task.filename() == Task(**record["key"]).filename()
    assert Task(**record["key"]) == task and load_record(path, task) is not None
    before = path.read_bytes(), path.stat().st_mtime_ns
    capsys.readouterr()
    run_experiment(NAME, tmp_path, **kw)
    assert capsys.readouterr().err == ""  # no "holds another run" warning
    assert (path.read_bytes(), path.stat().st_mtime_ns) == before  # not computed again
    listed = json.loads((tmp_path / "results.json").read_text())["records"]
    assert [ln.rsplit(" ", 1)[0] for ln in listed] == [path.name]
    assert main(["validate", str(tmp_path)]) == 0


def test_an_override_with_more_than_six_decimals_keeps_its_run(tmp_path, capsys):
    # Records round their floats to 6 decimals, the key's too: the stored key named
    # another file (validate: "no such file"), every resume warned and computed the run
    # again, and `validate --deep` reran it with the rounded value.
    from scenegen.cli import main

    over = {"sigma": [1.0, 1.0, 0.0012345678]}
    kw = dict(runs=1, scenes=1, quick=True, methods=["dps"], jobs=1, progress=False,
              overrides=over)  # fmt: skip
    run_experiment(NAME, tmp_path, **kw)
    (path,) = (tmp_path / "runs").iterdir()
    record = json.loads(path.read_text())
    assert Task(**record["key"]).filename() == path.name
    before = path.read_bytes()
    capsys.readouterr()
    run_experiment(NAME, tmp_path, **kw)
    assert capsys.readouterr().err == "" and path.read_bytes() == before
    assert main(["validate", "--deep", str(tmp_path)]) == 0


def _rate(k, n, lo, hi):
    return {"k": k, "n": n, "pct": 100.0 * k / n, "ci": [lo, hi]}


def test_compare_puts_each_value_beside_the_base_interval():
    base = {"m": {"DPS": {"success": _rate(8, 10, 49.0, 94.3),
                          "precision": {"mean": 80.0, "ci": [78.0, 82.0], "n": 10}},
                  "only_base": _rate(1, 2, 9.5, 90.5)}}
    other = {"m": {"DPS": {"success": _rate(5, 10, 23.7, 76.3),
                           "precision": {"mean": 81.0, "ci": [79.0, 83.0], "n": 10}}}}
    rows = kq.compare("x", base, other)
    by_path = {r.path: r for r in rows}
    assert set(by_path) == {"m/DPS/success", "m/DPS/precision"}
    assert by_path["m/DPS/success"].kind == "rate" and by_path["m/DPS/success"].inside
    assert by_path["m/DPS/precision"].kind == "mean" and by_path["m/DPS/precision"].inside
    worse = kq.compare("x", base, {"m": {"DPS": {"success": _rate(2, 10, 5.7, 51.0)}}})
    assert [r.inside for r in worse] == [False]
    text = kq.render(rows + worse, base="epan", other="box", metrics=["success"])
    assert "| x | m/DPS/success | 80.0 [49.0–94.3] (10) | 50.0 [23.7–76.3] (10) | yes |" in text
    assert "**no**" in text and "1 of 2 values of box inside epan's interval" in text


def _run_record(side: str, scene: int) -> dict:
    """A sound run record (two frames, one target), marked with its side."""
    series = {f: [1.0, 1.0] for f in ("precision", "recall", "iou", "centre_error",
                                       "path_error")}  # fmt: skip
    return {"key": {"experiment": NAME, "method": "dps", "preset": "dps-synthetic",
                    "param": "", "value": None, "scene": scene, "run": 0, "seed": 0,
                    "quick": True},
            "tracker": "dps", "params": {}, "scene_digest": "0" * 64, "scene_seed": 0,
            "tracker_seed": 0, "n_frames": 2, "failure_threshold": 0.5, "side": side,
            "targets": [{"name": "a", "state": [1, 1], **series}]}


def _write_sides(root, sides) -> None:
    for side, n in sides:
        for i in range(n):
            write_record(root / "exp" / side / "runs" / f"r{i}.json", _run_record(side, i))


def test_compare_root_summarises_both_sides_and_adds_shared_runs(tmp_path, monkeypatch):
    _write_sides(tmp_path, (("base", 2), ("other", 1), ("shared", 1)))
    seen = {}

    def fake_summary(name, records):
        sides = sorted(r["side"] for r in records)
        seen[sides[0] if sides[0] != "shared" else sides[-1]] = sides
        k = len(records)
        return {"M": {"success": _rate(k, 4, 10.0 * k, 30.0 * k)}}

    monkeypatch.setattr(kq, "summary_of", fake_summary)
    (row,) = kq.compare_root(tmp_path)
    assert seen == {"base": ["base", "base", "shared"], "other": ["other", "shared"]}
    assert (row.experiment, row.path, row.base, row.other) == ("exp", "M/success", 75.0, 50.0)
    assert row.inside  # 50 in [30, 90]
    out = tmp_path / "t.md"
    assert kq.main([str(tmp_path), "-o", str(out)]) == 0
    assert "M/success" in out.read_text()


@pytest.mark.parametrize("damage", ["edit", "truncate", "unseal"])
def test_a_damaged_or_edited_run_record_is_one_line(tmp_path, capsys, damage):
    # Records were parsed as plain JSON: an edited one counted as it read, a truncated
    # one ended in a JSONDecodeError traceback.
    _write_sides(tmp_path, (("base", 2), ("other", 2)))
    path = tmp_path / "exp" / "other" / "runs" / "r1.json"
    doc = json.loads(path.read_text())
    if damage == "edit":
        doc["targets"][0]["state"] = [0, 0]
        path.write_text(json.dumps(doc))
    elif damage == "truncate":
        path.write_bytes(path.read_bytes()[:40])
    else:
        del doc["sha256"]
        path.write_text(json.dumps(doc))
    with pytest.raises(DataError, match="r1.json"):
        kq.load_records([tmp_path / "exp" / "other"])
    capsys.readouterr()
    assert kq.main([str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert err.startswith("python -m scenegen.lab.kernel_quality: error: ") and "r1.json" in err
    assert err.count("\n") == 1


def test_a_root_that_is_not_a_folder_is_a_usage_error(tmp_path, capsys):
    with pytest.raises(SystemExit) as info:
        kq.main([str(tmp_path / "missing")])
    assert info.value.code == 2 and "is not a folder" in capsys.readouterr().err


@pytest.mark.parametrize(("name", "made", "says"), [
    ("nosuch", [], "unknown experiment 'nosuch'; valid experiments: dps-synthetic"),
    ("kams-accuracy", [], "experiment 'kams-accuracy': no "),
    ("kams-accuracy", ["base"], "kams-accuracy/other folder"),
])
def test_an_experiment_asked_for_must_be_there(tmp_path, capsys, name, made, says):
    """--experiment with an unknown name was a ConfigError traceback; a known one without
    its folders printed an empty table and exit 0, as if nothing differed."""
    for side in made:
        (tmp_path / name / side).mkdir(parents=True)
    with pytest.raises(SystemExit) as info:
        kq.main([str(tmp_path), "--experiment", name])
    err = capsys.readouterr().err
    assert info.value.code == 2 and says in err and "Traceback" not in err
    with pytest.raises(ConfigError, match=says.split(";")[0]):
        kq.compare_root(tmp_path, [name])


@pytest.mark.parametrize(("name", "plan", "options"), [
    ("shm-depth", {}, ""),
    ("dps-synthetic", {"quick": True}, "--quick"),
    ("dps-synthetic", {"runs": 2, "scenes": 3, "seed": 4, "methods": ["ps-1234567", "dps"],
                       "values": [30.0, 50.0], "overrides": {"weighting": "placed",
                                                             "sigma": [1.0, 1.0, 0.01]}},
     "--scenes 3 --runs 2 --seed 4 --method ps-1234567 --method dps --value 30 --value 50 "
     "--param 'sigma=[1.0, 1.0, 0.01]' --param weighting=placed"),
    ("kams-accuracy", {"scenes": 1, "quick": True, "methods": ["kams"],
                       "overrides": {"kernel": "epanechnikov", "n_layers": 4}},
     "--scenes 1 --quick --method kams --param kernel=epanechnikov --param n_layers=4"),
])
def test_rerun_command_plans_exactly_the_runs_it_was_made_from(name, plan, options):
    import dataclasses
    import shlex

    from scenegen.cli import _parser
    from scenegen.lab.experiments.outputs import rerun_command

    exp = get(name)
    kw = {"runs": exp.runs, "seed": 0, "quick": False, **plan}
    tasks = plan_tasks(exp, **kw)
    command = rerun_command(exp, [dataclasses.asdict(t) for t in tasks], "out/x")
    assert command == " ".join(filter(None, ["scenegen experiment", name, options, "-o out/x"]))
    args = _parser().parse_args(shlex.split(command)[1:])
    again = plan_tasks(get(args.name), runs=args.runs or exp.runs, scenes=args.scenes,
                       seed=args.seed, quick=args.quick, methods=args.method,
                       values=args.value, overrides=parse_overrides(args.param))
    assert again == tasks


def _sweeps(plan, seed=0, **restrict):
    """Per experiment, the run keys of `scenegen experiment all` with per-experiment
    (S, R, quick) ``plan`` (missing: the experiment's own S x R, not quick)."""
    import dataclasses

    from scenegen.lab.experiments import names

    out = {}
    for name in names():
        exp = get(name)
        s, r, q = plan.get(name, (exp.scenes, exp.runs, False))
        tasks = plan_tasks(exp, runs=r, scenes=s, seed=seed, quick=q,
                           **restrict.get(name, {}))
        out[name] = [dataclasses.asdict(t) for t in tasks]
    return out


def _uniform(s, r, q):
    from scenegen.lab.experiments import names

    return dict.fromkeys(names(), (s, r, q))


@pytest.mark.parametrize(("plan", "seed", "restrict", "command"), [
    ({}, 0, {}, "scenegen experiment all -o out/x"),
    ({}, 7, {}, "scenegen experiment all --seed 7 -o out/x"),
    ("demo", 0, {}, "scenegen demo -o out/x"),
    ("uniform", 3, {}, "scenegen experiment all --scenes 2 --runs 1 --seed 3 --quick -o out/x"),
    # The demo's counts on another seed: `scenegen demo` runs seed 0 only, and its S
    # differ by experiment, which `all` cannot say.
    ("demo", 5, {}, None),
    # A restricted sweep, or one with a tracker parameter: `all` cannot plan it.
    ({}, 0, {"shm-depth": {"methods": ["kalman"]}}, None),
    ({}, 0, {"kams-accuracy": {"methods": ["kams"], "overrides": {"n_layers": 4}}}, None),
])
def test_report_rerun_command_plans_exactly_the_folders_runs(plan, seed, restrict, command):
    import shlex

    from scenegen.cli import _parser
    from scenegen.lab.experiments.definitions import DEMO_PLAN
    from scenegen.lab.experiments.outputs import report_rerun_command

    if isinstance(plan, str):
        plan = {"demo": DEMO_PLAN, "uniform": _uniform(2, 1, True)}[plan]
    sweeps = _sweeps(plan, seed, **restrict)
    assert report_rerun_command(sweeps, "out/x") == command
    if command is None:
        return
    args = _parser().parse_args(shlex.split(command)[1:])
    if args.func.__name__ == "cmd_demo":
        again = _sweeps(DEMO_PLAN, 0)  # what run_demo_experiments plans
    else:
        again = _sweeps({n: (args.scenes or get(n).scenes, args.runs or get(n).runs,
                             args.quick) for n in sweeps}, args.seed)  # fmt: skip
    assert again == sweeps


def test_report_rerun_command_needs_every_experiment_and_one_seed():
    from scenegen.lab.experiments.outputs import report_rerun_command

    sweeps = _sweeps({})
    assert report_rerun_command({k: v for k, v in sweeps.items() if k != "shm-depth"},
                                "d") is None  # fmt: skip
    other = _sweeps({}, seed=1)
    assert report_rerun_command({**sweeps, "shm-depth": other["shm-depth"]}, "d") is None
    mixed = _sweeps({"shm-depth": (3, 1, False)})
    assert report_rerun_command(mixed, "d") is None  # S = 3 for one, defaults elsewhere
    same = _sweeps(_uniform(3, 2, False))
    assert report_rerun_command(same, "d") == "scenegen experiment all --scenes 3 --runs 2 -o d"
