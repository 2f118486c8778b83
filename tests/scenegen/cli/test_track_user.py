"""`scenegen track --tracker MODULE:FACTORY`: a user's tracker; one-line errors, exit 2."""

from __future__ import annotations

import textwrap
import warnings

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

    def forgot_call():
        return Still

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

    class Singular(Still):
        def step(self, frame):
            self.n = getattr(self, "n", 0) + 1
            if self.n == 2:
                np.linalg.inv(np.zeros((2, 2)))  # a ValueError subclass
            return super().step(frame)

    def singular():
        return Singular()

    class TwoBoxes(Still):
        def step(self, frame):
            return Box(np.vstack([self.b, self.b]))

    def wrong_bug():
        raise RuntimeError("model file not found: weights.bin")

    class BadOrderings(Still):
        orderings = [[0], [5]]

        def step(self, frame):
            out = super().step(frame)
            out.extras = {"order_prob": np.array([0.3, 0.3, 0.4])}
            return out

    class Huge(Still):
        def step(self, frame):
            out = super().step(frame)
            out.boxes = out.boxes.copy()
            out.boxes[0, 0] = 1e39  # finite, beyond float32
            return out

    class Exits(Still):
        def step(self, frame):
            raise SystemExit(0)

    class ExitsAtInit(Still):
        def init(self, frame, boxes):
            raise SystemExit(0)

    def exits_when_built():
        raise SystemExit(0)

    class Reuse(Still):
        orderings = [[0], [0]]

        def init(self, frame, boxes):
            super().init(frame, boxes)
            self.p, self.t = np.zeros(2), 0

        def step(self, frame):
            self.t += 1
            self.p[:] = (1.0, 0.0) if self.t % 2 else (0.0, 1.0)
            out = super().step(frame)
            out.extras = {"order_prob": self.p}
            return out
    """
)


@pytest.fixture(scope="module")
def user_dir(tmp_path_factory):
    folder = tmp_path_factory.mktemp("user")
    (folder / "usertrk.py").write_text(USER_MODULE)
    (folder / "sub").mkdir()
    (folder / "sub" / "usersib.py").write_text(USER_MODULE)
    (folder / "sub" / "userfile.py").write_text("from usersib import make\n")
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
        # Was exit 1, "Still.init() missing 1 required positional argument: 'boxes'".
        (["--tracker", "usertrk:forgot_call"], "returned the class Still, not a tracker"),
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


@pytest.mark.parametrize(
    ("spec", "needle"),
    [
        # A ValueError of the user's step was "error: Singular matrix", exit 2.
        ("usertrk:singular", "after 1 of 3 steps: LinAlgError: Singular matrix"),
        # A protocol breach of the user's tracker is its failure, exit 1.
        ("usertrk:TwoBoxes", "after 0 of 3 steps: ValueError: TwoBoxes.step() at frame 1: "
                             ".boxes has shape (2, 4), expected (1, 4)"),
        # A factory failing for its own reasons was "internal error: RuntimeError".
        ("usertrk:wrong_bug", "failed while being built: RuntimeError: model file not found"),
        # Depth-order outputs a result file cannot hold were written, then called invalid.
        ("usertrk:BadOrderings", "its output cannot be stored: orderings name "
                                 "positions outside 0..0"),
        # A box beyond float32 warned of an overflow, then blamed the depth-order output.
        ("usertrk:Huge", "its box at frame 1 for target 1 is [1e+39, "),
        # A SystemExit of the user's tracker was a clean exit 0 with no result.
        ("usertrk:Exits", "after 0 of 3 steps: SystemExit: 0"),
        ("usertrk:ExitsAtInit", "after 0 of 3 steps: SystemExit: 0"),
        ("usertrk:exits_when_built", "failed while being built: SystemExit: 0"),
    ],
)
def test_a_users_tracker_failing_is_exit_1_naming_it(user_dir, monkeypatch, capsys, spec, needle):
    monkeypatch.chdir(user_dir)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        code = main(["track", "seq.h5", "--tracker", spec, "-o", "f.h5"])
    err = capsys.readouterr().err
    assert code == 1 and len(err.strip().splitlines()) == 1, err
    assert err.startswith(f"scenegen: error: tracker '{spec}'") and needle in err, err
    assert not (user_dir / "f.h5").exists()


def test_per_frame_extras_are_copied_when_a_tracker_reuses_its_buffer(user_dir, monkeypatch):
    # Every frame held the last frame's order_prob (the list kept references).
    monkeypatch.chdir(user_dir)
    assert main(["track", "seq.h5", "--tracker", "usertrk:Reuse", "-o", "e.h5"]) == 0
    prob = read_result(user_dir / "e.h5").order_prob
    np.testing.assert_array_equal(prob[1:], [[1, 0], [0, 1], [1, 0]])


def test_a_file_spec_imports_its_sibling_modules(user_dir, monkeypatch, capsys):
    monkeypatch.chdir(user_dir)
    monkeypatch.setattr("sys.path", list(__import__("sys").path))
    code = main(["track", "seq.h5", "--tracker", "sub/userfile.py:make", "-o", "g.h5"])
    assert code == 0, capsys.readouterr().err


def test_seed_is_not_a_parameter_and_debug_goes_anywhere(user_dir, monkeypatch, capsys):
    monkeypatch.chdir(user_dir)
    args = ["--tracker", "usertrk:seeded", "--param", "rng=5", "-o", "h.h5"]
    code = main(["track", "seq.h5", *args])
    err = capsys.readouterr().err
    assert code == 2 and "parameter 'rng'" in err and "--seed" in err, err
    # "rerun with --debug" works with --debug after the verb too.
    from scenegen.errors import TrackerError

    with pytest.raises(TrackerError):
        main(["track", "seq.h5", "--tracker", "usertrk:fails", "-o", "r3.h5", "--debug"])


def test_a_module_already_imported_names_where_it_came_from(user_dir, monkeypatch, capsys):
    monkeypatch.chdir(user_dir)
    code = main(["track", "seq.h5", "--tracker", "trackers:make_mine", "-o", "i.h5"])
    err = capsys.readouterr().err
    assert code == 2 and "trackers has no attribute 'make_mine' (imported from " in err, err
