"""Benchmarking trackers over a dataset: same results on any executor, resume, the report."""

import json
from pathlib import Path

import pytest

from scenegen.datasets import build_dataset
from scenegen.lab.benchmark import leaderboard, run_benchmark

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


@pytest.mark.slow  # the Dask path of the shared executor is in the fast dataset tests
def test_same_results_on_a_dask_cluster(dataset, reference, tmp_path):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(
        n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None
    ) as cluster:
        run_benchmark(dataset, TRACKERS, tmp_path / "b", params=PARAMS,
                      scheduler=cluster.scheduler_address)  # fmt: skip
    assert files(tmp_path / "b") == files(reference)
