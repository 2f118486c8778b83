"""Benchmarking trackers over a dataset: same results on any executor, resume, the report."""

import json
import shutil
from pathlib import Path

import pytest

from scenegen.datasets import build_dataset
from scenegen.lab.benchmark import leaderboard, run_benchmark, run_file

TWO = {
    "width": 64, "height": 48, "n_frames": 5,
    "entities": [
        {"name": "a", "role": "target", "position": [18, 20], "depth": 0,
         "appearance": {"shape": "ellipse", "size": [12, 12], "pattern": "sectors",
                        "colors": [[230, 30, 30], [30, 60, 230]]},
         "motion": {"x": {"sigma": 0.5, "boundary": "reflect", "margin": 1},
                    "y": {"sigma": 0.5, "boundary": "reflect", "margin": 1}}},
        {"name": "b", "role": "target", "position": [44, 28], "depth": 1,
         "appearance": {"shape": "rect", "size": [10, 10], "pattern": "checker",
                        "colors": [[30, 170, 30], [240, 210, 0]]}},
    ],
    "clutter": [{"count": 0, "appearance": {"size": [6, 6]}, "min_size": 3}],
}  # fmt: skip
FAMILY = {
    "name": "two",
    "base": TWO,
    "sweep": {"clutter[0].count": [0, 8]},
    "vary": {"entities[a].position_noise": {"uniform": [0.0, 2.0]}},
    "count": 4,
}
TRACKERS = ["sok", "annealed"]
PARAMS = {"n_particles": 16, "n_layers": 2}


def files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file()}  # fmt: skip


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench") / "ds"
    build_dataset(FAMILY, out, jobs=1, shard_size=3)
    return out


@pytest.fixture(scope="module")
def reference(dataset, tmp_path_factory):
    out = tmp_path_factory.mktemp("bench") / "ref"
    run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=1)
    return out


def test_report(reference):
    res = json.loads((reference / "results.json").read_text())
    assert [e["tracker"] for e in res["leaderboard"]] == sorted(
        TRACKERS, key=lambda t: -next(e["auc"] for e in res["leaderboard"] if e["tracker"] == t)
    )
    assert res["params"] == {"sok": {}, "annealed": PARAMS}
    assert len(res["scores"]) == 8
    row = res["scores"][0]
    assert row["targets"] == 2 and None not in (row["mota"], row["idf1"], row["hota"])
    assert set(row["params"]) == {"clutter[0].count", "entities[a].position_noise"}
    axes = {(c["axis"], c["metric"]) for c in res["curves"]}
    assert ("clutter[0].count", "success") in axes and ("entities[a].position_noise", "auc") in axes
    page = (reference / "index.html").read_text()
    assert "Leaderboard" in page and "MOTA" in page and "HOTA" in page
    pngs = sorted(p.name for p in reference.glob("curve-*.png"))
    assert pngs and all(f'src="{p}"' in page for p in pngs)
    csv = (reference / "scores.csv").read_text().splitlines()
    assert len(csv) == 9 and csv[0].startswith("tracker,index,name,targets,clutter[0].count")


def test_combined_columns_are_trackevals_combined_row(dataset, reference):
    """MOTA/IDF1/HOTA (combined): the multi-target sequences' scores taken as one by
    mot.combine (TrackEval's COMBINED_SEQ; test_trackeval_oracle), from each run redone
    here, not the mean of the sequences' values; shown on both pages."""
    from scenegen.evaluation import evaluate
    from scenegen.evaluation.mot import combine
    from scenegen.io import read
    from scenegen.lab.benchmark import plan_benchmark
    from scenegen.lab.run import run

    res = json.loads((reference / "results.json").read_text())
    _, tasks = plan_benchmark(dataset, TRACKERS, PARAMS)
    for entry in res["leaderboard"]:
        parts = []
        for task in (t for t in tasks if t.tracker == entry["tracker"]):
            seq = read(Path(task.root) / task.file, task.name)
            out = run(seq, task.tracker, dict(task.params), task.tracker_seed(),
                      single_thread=True).result  # fmt: skip
            parts.append(evaluate(seq, out.boxes, out.target_ids).overall.mot.scores)
        want = combine(parts)
        got = (entry["mota_combined"], entry["idf1_combined"], entry["hota_combined"])
        assert got == pytest.approx((want.clear.mota, want.identity.idf1, want.hota.hota),
                                    abs=2e-6)  # fmt: skip
    # Equal-length sequences with two targets each: MOTA's mean is its combined value,
    # HOTA's (a square root of products) is not.
    mean = [e["hota"] for e in res["leaderboard"]]
    assert [e["hota_combined"] for e in res["leaderboard"]] != pytest.approx(mean, abs=1e-4)
    for page in ("leaderboard.md", "index.html"):
        text = (reference / page).read_text()
        assert "MOTA (combined)" in text and "COMBINED_SEQ" in text


def test_combined_columns_need_every_runs_counts(reference):
    """A tracker whose multi-target runs lack counts (recorded before them) or that has
    none gets None, not a sum over some of its runs; malformed counts are named."""
    from scenegen.lab.benchmark import combined_scores
    from scenegen.lab.benchmark_outputs import read_record, record_problems

    recs = [read_record(p) for p in sorted((reference / "runs").rglob("*.json"))]
    full = combined_scores(recs)
    assert all(v is not None for per in full.values() for v in per.values())
    old = [dict(r) for r in recs]
    del old[0]["mot_counts"]
    part = combined_scores(old)
    first = old[0]["key"]["tracker"]
    assert set(part[first].values()) == {None}
    assert all(part[t] == full[t] for t in part if t != first)
    single = [{**r, "targets": 1} for r in recs]
    assert all(set(v.values()) == {None} for v in combined_scores(single).values())
    assert record_problems(old[0]) == []
    for bad in ({}, {**recs[0]["mot_counts"], "hota_tp": [1.0] * 18},
                {**recs[0]["mot_counts"], "tp": "3"}):
        assert record_problems({**recs[0], "mot_counts": bad}) == [
            "mot_counts is not the counts of scenegen.evaluation.mot.mot_counts"]


def test_same_results_with_two_processes_and_resume(dataset, reference, tmp_path):
    out = tmp_path / "b"
    run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=2)
    assert files(out) == files(reference)
    ran = []
    run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=2, on_done=ran.append)
    assert ran == [] and files(out) == files(reference)
    # Other parameters: the stored runs of that tracker are stale and run again.
    run_benchmark(dataset, TRACKERS, out, params={**PARAMS, "n_particles": 8}, jobs=1,
                  on_done=ran.append)  # fmt: skip
    assert sorted({t.tracker for t in ran}) == ["annealed"] and len(ran) == 4


def test_leaderboard_means_skip_undefined():
    rows = [{"tracker": "x", "auc": 0.5, "mota": None}, {"tracker": "x", "auc": 0.7, "mota": 0.2},
            {"tracker": "y", "auc": 0.9, "mota": None}]  # fmt: skip
    board = leaderboard(rows, ["x", "y"])
    assert [e["tracker"] for e in board] == ["y", "x"]
    assert board[1]["auc"] == pytest.approx(0.6) and board[1]["mota"] == pytest.approx(0.2)
    assert board[0]["mota"] is None and board[0]["rank"] == 1


def test_leaderboard_intervals_cover_the_mean_as_a_bootstrap_should():
    import numpy as np

    vals = np.random.default_rng(3).normal(0.6, 0.1, 60)
    rows = [{"tracker": "x", "auc": float(v)} for v in vals] + [{"tracker": "y", "auc": 0.4}]
    x, y = leaderboard(rows, ["x", "y"])
    lo, hi = x["auc_ci"]
    assert lo < x["auc"] < hi and vals.min() < lo and hi < vals.max()
    # The interval of a mean: about ± 1.96 sd / sqrt(n).
    half = 1.96 * vals.std(ddof=1) / np.sqrt(vals.size)
    assert (hi - lo) / 2 == pytest.approx(half, rel=0.15)
    assert y["auc_ci"] is None and y["mota_ci"] is None  # one value, no metric
    assert leaderboard(rows, ["x", "y"]) == [x, y]  # seeded


@pytest.mark.slow  # the Dask path of the shared executor is in the fast dataset tests
def test_same_results_on_a_dask_cluster(dataset, reference, tmp_path):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(
        n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None
    ) as cluster:
        run_benchmark(dataset, TRACKERS, tmp_path / "b", params=PARAMS,
                      scheduler=cluster.scheduler_address)  # fmt: skip
    assert files(tmp_path / "b") == files(reference)


def test_validate_and_deep_find_what_each_can(dataset, reference, tmp_path, capsys):
    from scenegen.cli import main
    from scenegen.io.sealed import read_sealed_json, write_sealed_json
    from scenegen.lab.benchmark import write_outputs
    from scenegen.lab.benchmark_outputs import check_benchmark, read_record

    assert main(["validate", str(reference)]) == 0
    assert capsys.readouterr().out.strip() == f"{reference}: valid benchmark folder"
    res = read_sealed_json(reference / "results.json")
    assert res["dataset"]["path"] == str(dataset.resolve())
    assert res["dataset"]["axes"] == ["clutter[0].count", "entities[a].position_noise"]
    assert len(res["records"]) == 8 and res["records"][0].startswith("runs/sok/00000.json ")

    # A score edited, the record resealed and every output rewritten from it: only the
    # runs computed again (--deep, from the dataset results.json names) can tell.
    out = tmp_path / "b"
    shutil.copytree(reference, out)
    names = [e.split(" ")[0] for e in res["records"]]
    recs = [read_record(out / n) for n in names]
    recs[3]["scores"]["auc"] = round(recs[3]["scores"]["auc"] / 2, 6)
    write_sealed_json(out / names[3], recs[3])
    write_outputs(out, res["dataset"], res["trackers"], recs)
    assert check_benchmark(out) == []
    assert check_benchmark(out, deep=True) == [f"{out / names[3]}: differs from the run "
                                               "computed again"]  # fmt: skip
    # Without the dataset, --deep says so in one line; the folder itself stays valid.
    moved = tmp_path / "moved"
    shutil.copytree(reference, moved)
    doc = read_sealed_json(moved / "results.json")
    doc["dataset"]["path"] = str(tmp_path / "nowhere")
    write_outputs(moved, doc["dataset"], doc["trackers"],
                  [read_record(moved / n) for n in names])  # fmt: skip
    assert check_benchmark(moved) == []
    (line,) = check_benchmark(moved, deep=True)
    assert line.startswith(f"{moved / 'results.json'}: --deep needs the dataset it was "
                           f"computed on, at {tmp_path / 'nowhere'}")  # fmt: skip


def test_damaged_or_old_outputs_are_named_and_run_again(dataset, reference, tmp_path, capsys):
    from scenegen.io.sealed import read_sealed_json, seal
    from scenegen.lab.benchmark_outputs import check_benchmark, is_benchmark_folder

    out = tmp_path / "b"
    shutil.copytree(reference, out)
    run = out / "runs" / "annealed" / "00002.json"
    doc = read_sealed_json(run)
    doc["scores"]["success"] = 0.0
    run.write_text(json.dumps(seal(doc)))  # edited and correctly resealed
    (out / "leaderboard.md").write_text("| rank |\n")
    problems = check_benchmark(out)
    assert problems == [f"{run}: is not the run results.json was computed from (edited or "
                        "replaced since)"]  # fmt: skip
    ran = []
    run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=1, on_done=ran.append)
    assert [(t.tracker, t.index) for t in ran] == [("annealed", 2)]
    assert capsys.readouterr().err.strip() == (
        f"scenegen: warning: {run}: is not the run results.json lists (edited or replaced "
        "since); running it again")  # fmt: skip
    assert files(out) == files(reference) and check_benchmark(out) == []
    # A folder written before outputs were sealed: named, with the command that redoes it.
    old = tmp_path / "old"
    shutil.copytree(reference, old)
    body = read_sealed_json(old / "results.json")
    (old / "results.json").write_text(json.dumps(body))
    assert is_benchmark_folder(old) and not is_benchmark_folder(dataset)
    assert check_benchmark(old) == [
        f"{old / 'results.json'}: no sha256 digest (written by an older version of scenegen, "
        "or edited): run the same `scenegen benchmark` command again into this folder to "
        "recompute it"]  # fmt: skip
    for p in (old / "runs").rglob("*.json"):
        p.write_text(json.dumps(read_sealed_json(p)))
    run_benchmark(dataset, TRACKERS, old, params=PARAMS, jobs=1)
    warned = capsys.readouterr().err.splitlines()
    assert len(warned) == 8 and all("no sha256 digest" in w for w in warned)
    assert files(old) == files(reference)


@pytest.mark.parametrize("page", ["scores.csv", "leaderboard.md", "index.html"])
def test_each_page_and_figure_is_checked_against_results(reference, tmp_path, page):
    from scenegen.lab.benchmark_outputs import check_benchmark

    out = tmp_path / "b"
    shutil.copytree(reference, out)
    text = (out / page).read_text()
    (out / page).write_text(text.replace("0.", "1.", 1))  # one digit
    assert check_benchmark(out) == [f"{out / page}: is not the {page} of results.json (damaged "
                                    "or edited: run the same `scenegen benchmark` command "
                                    "again into this folder to recompute it)"]  # fmt: skip
    (out / page).write_text(text)
    figure = sorted(out.glob("curve-*.png"))[1]
    whole = figure.read_bytes()
    figure.write_bytes(whole[1:])
    assert check_benchmark(out) == [f"{figure}: not a PNG file (damaged)"]
    figure.write_bytes(whole[:-10])  # the signature is right
    assert check_benchmark(out) == [f"{figure}: not a whole PNG image (it does not end with "
                                    "the IEND chunk) (damaged)"]  # fmt: skip
    figure.unlink()
    assert check_benchmark(out)[0].startswith(f"{figure}: missing (run the same")


USER_TRACKER = '''
from types import SimpleNamespace

import numpy as np


class Jitter:
    """Keeps the initial boxes, moved each frame by a seeded jitter of ``jitter`` px."""

    def __init__(self, jitter, rng):
        self.sigma, self.rng = float(jitter), np.random.default_rng(rng)

    def init(self, frame, boxes):
        self.boxes = np.asarray(boxes, dtype=float).copy()

    def step(self, frame):
        b = self.boxes.copy()
        b[:, :2] += self.rng.normal(0.0, self.sigma, (len(b), 2))
        return SimpleNamespace(boxes=b)


def make(jitter=1.0, rng=None):
    return Jitter(jitter, rng)
'''


def test_a_users_factory_and_opencv_go_through_the_benchmark(dataset, tmp_path, capsys):
    from scenegen.cli import main
    from scenegen.errors import ConfigError
    from scenegen.io.sealed import read_sealed_json
    from scenegen.lab.benchmark_outputs import check_benchmark

    mod = tmp_path / "mine.py"
    mod.write_text(USER_TRACKER)
    spec = f"{mod}:make"
    one, two = tmp_path / "one", tmp_path / "two"
    run_benchmark(dataset, [spec, "annealed"], one, params={"jitter": 2.0, **PARAMS}, jobs=1)
    run_benchmark(dataset, [spec, "annealed"], two, params={"jitter": 2.0, **PARAMS}, jobs=2)
    res = read_sealed_json(one / "results.json")
    assert res["params"] == {spec: {"jitter": 2.0}, "annealed": PARAMS}
    assert {r["tracker"] for r in res["scores"]} == {spec, "annealed"}
    assert sorted(p.name for p in (one / "runs").iterdir()) == ["annealed", "mine.py_make"]
    assert files(one).keys() == files(two).keys()
    assert all(files(one)[k] == files(two)[k] for k in files(one) if k.startswith("runs/"))
    skipped: list[str] = []
    assert check_benchmark(one, deep=True, skipped=skipped) == [] and skipped == []
    with pytest.raises(ConfigError, match=r"--param window: no tracker of .*mine.py:make"):
        run_benchmark(dataset, [spec], tmp_path / "x", params={"window": 3})
    with pytest.raises(ConfigError, match=r"is the dataset folder \(manifest.json\); write"):
        run_benchmark(dataset, [spec], dataset)
    with pytest.raises(ConfigError, match="mine.py has no attribute 'nope'"):
        run_benchmark(dataset, [f"{mod}:nope"], tmp_path / "x")
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "mine.py").write_text(USER_TRACKER)
    with pytest.raises(ConfigError, match=r"would share the run folder runs/mine.py_make"):
        run_benchmark(dataset, [spec, f"{tmp_path / 'sub' / 'mine.py'}:make"], tmp_path / "x")
    # OpenCV's MIL through the adapter: its derived 63-bit seeds reach cv2 as C ints; it is
    # not deterministic, so --deep does not run it again (and says how many it skipped).
    cv = tmp_path / "cv"
    with pytest.raises(ConfigError, match="opencv': unknown parameter 'n_(particles|layers)' "
                       "for cv2.TrackerMIL"):
        run_benchmark(dataset, ["trackers.adapters:opencv", "annealed"], cv,
                      params={"name": "MIL", **PARAMS})  # fmt: skip
    assert not (cv / "runs").exists()
    run_benchmark(dataset, ["trackers.adapters:opencv"], cv, params={"name": "MIL"}, jobs=1)
    assert main(["validate", str(cv), "--deep"]) == 0
    assert capsys.readouterr().out.strip() == (
        f"{cv}: valid benchmark folder (4 runs of trackers that are not deterministic not "
        "run again)")  # fmt: skip


def _paths(x, prefix=()):
    out = [prefix] if prefix else []
    items = x.items() if isinstance(x, dict) else enumerate(x) if isinstance(x, list) else ()
    for k, v in items:
        out += _paths(v, (*prefix, k))
    return out


def _get(x, path):
    for k in path:
        x = x[k]
    return x


def _retyped(v):
    """A value of another JSON type than ``v``."""
    if isinstance(v, dict):
        return [v]
    if isinstance(v, list):
        return {"0": v}
    if isinstance(v, str):
        return [v]
    if v is None or isinstance(v, bool):
        return {"x": v}
    return str(v)


def _changed(v):
    """Another value of the same JSON type as the leaf ``v``."""
    if isinstance(v, bool):
        return not v
    if isinstance(v, str):
        return v + "x"
    if isinstance(v, (int, float)):
        return v + 1
    return 0  # None


@pytest.mark.parametrize("how", ["retyped", "changed"])
@pytest.mark.parametrize("target", ["results.json", "runs/sok/00001.json"])
def test_every_value_edited_and_resealed_is_one_line(reference, tmp_path, target, how):
    # Each value of the file (any container or leaf) replaced by one of another JSON type,
    # or each leaf by another value of its type, and the file correctly resealed: validate
    # names the folder's file at fault in a line or two, and never raises.
    from scenegen.io.sealed import read_sealed_json, seal
    from scenegen.lab.benchmark_outputs import check_benchmark

    body = read_sealed_json(reference / target)
    paths = [p for p in _paths(body) if p[0] != "sha256"]
    edit = _retyped
    if how == "changed":
        edit = _changed
        paths = [p for p in paths if not isinstance(_get(body, p), (dict, list))]
    assert len(paths) > 20
    out = tmp_path / "b"
    shutil.copytree(reference, out)
    for p in paths:
        doc = json.loads(json.dumps(body))
        parent = doc
        for k in p[:-1]:
            parent = parent[k]
        parent[p[-1]] = edit(parent[p[-1]])
        (out / target).write_text(json.dumps(seal(doc)))
        problems = check_benchmark(out)
        assert 1 <= len(problems) <= 2 and all(ln.startswith(str(out)) for ln in problems), (
            p, problems)


def test_a_dataset_is_not_written_into_a_benchmark_folder(reference, tmp_path):
    from scenegen.errors import ConfigError

    out = tmp_path / "b"
    shutil.copytree(reference, out)
    with pytest.raises(ConfigError, match=f"^-o {out}: is a benchmark output folder "):
        build_dataset(FAMILY, out, jobs=1)
    assert files(out) == files(reference)


def test_benchmarks_and_experiments_do_not_overwrite_each_other(dataset, reference, tmp_path,
                                                                capsys):
    # Each exited 0 after replacing the other's results.json (and index.html).
    from scenegen.cli import main

    bench = tmp_path / "b"
    shutil.copytree(reference, bench)
    assert main(["experiment", "shm-depth", "--quick", "--scenes", "1", "--method", "kalman",
                 "-o", str(bench)]) == 2  # fmt: skip
    assert capsys.readouterr().err.strip() == (
        f"scenegen: error: -o {bench}: holds the outputs of `scenegen benchmark`; choose "
        "another folder")  # fmt: skip
    assert files(bench) == files(reference)
    exp = tmp_path / "e"
    (exp / "runs").mkdir(parents=True)
    (exp / "results.json").write_text('{"experiment": "shm-depth"}')
    before = files(exp)
    assert main(["benchmark", str(dataset), "--tracker", "kalman", "-o", str(exp)]) == 2
    assert "holds the results of `scenegen experiment`" in capsys.readouterr().err
    assert files(exp) == before


def test_a_named_axis_is_plotted_by_its_values(tmp_path):
    import csv

    from scenegen.datasets import open_dataset

    named = {"name": "sizes", "base": TWO, "count": 2, "set": {"n_frames": 3},
             "sweep": {"size": {"entities[a].appearance.size[0]": [10, 14],
                                "entities[b].appearance.size[0]": [10, 14]}}}  # fmt: skip
    data = tmp_path / "ds"
    build_dataset(named, data, jobs=1)
    ds = open_dataset(data)
    assert [e["params"]["size"] for e in ds.entries] == [0, 1]  # the manifest: positions
    assert [e["index"] for e in ds.select(size=1).entries] == [1]
    res = run_benchmark(data, ["kalman"], tmp_path / "b", jobs=1)
    curve = next(c for c in res["curves"] if c["axis"] == "size")
    assert curve["labels"] == ["10", "14"] and curve["x"] == [10.0, 14.0]
    rows = list(csv.DictReader((tmp_path / "b" / "scores.csv").open()))
    assert [r["size"] for r in rows] == ["10", "14"]
    # A record stored with the position (as before) is run again, silently.
    from scenegen.io.sealed import read_sealed_json, write_sealed_json

    run = tmp_path / "b" / "runs" / "kalman" / "00001.json"
    rec = read_sealed_json(run)
    rec["sequence_params"]["size"] = 1
    write_sealed_json(run, rec)
    (tmp_path / "b" / "results.json").unlink()
    ran = []
    run_benchmark(data, ["kalman"], tmp_path / "b", jobs=1, on_done=ran.append)
    assert [t.index for t in ran] == [1]
    assert read_sealed_json(run)["sequence_params"]["size"] == 14


def test_a_sequence_with_no_target_at_frame_0_is_recorded_unscored(tmp_path, capsys):
    from scenegen.cli import main

    late = {"name": "late", "base": TWO, "count": 4, "set": {"n_frames": 4},
            "sweep": {"entities[a].appear": [0, 2], "entities[b].appear": [0, 2]}}
    data = tmp_path / "ds"
    build_dataset(late, data, jobs=1)
    res = run_benchmark(data, ["kalman"], tmp_path / "b", jobs=1)
    by_index = {r["index"]: r for r in res["scores"]}
    assert by_index[3]["targets"] == 0  # both enter at frame 2: nothing to track
    assert all(by_index[3][m] is None for m in ("auc", "success", "tracked", "mota"))
    assert by_index[0]["targets"] == 2 and by_index[0]["auc"] is not None
    (board,) = res["leaderboard"]
    assert board["sequences"] == 3  # the scored ones
    assert main(["validate", str(tmp_path / "b"), "--deep"]) == 0
    assert "valid benchmark folder" in capsys.readouterr().out
    # Kept tracks: an empty tracker file where the tracker did not run; only the sequence
    # with two targets at frame 0 in the seqmap of the combined columns.
    from scenegen.lab.benchmark_tracks import seqmap_file, track_file

    run_benchmark(data, ["kalman"], tmp_path / "b", jobs=1, keep_tracks=True)
    assert (tmp_path / "b" / track_file("kalman", "late-00003")).read_text() == ""
    assert (tmp_path / "b" / track_file("kalman", "late-00001")).read_text() != ""
    assert (tmp_path / "b" / seqmap_file("multi")).read_text() == "name\nlate-00000\n"
    assert main(["validate", str(tmp_path / "b"), "--deep"]) == 0


def _forged(reference, out, forge):
    """A copy of ``reference`` at ``out`` whose records ``forge`` changes (given the list of
    records, it edits them or returns another list), every record resealed and every output
    written again from them: sound digests and consistent pages."""
    from scenegen.io.sealed import read_sealed_json, write_sealed_json
    from scenegen.lab.benchmark import run_file, write_outputs
    from scenegen.lab.benchmark_outputs import read_record

    shutil.copytree(reference, out)
    res = read_sealed_json(out / "results.json")
    recs = [read_record(out / e.split(" ")[0]) for e in res["records"]]
    recs = forge(recs) or recs
    for rec in recs:
        write_sealed_json(out / run_file(rec["key"]["tracker"], rec["key"]["index"]), rec)
    write_outputs(out, res["dataset"], res["trackers"], recs)
    return out


def test_a_forged_benchmark_folder_is_invalid(dataset, reference, tmp_path, capsys):
    # Each was "valid benchmark folder", even with --deep: the records were trusted for
    # their own keys. They are checked against results.json's trackers and the dataset's
    # count (and with --deep, against the manifest), and a built-in tracker is deterministic.
    from scenegen.cli import main
    from scenegen.lab.benchmark_outputs import check_benchmark

    def swap(recs):  # sok's runs on sequences 0 and 1 exchanged, each kept at its index
        a, b = recs[0], recs[1]
        for k in ("name", "file", "seed", "frames_digest"):
            a["key"][k], b["key"][k] = b["key"][k], a["key"][k]
        for k in ("scores", "sequence_params", "tracker_seed", "targets", "n_frames"):
            a[k], b[k] = b[k], a[k]

    def nondeterministic(recs):  # --deep would skip the edited run
        recs[5]["deterministic"] = False
        recs[5]["scores"]["auc"] = 0.999

    out = _forged(reference, tmp_path / "swap", swap)
    assert check_benchmark(out) == []  # needs the manifest
    assert main(["validate", str(out), "--deep"]) == 1
    assert capsys.readouterr().err.splitlines() == [
        f"{out / 'runs' / 'sok' / f'0000{i}.json'}: its key is not the run of 'sok' on "
        f"sequence {i} of {dataset.resolve()} (frames_digest, name, seed differ)"
        for i in (0, 1)
    ]  # fmt: skip
    out = _forged(reference, tmp_path / "drop", lambda recs: recs[:-1])
    assert main(["validate", str(out), "--deep"]) == 1
    assert capsys.readouterr().err.strip() == (
        f"{out / 'results.json'}: lists no run of 'annealed' on sequence 3; each tracker "
        "runs once on each of the dataset's 4 sequences")  # fmt: skip
    out = _forged(reference, tmp_path / "nondet", nondeterministic)
    assert main(["validate", str(out), "--deep"]) == 1
    assert capsys.readouterr().err.strip() == (
        f"{out / 'runs/annealed/00001.json'}: says the built-in tracker 'annealed' is not "
        "deterministic (every built-in tracker is)")  # fmt: skip
    out = _forged(reference, tmp_path / "twice", lambda recs: [*recs, recs[0]])
    assert check_benchmark(out) == [f"{out / 'results.json'}: lists the run "
                                    "runs/sok/00000.json twice"]  # fmt: skip
    out = _forged(reference, tmp_path / "order", lambda recs: [recs[1], recs[0], *recs[2:]])
    assert check_benchmark(out) == [f"{out / 'results.json'}: lists the runs out of their "
                                    "order (trackers as listed, then sequences)"]  # fmt: skip


def test_an_experiment_all_report_and_a_benchmark_do_not_overwrite_each_other(
        dataset, reference, tmp_path, capsys, monkeypatch):  # fmt: skip
    # Each exited 0 after replacing the other's results.json and index.html.
    from scenegen.cli import main
    from scenegen.lab import report

    monkeypatch.setattr(report, "names", lambda: [])  # `experiment all` of no experiment
    rep = tmp_path / "rep"
    report.build_report(rep)  # what `experiment all` leaves: results.json {"experiments"}
    before = files(rep)
    assert main(["benchmark", str(dataset), "--tracker", "kalman", "-o", str(rep)]) == 2
    assert capsys.readouterr().err.strip() == (
        f"scenegen: error: -o {rep}: holds a report of `scenegen experiment all`; write the "
        "benchmark into another folder")  # fmt: skip
    assert files(rep) == before
    bench = tmp_path / "b"
    shutil.copytree(reference, bench)
    assert main(["experiment", "all", "-o", str(bench)]) == 2
    assert capsys.readouterr().err.strip() == (
        f"scenegen: error: -o {bench}: holds the outputs of `scenegen benchmark`; write the "
        "report into another folder")  # fmt: skip
    assert files(bench) == files(reference)
    assert main(["experiment", "all", "-o", str(rep)]) == 0  # its own folder: rewritten


def test_datasets_and_experiments_are_not_written_into_each_other(dataset, tmp_path, capsys,
                                                                   monkeypatch):  # fmt: skip
    from scenegen.cli import main
    from scenegen.errors import ConfigError
    from scenegen.lab import report

    exp = tmp_path / "e"
    (exp / "runs").mkdir(parents=True)
    (exp / "results.json").write_text('{"experiment": "shm-depth"}')
    (exp / "table.md").write_text("| a |\n")
    monkeypatch.setattr(report, "names", lambda: [])
    rep = tmp_path / "rep"
    report.build_report(rep)
    for folder, what in [(exp, "the results of `scenegen experiment`"),
                         (rep, "a report of `scenegen experiment all`")]:  # fmt: skip
        before = files(folder)
        with pytest.raises(ConfigError, match=rf"^-o {folder}: holds {what}; write the "
                           "dataset into another folder$"):  # fmt: skip
            build_dataset(FAMILY, folder, jobs=1)
        assert files(folder) == before
    data = tmp_path / "ds"
    shutil.copytree(dataset, data)
    before = files(data)
    assert main(["experiment", "shm-depth", "--quick", "--scenes", "1", "--runs", "1",
                 "--method", "kalman", "-o", str(data)]) == 2  # fmt: skip
    assert capsys.readouterr().err.strip() == (
        f"scenegen: error: -o {data}: is a dataset folder (manifest.json); choose another "
        "folder")  # fmt: skip
    assert main(["experiment", "all", "-o", str(data)]) == 2
    assert capsys.readouterr().err.strip() == (
        f"scenegen: error: -o {data}: is a dataset folder (manifest.json); write the report "
        "into another folder")  # fmt: skip
    assert main(["experiment", "all", "-o", str(exp)]) == 2
    assert "holds the results of `scenegen experiment`; write the report" in (
        capsys.readouterr().err)  # fmt: skip
    assert files(data) == before


def test_a_benchmark_where_no_sequence_is_scored_says_so(tmp_path, capsys):
    # It said "best AUC kalman (None)", leaderboard.md had a header row of one empty column,
    # and index.html said there was no swept axis (there is one).
    from scenegen.cli import main

    late = {"name": "late", "base": TWO, "count": 2,
            "set": {"n_frames": 3, "entities[b].appear": 2},
            "sweep": {"entities[a].appear": [1, 2]}}  # fmt: skip
    data, out = tmp_path / "ds", tmp_path / "b"
    build_dataset(late, data, jobs=1)
    assert main(["benchmark", str(data), "--tracker", "kalman", "--tracker", "sok",
                 "--jobs", "1", "-o", str(out)]) == 0  # fmt: skip
    assert capsys.readouterr().err.strip() == (
        "benchmark: 4 runs; no sequence was scored (none has a target at frame 0)")
    assert (out / "leaderboard.md").read_text() == (
        "| rank | tracker | sequences |\n"
        "|---:|---|---:|\n"
        "| 1 | kalman | 0 |\n"
        "| 2 | sok | 0 |\n\n"
        "No sequence was scored (none has a target at frame 0): no tracker has a score, and "
        "the ranks are only the order of the trackers' names.\n")  # fmt: skip
    page = (out / "index.html").read_text()
    assert "<p>No figure: no sequence was scored (none has a target at frame 0).</p>" in page
    assert "No swept or drawn axis" not in page and "Each cell: the mean" not in page
    assert main(["validate", str(out)]) == 0


def test_pages_write_json_cells_and_escape_a_pipe_in_a_trackers_name(reference):
    import csv
    import io

    from scenegen.io.sealed import read_sealed_json
    from scenegen.lab.benchmark import texts

    res = read_sealed_json(reference / "results.json")
    res["dataset"]["sequence_params"] = ["d", "t", "l", "n", "s"]
    res["scores"][0]["params"] = {"d": {"b": 2, "a": 1}, "t": True, "l": [1, 2], "n": None,
                                  "s": "x"}  # fmt: skip
    res["leaderboard"][0]["tracker"] = "my|t.py:make"
    got = texts(res)
    row = next(csv.DictReader(io.StringIO(got["scores.csv"])))  # was Python's repr
    assert [row[k] for k in "dtlns"] == ['{"a": 1, "b": 2}', "true", "[1, 2]", "", "x"]
    table = [ln for ln in got["leaderboard.md"].splitlines() if ln.startswith("|")]
    assert "| my\\|t.py:make |" in table[2]
    assert len({ln.replace("\\|", "").count("|") for ln in table}) == 1  # one column count


# --keep-tracks: the tracker outputs and the ground truth as TrackEval reads them.

ORACLE = Path(__file__).resolve().parents[2] / "data" / "trackeval_benchmark"
TOOL = Path(__file__).resolve().parents[3] / "tools" / "trackeval" / "make_benchmark_inputs.py"
_REDO = "run the same `scenegen benchmark ... --keep-tracks` command again to rewrite it"


@pytest.fixture(scope="module")
def kept(dataset, tmp_path_factory):
    out = tmp_path_factory.mktemp("bench") / "kept"
    run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=1, keep_tracks=True)
    return out


def _track(out, tracker, index):
    from scenegen.lab.benchmark_tracks import track_file

    return out / track_file(tracker, f"two-{index:05d}")


def test_kept_tracks_are_the_boxes_each_run_produced(dataset, reference, kept):
    """Each tracker file reads back as the boxes of its pair's run (ids sorted, 1-based
    pixels undone); the records and pages are those of a benchmark without the option,
    which writes no kept folder and no ``tracks`` key."""
    import numpy as np

    from scenegen.io.mot import read_mot_tracker
    from scenegen.lab.benchmark import plan_benchmark, run_pair_tracks
    from scenegen.lab.benchmark_outputs import check_benchmark

    _, tasks = plan_benchmark(dataset, TRACKERS, PARAMS)
    for task in tasks:
        rec, res = run_pair_tracks(task)
        ids, boxes = read_mot_tracker(_track(kept, task.tracker, task.index), rec["n_frames"])
        order = np.argsort(res.target_ids)
        assert ids.tolist() == sorted(res.target_ids.tolist()) and len(ids) == 2
        np.testing.assert_allclose(boxes, res.boxes[:, order], rtol=0, atol=1e-9)
    mine, theirs = files(kept), files(reference)
    assert {n: b for n, b in mine.items() if not n.startswith("trackeval/")
            and n != "results.json"} == {n: b for n, b in theirs.items()
                                         if n != "results.json"}  # fmt: skip
    res, ref = (json.loads((f / "results.json").read_text()) for f in (kept, reference))
    assert set(res) - set(ref) == {"tracks"} and len(res["tracks"]) == 2 + 2 * 4 + 2 * 4
    assert {k: v for k, v in res.items() if k not in ("tracks", "sha256")} == {
        k: v for k, v in ref.items() if k != "sha256"}
    assert not (reference / "trackeval").exists()
    assert check_benchmark(kept) == []
    gt = (kept / "trackeval/gt/mot_challenge/scenegen-all/two-00000/gt/gt.txt").read_text()
    assert gt.splitlines()[0].endswith(",1,1,1.000000") and len(gt.splitlines()) == 10
    seqmap = (kept / "trackeval/gt/mot_challenge/seqmaps/scenegen-all.txt").read_text()
    assert seqmap == "name\n" + "".join(f"two-{i:05d}\n" for i in range(4))


def test_resume_writes_the_missing_tracks_and_keeps_the_records(dataset, reference, kept,
                                                                tmp_path):  # fmt: skip
    """--keep-tracks on a folder made without it runs every pair again for its tracks, the
    records staying byte for byte; a lost tracker file is run again, even without the
    option (results.json lists kept tracks), and nothing else."""
    out = tmp_path / "b"
    shutil.copytree(reference, out)
    before = files(out / "runs")
    ran = []
    run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=1, keep_tracks=True,
                  on_done=ran.append)  # fmt: skip
    assert len(ran) == 8 and files(out / "runs") == before
    assert files(out) == files(kept)
    lost = _track(out, "annealed", 2)
    lost.unlink()
    ran.clear()
    run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=1, on_done=ran.append)
    assert [(t.tracker, t.index) for t in ran] == [("annealed", 2)]
    assert files(out) == files(kept)
    ran.clear()
    run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=1, keep_tracks=True,
                  on_done=ran.append)  # fmt: skip
    assert ran == [] and files(out) == files(kept)


def test_an_interrupted_benchmark_keeps_the_tracks_it_wrote(dataset, kept, tmp_path):
    """Interrupted after 3 of its 8 pairs, a --keep-tracks benchmark run again runs only
    the 5 others (it ran all 8 again: no results.json listed the 3 tracker files yet), but
    also a pair whose tracker file was edited since, or whose note was; it ends as an
    uninterrupted run, without its notes."""
    from scenegen.lab.benchmark_tracks import PENDING, pending_file

    class Stop(Exception):
        pass

    out = tmp_path / "b"
    done = []

    def stop_after_3(t):
        done.append((t.tracker, t.index))
        if len(done) == 3:
            raise Stop

    with pytest.raises(Stop):
        run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=1, keep_tracks=True,
                      on_done=stop_after_3)  # fmt: skip
    assert not (out / "results.json").exists()
    assert sorted(p.relative_to(out).as_posix() for p in (out / PENDING).rglob("*.json")) == \
        sorted(pending_file(run_file(t, i)) for t, i in done)
    ran = []
    again = dict(params=PARAMS, jobs=1, keep_tracks=True, on_done=ran.append)
    shutil.copytree(out, tmp_path / "c")
    run_benchmark(dataset, TRACKERS, out, **again)
    pairs = [(t, i) for t in TRACKERS for i in range(4)]
    assert [(t.tracker, t.index) for t in ran] == [p for p in pairs if p not in done]
    assert files(out) == files(kept) and not (out / PENDING).exists()
    # The same interrupted folder, one kept file edited and one note damaged.
    out = tmp_path / "c"
    f = _track(out, *done[0])
    f.write_bytes(f.read_bytes().replace(b",", b", ", 1))
    note = out / pending_file(run_file(*done[1]))
    note.write_bytes(note.read_bytes()[:-3])
    ran.clear()
    run_benchmark(dataset, TRACKERS, out, **again)
    assert [(t.tracker, t.index) for t in ran] == [p for p in pairs if p not in done[2:]]
    assert files(out) == files(kept)


def test_a_tracker_dropped_from_a_benchmark_leaves_its_kept_tracks(dataset, kept, tmp_path,
                                                                  capsys):  # fmt: skip
    """The same OUT run again with fewer trackers stays a valid folder: the dropped
    tracker's run records stay (as without kept tracks), its TrackEval folder and stray
    files TrackEval would read are removed, one warning each, and nothing else changes."""
    from scenegen.lab.benchmark_outputs import check_benchmark

    out = tmp_path / "b"
    shutil.copytree(kept, out)
    stray = _track(out, "annealed", 9)
    stray.write_text("")
    summary = _track(out, "annealed", 0).parents[1] / "pedestrian_summary.txt"
    summary.write_text("HOTA\n")
    before = files(out)
    capsys.readouterr()
    ran = []
    run_benchmark(dataset, ["annealed"], out, params=PARAMS, jobs=1, on_done=ran.append)
    assert ran == [] and check_benchmark(out) == []
    dropped = _track(out, "sok", 0).parents[1]
    assert not dropped.exists() and not stray.exists() and summary.exists()
    assert capsys.readouterr().err.splitlines() == [
        f"scenegen: warning: {p}: removed from the kept tracks (not a tracker or sequence "
        "of this benchmark; TrackEval would read it)" for p in (dropped, stray)]  # fmt: skip
    after = files(out)
    assert {k for k in before if k not in after} == {
        k for k in before if k.startswith(("trackeval/trackers/mot_challenge/scenegen-all/"
                                           "sok/", stray.relative_to(out).as_posix()))}
    assert all(after[k] == before[k] for k in after if k.startswith(("runs/", "trackeval/")))


def test_a_damaged_results_json_does_not_drop_the_kept_tracks(dataset, kept, tmp_path):
    """results.json (the listing of the kept files) truncated: the command run again
    without --keep-tracks still keeps the tracks (OUT/trackeval/ is there), so the folder
    comes back as it was and valid, not with tracks its results.json does not list."""
    from scenegen.lab.benchmark_outputs import check_benchmark

    out = tmp_path / "b"
    shutil.copytree(kept, out)
    res = out / "results.json"
    res.write_bytes(res.read_bytes()[:100])
    assert check_benchmark(out) != []
    run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=1)
    assert check_benchmark(out) == [] and files(out) == files(kept)


def test_a_run_that_does_not_come_out_the_same_is_not_rewritten(dataset, reference, tmp_path,
                                                                monkeypatch):  # fmt: skip
    from scenegen.errors import DataError
    from scenegen.lab import benchmark_tracks

    real = benchmark_tracks.pair_with_tracks

    def drifting(task):
        rec, ids, boxes = real(task)
        rec["scores"]["auc"] = 0.0
        return rec, ids, boxes

    out = tmp_path / "b"
    shutil.copytree(reference, out)
    monkeypatch.setattr(benchmark_tracks, "pair_with_tracks", drifting)
    with pytest.raises(DataError, match="running it again for its tracks gave another record"):
        run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=1, keep_tracks=True)
    assert files(out / "runs") == files(reference / "runs")


def test_damaged_missing_or_extra_track_files_are_named(reference, kept, tmp_path, capsys):
    from scenegen.cli import main
    from scenegen.lab.benchmark_outputs import check_benchmark

    out = tmp_path / "b"
    shutil.copytree(kept, out)
    f = _track(out, "sok", 1)
    text = f.read_bytes()
    f.write_bytes(text + b"1,9,1,1,2,2,1,-1,-1,-1\n")
    want = f"{f}: is not the file results.json lists (damaged or edited: {_REDO})"
    assert check_benchmark(out) == [want]
    assert main(["validate", str(out)]) == 1
    assert capsys.readouterr().err.strip() == want
    f.unlink()
    assert check_benchmark(out) == [f"{f}: missing ({_REDO})"]
    f.write_bytes(text)
    extra = f.parent / "two-00009.txt"
    extra.write_text("")
    other = out / "trackeval/trackers/mot_challenge/scenegen-all/other"
    (other / "data").mkdir(parents=True)
    assert check_benchmark(out) == [
        f"{p}: a {what} the benchmark did not write (TrackEval would read it: remove it)"
        for p, what in ((other, "folder"), (extra, "file"))]  # fmt: skip
    extra.unlink()
    shutil.rmtree(other)
    # What TrackEval writes beside a tracker's data/ folder is allowed.
    (f.parents[1] / "pedestrian_summary.txt").write_text("HOTA\n")
    assert check_benchmark(out) == []
    # Kept tracks that results.json does not list (an unfinished first run).
    plain = tmp_path / "plain"
    shutil.copytree(reference, plain)
    shutil.copytree(out / "trackeval", plain / "trackeval")
    assert check_benchmark(plain) == [
        f"{plain / 'trackeval'}: kept tracks that results.json does not list (written by an "
        f"unfinished run: {_REDO})"]  # fmt: skip


def test_a_file_or_folder_in_the_way_of_a_kept_file_is_one_line(dataset, kept, tmp_path,
                                                              capsys):  # fmt: skip
    """A file where the kept folders hold a folder (a tracker's data/, trackeval/gt/), or
    a folder where they hold a file: validate names it in one line (it crashed on the
    file), and the command run again refuses in one line naming it (it crashed on
    mkdir); once it is removed, the command restores the folder."""
    from scenegen.cli import main
    from scenegen.errors import ConfigError
    from scenegen.lab.benchmark_outputs import check_benchmark

    out = tmp_path / "b"
    shutil.copytree(kept, out)
    data = _track(out, "sok", 0).parent
    shutil.rmtree(data)
    data.write_text("")
    want = (f"{data}: a file where the kept tracks have a folder (remove it, then {_REDO})")
    assert check_benchmark(out) == [want]
    assert main(["validate", str(out)]) == 1
    assert capsys.readouterr().err.strip() == want
    with pytest.raises(ConfigError, match=f"^{data}: is a file, not a folder"):
        run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=1)
    data.unlink()
    shutil.copytree(_track(kept, "sok", 0).parent, data)
    gt = out / "trackeval" / "gt"
    shutil.rmtree(gt)
    gt.write_text("")
    with pytest.raises(ConfigError, match=f"^{gt}: is a file, not a folder"):
        run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=1)
    gt.unlink()
    shutil.copytree(kept / "trackeval" / "gt", gt)
    f = _track(out, "annealed", 1)
    f.unlink()
    f.mkdir()
    want = f"{f}: a folder where the kept tracks have a file (remove it, then {_REDO})"
    assert check_benchmark(out) == [want]
    with pytest.raises(ConfigError, match=f"^{f}: is a folder, expected a file name"):
        run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=1)
    f.rmdir()
    run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=1)
    assert check_benchmark(out) == [] and files(out) == files(kept)


def test_a_kept_file_made_a_link_is_not_written_through(dataset, kept, tmp_path, capsys):
    """A tracker file replaced by a link to another tracker's file (or a tracker's folder
    by a link to another's): the command run again writes the file in place of the link;
    it wrote through it, so the other tracker's file took these boxes and the folder was
    valid with one tracker's boxes under the other's name."""
    from scenegen.lab.benchmark_outputs import check_benchmark

    out = tmp_path / "b"
    shutil.copytree(kept, out)
    f, other = _track(out, "annealed", 1), _track(out, "sok", 1)
    f.unlink()
    f.symlink_to(other)
    run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=1)
    assert not f.is_symlink()
    assert capsys.readouterr().err.splitlines() == [
        f"scenegen: warning: {f}: a link removed from the kept tracks (the benchmark writes "
        "its own files there, not through links)"]  # fmt: skip
    assert check_benchmark(out) == [] and files(out) == files(kept)
    folder, sok = f.parents[1], other.parents[1]
    shutil.rmtree(folder)
    folder.symlink_to(sok, target_is_directory=True)
    run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=1)
    assert not folder.is_symlink()
    assert check_benchmark(out) == [] and files(out) == files(kept)


def test_a_link_to_the_listed_bytes_is_not_a_kept_file(dataset, kept, tmp_path, capsys):
    """A kept file, a tracker's folder or the whole trackeval/ folder replaced by a link to
    a copy outside the output folder, with the listed bytes: validate names the link in
    one line (it called the folder valid, though its files lived elsewhere), and the
    command run again restores the folder's own files."""
    from scenegen.cli import main
    from scenegen.lab.benchmark_outputs import check_benchmark

    out = tmp_path / "b"
    shutil.copytree(kept, out)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    f = _track(out, "sok", 1)
    folder = f.parents[1]
    for link in (f, folder, out / "trackeval"):
        target = elsewhere / link.name
        shutil.move(link, target)
        link.symlink_to(target, target_is_directory=target.is_dir())
        want = (f"{link}: a symbolic link in the kept tracks (they must be the folder's own "
                f"files: {_REDO})")  # fmt: skip
        assert check_benchmark(out) == [want]
        assert main(["validate", str(out)]) == 1
        assert capsys.readouterr().err.strip() == want
        link.unlink()
        shutil.move(target, link)
        assert check_benchmark(out) == []
    f.unlink()
    f.symlink_to(kept / f.relative_to(out))
    assert len(check_benchmark(out)) == 1
    run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=1)
    capsys.readouterr()
    assert not f.is_symlink()
    assert check_benchmark(out) == [] and files(out) == files(kept)


def test_a_fifo_in_a_benchmark_folder_is_one_line_and_never_waited_on(dataset, kept, tmp_path,
                                                                    deadline):  # fmt: skip
    """A FIFO in place of a page, a figure or a kept file: validate names it in one line;
    with a kept file, the command run again refuses in one line before running anything.
    validate waited for ever on a page or a figure and called a kept FIFO "missing"; the
    command waited for ever on a kept FIFO (reading it for its digest)."""
    import os

    from scenegen.errors import ConfigError
    from scenegen.lab.benchmark_outputs import check_benchmark

    out = tmp_path / "b"
    shutil.copytree(kept, out)
    figure = next(out.glob("*.png"))
    pages = [out / n for n in ("leaderboard.md", "scores.csv", "index.html")] + [figure]
    kept_files = [_track(out, "sok", 2), out / "trackeval/gt/mot_challenge/seqmaps/"
                  "scenegen-all.txt"]  # fmt: skip
    for p in pages + kept_files:
        body = p.read_bytes()
        p.unlink()
        os.mkfifo(p)
        fix = (f"remove it, then {_REDO}" if p in kept_files else
               "remove it, then run the same `scenegen benchmark` command again into this "
               "folder to recompute it")  # fmt: skip
        with deadline(30):
            assert check_benchmark(out) == [f"{p}: is not a regular file (a FIFO) ({fix})"]
            if p in kept_files:
                ran = []
                with pytest.raises(ConfigError, match=f"^{p}: is not a regular file \\(a "
                                   "FIFO\\); remove it$"):  # fmt: skip
                    run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=1,
                                  on_done=ran.append)  # fmt: skip
                assert ran == [] and p.is_fifo()
        p.unlink()
        p.write_bytes(body)
    assert check_benchmark(out) == [] and files(out) == files(kept)
    # A page the benchmark would write only after every run: refused before the first.
    shutil.rmtree(out / "runs")
    page = out / "leaderboard.md"
    page.unlink()
    os.mkfifo(page)
    ran = []
    with deadline(30), pytest.raises(ConfigError, match=f"^{page}: is not a regular file"):
        run_benchmark(dataset, TRACKERS, out, params=PARAMS, jobs=1, on_done=ran.append)
    assert ran == [] and not (out / "runs").exists()


def test_deep_compares_each_tracker_file_with_its_run_again(kept, tmp_path):
    """A tracker file replaced and its digest listed again (results.json resealed) is
    found only by the runs computed again."""
    from scenegen.io.sealed import read_sealed_json, write_sealed_json
    from scenegen.lab.benchmark_tracks import file_digest

    out = tmp_path / "b"
    shutil.copytree(kept, out)
    f = _track(out, "sok", 3)
    f.write_text(f.read_text().replace(",1,-1,-1,-1", ",1.0,-1,-1,-1", 1))
    doc = read_sealed_json(out / "results.json")
    name = f.relative_to(out).as_posix()
    doc["tracks"] = [f"{name} {file_digest(f)}" if e.startswith(name + " ") else e
                     for e in doc["tracks"]]  # fmt: skip
    write_sealed_json(out / "results.json", doc, indent=1)
    from scenegen.lab.benchmark_outputs import check_benchmark

    assert check_benchmark(out) == []
    assert check_benchmark(out, deep=True) == [
        f"{f}: differs from the tracks of the run computed again"]


def _oracle_diffs(summary, case):
    """|ours - TrackEval's| of every combined column (the multi-target seqmap) and every
    multi-target run's MOTA, IDF1 and HOTA."""
    te = {"mota": "MOTA", "idf1": "IDF1", "hota": "HOTA"}
    out = []
    for tracker, cols in summary["combined"].items():
        for m, name in te.items():
            out.append(abs(cols[f"{m}_combined"] - case["combined_multi"][tracker][name]))
    for row in summary["scores"]:
        if row["targets"] > 1:
            seq = case["sequences"][row["tracker"]][row["name"]]
            out += [abs(row[m] - seq[name]) for m, name in te.items()]
    return out


def test_kept_tracks_score_as_trackeval_does(kept, tool, tmp_path):
    """TrackEval (tools/trackeval/score_benchmark.py, run on the committed kept folders)
    gives the leaderboard's combined columns and every multi-target run's scores, to
    their rounding: on this module's benchmark and a mixed one (one single-target
    sequence, left out of the combined columns) regenerated here, and on the committed
    output of a built-in family (seven targets)."""
    from scenegen.lab.benchmark_tracks import file_digest

    oracle = json.loads((ORACLE / "oracle.json").read_text())["cases"]
    assert tool.CASES["two"] == {"family": FAMILY, "trackers": TRACKERS, "params": PARAMS}
    diffs = []
    for name, folder in (("two", kept), ("mixed", tmp_path / "benchmark")):
        if name == "mixed":
            tool.run_case(name, tmp_path)
        assert files(folder / "trackeval") == files(ORACLE / name / "trackeval")
        summary = tool.summary(json.loads((folder / "results.json").read_text()))
        assert summary == json.loads((ORACLE / name / "benchmark.json").read_text())
        diffs += _oracle_diffs(summary, oracle[name])
    mixed = json.loads((ORACLE / "mixed" / "benchmark.json").read_text())
    assert sorted({r["targets"] for r in mixed["scores"]}) == [1, 2]
    committed = json.loads((ORACLE / "dps-synthetic" / "benchmark.json").read_text())
    for entry in committed["tracks"]:
        rel, digest = entry.split(" ")
        assert file_digest(ORACLE / "dps-synthetic" / rel) == digest
    diffs += _oracle_diffs(committed, oracle["dps-synthetic"])
    assert len(diffs) == 30 + 12 + 24 and max(diffs) <= 5.1e-7


def test_the_committed_built_in_benchmark_is_the_benchmarks_output(tool, tmp_path):
    """The committed dps-synthetic case (scored by TrackEval) is what the benchmark writes."""
    results = tool.run_case("dps-synthetic", tmp_path)
    case = ORACLE / "dps-synthetic"
    assert files(tmp_path / "benchmark" / "trackeval") == files(case / "trackeval")
    assert tool.summary(results) == json.loads((case / "benchmark.json").read_text())
