"""Regression fixtures: the committed set, ``scenegen fixtures verify`` and ``regen``."""

import json
import os
import shutil
from dataclasses import replace

import numpy as np
import pytest

import trackers
from scenegen import presets
from scenegen.cli import main
from scenegen.config import AR2, Camera
from scenegen.errors import ConfigError
from scenegen.io import read, write
from scenegen.lab.regen import regen, verify
from scenegen.render.plan import generate
from scenegen.testing.fixtures import default_dir, definitions, downsized

SUBSET = ["one-pixel", "single-frame"]
SOME_TRACKERS = ["meanshift", "kalman"]
REGEN_HINT = "if the change is intended, run `scenegen fixtures regen` and commit fixtures/"


def test_committed_fixtures_regenerate_identically():
    problems = verify(default_dir(), tracker_names=[])
    assert problems == [], "\n".join(problems)


@pytest.mark.parametrize("name", trackers.names())
def test_trackers_give_their_committed_outputs(name):
    problems = verify(default_dir(), tracker_names=[name])
    assert problems == [], "\n".join([*problems, REGEN_HINT])


def test_committed_set_is_small_and_complete():
    folder = default_dir()
    total = sum(p.stat().st_size for p in folder.rglob("*") if p.is_file())
    assert total <= 5 * 2**20
    registry = json.loads((folder / "registry.json").read_text())
    assert list(registry["fixtures"]) == list(definitions())
    assert {d.preset for d in definitions().values()} >= set(presets.names())
    for entry in registry["fixtures"].values():
        assert set(entry["trackers"]) == set(trackers.names())


def test_plugin_serves_committed_fixtures(scenegen_fixture):
    seq = scenegen_fixture("single-frame")
    assert seq.n_frames == 1 and seq.entities.role[0] == "target"


def test_regen_then_verify_then_nothing_changes(tmp_path):
    changes, errors = regen(tmp_path, fixtures=SUBSET, tracker_names=SOME_TRACKERS)
    assert errors == []
    assert "fixture one-pixel: new" in changes
    assert "fixture single-frame, tracker kalman: new expected output" in changes
    assert verify(tmp_path, fixtures=SUBSET, tracker_names=SOME_TRACKERS) == []
    h5 = tmp_path / "one-pixel.h5"
    before = h5.stat().st_mtime_ns
    assert regen(tmp_path, fixtures=SUBSET, tracker_names=SOME_TRACKERS) == ([], [])
    assert h5.stat().st_mtime_ns == before


def test_verify_names_every_mismatch(tmp_path, capsys):
    regen(tmp_path, fixtures=SUBSET, tracker_names=SOME_TRACKERS)
    npy = tmp_path / "expected" / "one-pixel" / "meanshift.npy"
    np.save(npy, np.load(npy) + 1.0)
    (tmp_path / "expected" / "single-frame" / "kalman.npy").unlink()
    write(tmp_path / "single-frame.h5", generate(definitions()["single-frame"].config, seed=9))
    argv = ["fixtures", "verify", "--dir", str(tmp_path)]
    for name in SUBSET:
        argv += ["--fixture", name]
    for name in SOME_TRACKERS:
        argv += ["--tracker", name]
    assert main(argv) == 1
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 3, err
    assert "fixture one-pixel, tracker meanshift: boxes" in err[0]
    assert "differ beyond atol=0.01, rtol=0.0 (largest difference 1)" in err[0]
    assert "fixture single-frame:" in err[1] and "holds different frames" in err[1]
    assert "fixture single-frame, tracker kalman:" in err[2] and "is missing" in err[2]


def test_verify_flags_a_changed_definition(tmp_path):
    regen(tmp_path, fixtures=["one-pixel"], tracker_names=[])
    path = tmp_path / "registry.json"
    registry = json.loads(path.read_text())
    registry["fixtures"]["one-pixel"]["seed"] = 2
    path.write_text(json.dumps(registry))
    problems = verify(tmp_path, fixtures=["one-pixel"], tracker_names=[])
    assert problems[0] == (
        "fixture one-pixel: its definition (config or seed) differs from the registry"
    )
    assert problems[1].startswith("fixture one-pixel: regenerating gives different frames")


def test_a_refusal_is_recorded_and_verified(tmp_path):
    changes, errors = regen(tmp_path, fixtures=["dps-synthetic-small"], tracker_names=["shm"])
    assert errors == []
    assert any("tracker shm: refuses: ConfigError" in c for c in changes)
    run = json.loads((tmp_path / "registry.json").read_text())["fixtures"]["dps-synthetic-small"][
        "trackers"
    ]["shm"]
    assert run["raises"].startswith("ConfigError: 7 objects")
    assert verify(tmp_path, fixtures=["dps-synthetic-small"], tracker_names=["shm"]) == []


def test_regen_removes_fixtures_no_longer_defined(tmp_path):
    regen(tmp_path, fixtures=["one-pixel"], tracker_names=["kalman"])
    path = tmp_path / "registry.json"
    registry = json.loads(path.read_text())
    registry["fixtures"]["old"] = {"file": "old.h5", "digests": {}, "trackers": {}}
    path.write_text(json.dumps(registry))
    shutil.copy(tmp_path / "one-pixel.h5", tmp_path / "old.h5")
    problems = verify(tmp_path, tracker_names=[])
    assert problems[0].startswith("fixture old: in the registry but no longer defined")
    changes, _ = regen(tmp_path, fixtures=None, tracker_names=["kalman"])
    assert "fixture old: removed" in changes
    assert not (tmp_path / "old.h5").exists()


def test_regen_keeps_what_a_user_stored_beside_a_removed_fixture(tmp_path):
    regen(tmp_path, fixtures=["one-pixel"], tracker_names=["kalman"])
    path = tmp_path / "registry.json"
    registry = json.loads(path.read_text())
    registry["fixtures"]["old"] = {"file": "old.h5", "digests": {}, "trackers": {"kalman": {}}}
    registry["fixtures"]["older"] = {"file": "older.h5", "digests": {}, "trackers": {"kalman": {}}}
    path.write_text(json.dumps(registry))
    for name in ("old", "older"):
        folder = tmp_path / "expected" / name
        folder.mkdir(parents=True)
        shutil.copy(tmp_path / "expected" / "one-pixel" / "kalman.npy", folder / "kalman.npy")
    (tmp_path / "expected" / "old" / "mine.npy").write_bytes(b"user data")
    changes, _ = regen(tmp_path, fixtures=None, tracker_names=["kalman"])
    assert "fixture old: removed; kept expected/old/ (1 file(s) regen did not write)" in changes
    assert (tmp_path / "expected" / "old" / "mine.npy").read_bytes() == b"user data"
    assert not (tmp_path / "expected" / "old" / "kalman.npy").exists()
    assert "fixture older: removed" in changes
    assert not (tmp_path / "expected" / "older").exists()


def test_cli_errors_are_one_line(tmp_path, capsys):
    assert main(["fixtures", "verify", "--dir", str(tmp_path)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "registry.json: no such file" in err[0]
    assert main(["fixtures", "regen", "--dir", str(tmp_path), "--fixture", "nope"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "unknown fixture 'nope'" in err[0]
    # A user's own tracker is not a fixture tracker; the refused command leaves no empty
    # folder behind (it was created before the names were checked).
    new = tmp_path / "new"
    assert main(["fixtures", "regen", "--dir", str(new), "--tracker", "mytrack:make"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "unknown tracker 'mytrack:make'" in err[0]
    assert not new.exists()


def test_edge_cases_exercise_what_they_claim():
    defs = definitions()

    def gt(name):
        return generate(defs[name].config, seed=defs[name].seed).gt

    leave = gt("enter-leave")
    assert leave.present[0].tolist() == [True, False]
    assert not leave.present[-1].any()  # both gone by the last frame
    assert leave.present[:, 1].any()  # the second came and went
    occl = gt("full-occlusion")
    assert occl.present[:, 0].all() and (occl.visibility[:, 0] == 0).any()
    assert occl.visibility[0, 0] == 1 and occl.visibility[-1, 0] == 1
    dist = gt("distractor-on-target")
    assert not dist.present[:2, 1].any() and dist.present[2, 1]
    assert dist.visibility[2, 0] < 0.5  # the copy covers the target when it appears
    pixel = gt("one-pixel")
    assert np.all(pixel.box[:, 0, 2:] == 1)
    assert gt("single-frame").box.shape[0] == 1
    for d in defs.values():
        seq = generate(d.config, seed=d.seed)
        assert seq.gt.present[0, seq.target_indices()].any(), d.name


def test_downsized_scales_geometry_and_clutter():
    cfg = presets.get("kams-d")
    small = downsized(cfg, factor=0.5, n_frames=4, max_clutter=60)
    assert (small.width, small.height, small.n_frames) == (160, 120, 4)
    assert small.entities[0].appearance.size == (15, 15)
    assert small.entities[0].position == (35.0, 60.0)
    assert small.entities[0].position_noise == pytest.approx(7.0)
    assert small.clutter[0].count == 60 and small.clutter[0].min_size == 4
    assert small.clutter[0].appearance.size == (8, 8)
    assert downsized(cfg, factor=0.5, n_frames=4).clutter[0].count == 150
    for bad in ({"factor": 0.0, "n_frames": 4}, {"factor": 1.5, "n_frames": 4},
                {"factor": 0.5, "n_frames": 0}):  # fmt: skip
        with pytest.raises(ConfigError):
            downsized(cfg, **bad)


def test_downsized_scales_the_camera_in_pixels():
    # The camera was kept: on a half-size canvas it panned twice as far, relative to the
    # frame, as on the full one.
    cfg = presets.get("tiger-like")
    cam = cfg.camera
    small = downsized(cfg, factor=0.5, n_frames=4).camera
    assert small.extent == (cam.extent[0] // 2, cam.extent[1] // 2)
    assert small.x.sigma == pytest.approx(cam.x.sigma / 2)
    assert small.y.sigma == pytest.approx(cam.y.sigma / 2)
    assert small.velocity == pytest.approx((cam.velocity[0] / 2, cam.velocity[1] / 2))
    assert (small.x.a1, small.x.a2, small.x.boundary) == (cam.x.a1, cam.x.a2, cam.x.boundary)
    # Keyframe offsets scale with the extent and stay within it after its rounding
    # (5 * 0.5 rounds to 2); frames are kept; the log zoom is scale-free.
    zoom = AR2(boundary="reflect", sigma=0.02, margin=0.3)
    scripted = replace(cfg, camera=Camera(extent=(5, 6), zoom=zoom,
                                          keyframes=((0, 0.0, 0.0), (3, 5.0, -4.0))))
    small = downsized(scripted, factor=0.5, n_frames=4).camera
    assert small.extent == (2, 3)
    assert small.keyframes == ((0, 0.0, 0.0), (3, 2.0, -2.0))
    assert small.zoom == zoom
    assert downsized(replace(cfg, camera=None), factor=0.5, n_frames=4).camera is None


def test_committed_files_read_back():
    folder = default_dir()
    for name, d in definitions().items():
        seq = read(folder / f"{name}.h5")
        assert seq.config == d.config and seq.seed == d.seed
        assert os.path.getsize(folder / f"{name}.h5") < 2**20
