"""`scenegen track --tracker MODULE:FACTORY`: a user's tracker; one-line errors, exit 2."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

import scenegen
from scenegen.cli import main
from scenegen.io import read_result

USER_MODULE = textwrap.dedent(
    """
    import numpy as np

    class Box:
        def __init__(self, boxes):
            self.boxes = boxes

    class Still:
        def __init__(self, offset=0.0):
            self.offset = offset

        def init(self, frame, boxes):
            self.b = np.asarray(boxes, dtype=float)

        def step(self, frame):
            return Box(self.b + self.offset)

    def make(offset=0.0):
        return Still(offset)

    def seeded(rng=None):
        return Still(float(rng))

    not_callable = 3

    def broken():
        return object()

    class Fails(Still):
        def step(self, frame):
            self.n = getattr(self, "n", 0) + 1
            if self.n == 3:
                raise RuntimeError("lost my way")
            return super().step(frame)

    def fails():
        return Fails()
    """
)


@pytest.fixture(scope="module")
def user_dir(tmp_path_factory):
    folder = tmp_path_factory.mktemp("user")
    (folder / "usertrk.py").write_text(USER_MODULE)
    scenegen.write(folder / "seq.h5", scenegen.generate("kams-a", seed=1, frames=4))
    return folder


def test_track_runs_a_users_factory(user_dir, monkeypatch, capsys):
    monkeypatch.chdir(user_dir)
    assert (
        main(["track", "seq.h5", "--tracker", "usertrk:make", "--param", "offset=2", "-o", "r.h5"])
        == 0
    ), capsys.readouterr().err
    res = read_result(user_dir / "r.h5")
    assert res.tracker == "usertrk:make" and res.params == {"offset": 2}
    np.testing.assert_allclose(res.boxes[1:] - res.boxes[0], 2)
    # rng=seed reaches a factory that takes rng; a file path works too
    assert (
        main(["track", "seq.h5", "--tracker", "./usertrk.py:seeded", "--seed", "3", "-o", "s.h5"])
        == 0
    ), capsys.readouterr().err
    res = read_result(user_dir / "s.h5")
    assert res.tracker == "usertrk.py:seeded"
    np.testing.assert_allclose(res.boxes[1:] - res.boxes[0], 3)


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--tracker", "usertrk:nope"], "usertrk has no attribute 'nope'"),
        (["--tracker", "nomodule_xyz:make"], "cannot import nomodule_xyz: ModuleNotFoundError"),
        (["--tracker", "usertrk:not_callable"], "not_callable is not callable"),
        (["--tracker", "usertrk:broken"], "returned a object, which has no init or step"),
        (["--tracker", "usertrk:make", "--param", "bogus=1"], "unexpected keyword argument"),
        (["--tracker", "dps", "--param", "n_particles=abc"], "n_particles must be an integer"),
        (["--tracker", "missing.py:make"], "no such file missing.py"),
    ],
)
def test_track_user_errors_are_one_line_exit_2(user_dir, monkeypatch, capsys, args, needle):
    monkeypatch.chdir(user_dir)
    code = main(["track", "seq.h5", *args, "-o", "x.h5"])
    err = capsys.readouterr().err
    assert code == 2 and needle in err and len(err.strip().splitlines()) == 1, err
    assert not (user_dir / "x.h5").exists()


@pytest.mark.parametrize("target", ["afile/r.h5", "adir"])
def test_unwritable_output_names_the_target(user_dir, monkeypatch, capsys, target):
    monkeypatch.chdir(user_dir)
    (user_dir / "afile").write_text("in the way")
    (user_dir / "adir").mkdir(exist_ok=True)
    code = main(["track", "seq.h5", "--tracker", "kalman", "-o", target])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert err.startswith(f"scenegen: error: {target}: cannot write the output")


def test_track_help_lists_the_tracker_names(capsys):
    assert main(["track", "--help"]) == 0
    out = capsys.readouterr().out
    import trackers

    assert all(name in out for name in trackers.names()) and "MODULE:FACTORY" in out


def test_a_users_tracker_that_raises_is_one_line_naming_it(user_dir, monkeypatch, capsys):
    # It was "internal error: RuntimeError: ..." as if scenegen had failed.
    from scenegen.errors import TrackerError

    monkeypatch.chdir(user_dir)
    assert main(["track", "seq.h5", "--tracker", "usertrk:fails", "-o", "r2.h5"]) == 1
    assert capsys.readouterr().err.strip() == (
        "scenegen: error: tracker 'usertrk:fails' failed on sequence 'kams-a' after 2 of 3 "
        "steps: RuntimeError: lost my way (rerun with --debug for its traceback)")  # fmt: skip
    assert not (user_dir / "r2.h5").exists()
    with pytest.raises(TrackerError) as info:
        main(["--debug", "track", "seq.h5", "--tracker", "usertrk:fails", "-o", "r2.h5"])
    assert isinstance(info.value.__cause__, RuntimeError)
