"""The pytest plugin as a user meets it: test files run with ``pytester``."""

import json
from pathlib import Path

import numpy as np
import pytest

from scenegen.io import write
from scenegen.render.plan import generate
from scenegen.testing.fixtures import digests
from scenegen.testing.pytest_plugin import (
    assert_close_to_expected,
    cache_key,
    generator_fingerprint,
)

pytest_plugins = ["pytester"]

SMALL = {
    "width": 40,
    "height": 30,
    "n_frames": 3,
    "entities": [
        {
            "name": "t",
            "role": "target",
            "position": [20, 15],
            "appearance": {"size": [6, 6]},
            "motion": {"x": {"boundary": "reflect", "sigma": 1}, "y": {"boundary": "reflect"}},
        }
    ],
}


def test_sequence_factory_generates_caches_and_freezes(pytester):
    pytester.makepyfile(
        test_user=f"""
        import numpy as np
        import pytest

        CONFIG = {SMALL!r}

        def test_preset(scenegen_sequence):
            seq = scenegen_sequence("kams-a", seed=3, frames=2)
            assert seq.frames.shape == (2, 240, 320, 3) and seq.seed == 3
            assert seq is scenegen_sequence("kams-a", seed=3, frames=2)
            with pytest.raises(ValueError):
                seq.frames[0, 0, 0, 0] = 1

        def test_config(scenegen_sequence):
            seq = scenegen_sequence(CONFIG, seed=1)
            assert isinstance(seq.frames, np.ndarray) and seq.frames.shape == (3, 30, 40, 3)
            assert seq.gt.box.shape == (3, 1, 4)
            assert not seq.gt.box.flags.writeable

        def test_preset_name_is_kept(scenegen_sequence):
            from scenegen import presets
            a = scenegen_sequence("kams-a", seed=3, frames=2)
            b = scenegen_sequence(presets.get("kams-a"), seed=3, frames=2)
            assert a.preset == "kams-a" and b.preset == ""
            np.testing.assert_array_equal(a.frames, b.frames)

        def test_bad_seed(scenegen_sequence):
            from scenegen.errors import ConfigError
            with pytest.raises(ConfigError, match="seed"):
                scenegen_sequence(CONFIG, seed=-1)
        """
    )
    pytester.runpytest("-q").assert_outcomes(passed=4)
    cached = sorted((pytester.path / ".pytest_cache" / "d" / "scenegen").glob("*.h5"))
    assert len(cached) == 3
    # The second session reads the cache: same contents as a fresh generation.
    pytester.runpytest("-q").assert_outcomes(passed=4)
    from scenegen.io import read

    by_seed = {read(p).seed: read(p) for p in cached if not p.stem.endswith("kams-a")}
    # Without pytest's cache plugin the factory still works, from memory only.
    pytester.runpytest("-q", "-p", "no:cacheprovider").assert_outcomes(passed=4)
    np.testing.assert_array_equal(np.asarray(by_seed[1].frames), generate(SMALL, seed=1).frames)


def test_sequence_factory_works_inside_given(pytester):
    pytester.makepyfile(
        test_given=f"""
        from hypothesis import given, settings, strategies as st

        @settings(max_examples=3, deadline=None)
        @given(seed=st.integers(0, 2))
        def test_any_seed(scenegen_sequence, seed):
            assert scenegen_sequence({SMALL!r}, seed=seed).seed == seed
        """
    )
    pytester.runpytest("-q").assert_outcomes(passed=1)


def test_expect_regen_then_compare_then_detect_change(pytester):
    pytester.makepyfile(
        test_expect="""
        import numpy as np
        import pytest

        VALUE = 1.0

        def test_boxes(scenegen_expect):
            boxes = np.array([[[1.0, 2.0, 3.0, 4.0]], [[np.nan, 2.0, 3.0, VALUE]]])
            scenegen_expect("run/boxes", boxes, atol=0.01)

        @pytest.mark.scenegen_tolerance(atol=0.5)
        def test_marker_tolerance(scenegen_expect):
            scenegen_expect("loose", np.array([10.0 + VALUE / 10]))
        """
    )
    first = pytester.runpytest("-q")
    first.assert_outcomes(failed=2)
    first.stdout.fnmatch_lines(["*no stored expectation*--scenegen-regen*"])

    regen = pytester.runpytest("-q", "--scenegen-regen")
    regen.assert_outcomes(passed=2)
    regen.stdout.fnmatch_lines(["*scenegen --scenegen-regen*", "wrote: *boxes.npy"])
    stored = pytester.path / "fixtures" / "expected" / "run" / "boxes.npy"
    assert stored.exists() and (pytester.path / "fixtures" / "expected" / "loose.npy").exists()

    pytester.runpytest("-q").assert_outcomes(passed=2)
    # Unchanged expectations are not rewritten.
    mtime = stored.stat().st_mtime_ns
    again = pytester.runpytest("-q", "--scenegen-regen")
    assert stored.stat().st_mtime_ns == mtime
    assert "wrote:" not in again.stdout.str()

    # A change beyond atol fails, naming the file and the difference; within the marker's
    # tolerance it passes.
    pytester.makepyfile(test_expect=pytester.path.joinpath("test_expect.py").read_text()
                        .replace("VALUE = 1.0", "VALUE = 1.5"))  # fmt: skip
    changed = pytester.runpytest("-q")
    changed.assert_outcomes(passed=1, failed=1)
    changed.stdout.fnmatch_lines(["*boxes.npy: 1 of 8 values differ beyond atol=0.01*"])


def test_the_plugin_under_pytest_xdist(pytester):
    # With -n 2 the tests run in two worker processes. The list of written expectations
    # was empty then (each worker kept its own; the summary is printed by the controller),
    # so `pytest -n auto --scenegen-regen` wrote files without saying which.
    pytester.makepyfile(
        test_a="""
        import numpy as np

        def test_a(scenegen_expect, scenegen_sequence):
            seq = scenegen_sequence("kams-a", seed=3, frames=2)
            scenegen_expect("a", np.asarray(seq.gt.box[:, 0]))
        """,
        test_b="""
        import numpy as np

        def test_b(scenegen_expect_distribution, scenegen_sequence):
            seq = scenegen_sequence("kams-a", seed=3, frames=2)
            scenegen_expect_distribution("b/runs", np.asarray(seq.gt.box[:, 0, :2]) + [[0], [1]])
        """,
    )
    regen = pytester.runpytest("-q", "-n", "2", "--dist", "load", "--scenegen-regen")
    regen.assert_outcomes(passed=2)
    expected = pytester.path / "fixtures" / "expected"
    wrote = sorted(line for line in regen.stdout.lines if line.startswith("wrote: "))
    assert wrote == [f"wrote: {expected / 'a.npy'}", f"wrote: {expected / 'b' / 'runs.npy'}"]
    assert "bringing up nodes" in regen.stdout.str()  # xdist's workers ran the tests
    # One cache entry although both workers asked for the scene; the next run compares.
    cached = list((pytester.path / ".pytest_cache" / "d" / "scenegen").glob("*.h5"))
    assert len(cached) == 1
    again = pytester.runpytest("-q", "-n", "2", "--scenegen-regen")
    again.assert_outcomes(passed=2)
    # An unchanged expectation is not rewritten; a distribution always is (new runs).
    assert [line for line in again.stdout.lines if line.startswith("wrote: ")] == [
        f"wrote: {expected / 'b' / 'runs.npy'}"
    ]
    pytester.runpytest("-q", "-n", "2").assert_outcomes(passed=2)
    np.save(expected / "a.npy", np.load(expected / "a.npy") + 1)
    pytester.runpytest("-q", "-n", "2").assert_outcomes(passed=1, failed=1)


def test_fixture_reads_committed_files_and_checks_digests(pytester):
    folder = pytester.path / "data"
    folder.mkdir()
    seq = generate(SMALL, seed=2)
    write(folder / "small.h5", seq)
    registry = {"fixtures": {"small": {"digests": digests(seq)}}}
    (folder / "registry.json").write_text(json.dumps(registry))
    pytester.makepyfile(
        test_fixture="""
        import pytest

        def test_read(scenegen_fixture):
            seq = scenegen_fixture("small")
            assert seq.frames.shape == (3, 30, 40, 3) and seq.seed == 2

        def test_unknown(scenegen_fixture):
            with pytest.raises(FileNotFoundError, match="known: small"):
                scenegen_fixture("missing")
        """
    )
    pytester.runpytest("-q", "--scenegen-fixtures", str(folder)).assert_outcomes(passed=2)
    # A fixture file that no longer matches its registered digests is refused.
    write(folder / "small.h5", generate(SMALL, seed=3))
    tampered = pytester.runpytest("-q", "--scenegen-fixtures", str(folder))
    tampered.assert_outcomes(passed=1, failed=1)
    tampered.stdout.fnmatch_lines(["*fixture 'small': *frames* differ from the digests*"])


def test_ini_option_sets_the_fixtures_folder(pytester):
    pytester.makeini("[pytest]\nscenegen_fixtures = golden\n")
    pytester.makepyfile(
        test_ini="""
        import numpy as np

        def test_it(scenegen_expect):
            scenegen_expect("x", np.arange(3))
        """
    )
    pytester.runpytest("-q", "--scenegen-regen").assert_outcomes(passed=1)
    assert (pytester.path / "golden" / "expected" / "x.npy").exists()


def test_markers_are_registered_and_applied(pytester):
    pytester.makepyfile(
        test_markers="""
        import pytest

        def test_uses_fixture(scenegen_expect):
            pass

        @pytest.mark.scenegen_tolerance(atol=1.0)
        def test_plain():
            pass
        """
    )
    result = pytester.runpytest("-q", "--strict-markers", "-m", "scenegen")
    result.assert_outcomes(passed=1, deselected=1)
    listed = pytester.runpytest("--markers")
    listed.stdout.fnmatch_lines(["@pytest.mark.scenegen:*", "@pytest.mark.scenegen_tolerance*"])


def test_the_tolerance_marker_binds_like_a_function_and_refuses_what_it_cannot_use(pytester):
    # scenegen_tolerance(0.5) is atol=0.5; an unknown or bad argument was silently
    # ignored (exact comparison) before.
    pytester.makepyfile(
        test_marker="""
        import numpy as np
        import pytest

        SHIFT = 0.0

        @pytest.mark.scenegen_tolerance(0.5)
        def test_positional(scenegen_expect):
            scenegen_expect("pos", np.array([1.0 + SHIFT]))

        @pytest.mark.scenegen_tolerance(0.0, 0.5)
        def test_positional_rtol(scenegen_expect):
            scenegen_expect("rel", np.array([1.0 + SHIFT]))

        @pytest.mark.scenegen_tolerance(tol=0.5)
        def test_unknown(scenegen_expect):
            scenegen_expect("unknown", np.array([1.0]))

        @pytest.mark.scenegen_tolerance(atol=-1)
        def test_negative(scenegen_expect):
            scenegen_expect("negative", np.array([1.0]))
        """
    )
    pytester.runpytest("-q", "--scenegen-regen").assert_outcomes(passed=2, errors=2)
    pytester.makepyfile(test_marker=pytester.path.joinpath("test_marker.py").read_text()
                        .replace("SHIFT = 0.0", "SHIFT = 0.25"))  # fmt: skip
    result = pytester.runpytest("-q")
    result.assert_outcomes(passed=2, errors=2)
    result.stdout.fnmatch_lines(
        [
            "*scenegen_tolerance marker (atol=0.0, rtol=0.0): got an unexpected keyword "
            "argument 'tol'",
            "*scenegen_tolerance marker: atol must be a number >= 0, got -1",
        ],
        consecutive=False,
    )


def test_expectation_keys_must_stay_inside_the_folder(pytester):
    pytester.makepyfile(
        test_keys="""
        import pytest

        @pytest.mark.parametrize("key", ["../escape", "a/../../b", "/abs", "", "a\\\\b"])
        def test_bad_key(scenegen_expect, key):
            with pytest.raises(ValueError, match="key"):
                scenegen_expect(key, [1.0])
        """
    )
    pytester.runpytest("-q", "--scenegen-regen").assert_outcomes(passed=5)


def test_compare_helper_semantics(tmp_path):
    path = tmp_path / "e.npy"
    expected = np.array([1.0, np.nan, 3.0])
    assert assert_close_to_expected(path, expected, regen=True)
    assert not assert_close_to_expected(path, expected, regen=True)
    assert_close_to_expected(path, expected + [0.1, 0, 0.3], atol=0.1, rtol=0.1)
    with pytest.raises(AssertionError, match="NaN pattern"):
        assert_close_to_expected(path, [1.0, 2.0, 3.0], atol=10)
    with pytest.raises(AssertionError, match="shape"):
        assert_close_to_expected(path, [1.0, np.nan])
    with pytest.raises(AssertionError, match=r"largest difference 0\.5"):
        assert_close_to_expected(path, [1.5, np.nan, 3.0], atol=0.1)
    with pytest.raises(ValueError, match="tolerances"):
        assert_close_to_expected(path, expected, atol=-1)


@pytest.mark.parametrize("content", [b"", b"not an array", b"\x93NUMPY\x01\x00v\x00{'descr"])
def test_a_damaged_expectation_names_its_file_and_regen_rewrites_it(tmp_path, content):
    # Was numpy's EOFError / ValueError (naming no file); regen could not repair it.
    path = tmp_path / "e.npy"
    path.write_bytes(content)
    with pytest.raises(AssertionError, match=r"e\.npy: not a readable \.npy file; run pytest "
                                             r"with --scenegen-regen"):
        assert_close_to_expected(path, [1.0])
    assert assert_close_to_expected(path, [1.0], regen=True)
    assert not assert_close_to_expected(path, [1.0])


@pytest.mark.parametrize(
    ("text", "needle"),
    [("{", "not a readable JSON registry"), ("[]", "not a registry (no 'fixtures' mapping)"),
     ('{"fixtures": {"small": 3}}', "the entry of fixture 'small' is malformed")],
)
def test_a_damaged_registry_is_named(tmp_path, text, needle):
    from scenegen.testing.pytest_plugin import _check_digests

    (tmp_path / "registry.json").write_text(text)
    with pytest.raises(AssertionError, match="registry.json: ") as info:
        _check_digests(tmp_path / "registry.json", "small", None)
    assert needle in str(info.value)


def test_a_fifo_registry_is_named_not_waited_on(tmp_path, deadline):
    # The plugin and `scenegen fixtures verify` read a FIFO registry.json for ever.
    import os

    from scenegen.errors import DataError
    from scenegen.testing.fixtures import load_registry
    from scenegen.testing.pytest_plugin import _check_digests

    reg = tmp_path / "registry.json"
    os.mkfifo(reg)
    with deadline(20):
        with pytest.raises(AssertionError, match=f"{reg}: not a readable JSON registry: "
                           f"{reg}: is not a regular file \\(a FIFO\\)"):  # fmt: skip
            _check_digests(reg, "small", None)
        with pytest.raises(DataError, match=f"^{reg}: is not a regular file \\(a FIFO\\)$"):
            load_registry(tmp_path, missing_ok=False)


def test_cache_key_changes_with_every_input():
    from scenegen.config import from_dict

    cfg = from_dict(SMALL)
    base = cache_key(cfg, 0)
    assert base == cache_key(from_dict(SMALL), 0)
    assert len({base, cache_key(cfg, 1), cache_key(cfg, 0, frames=2)}) == 3
    other = from_dict({**SMALL, "width": 41})
    assert cache_key(other, 0) != base
    assert len(generator_fingerprint()) == 16


def test_the_generator_fingerprint_covers_every_config_and_render_module():
    # A module of the config or render package decides pixels and ground truth: one added
    # or split off (config.py became a package) must change the fingerprint with it.
    import scenegen
    from scenegen.testing.pytest_plugin import _generator_sources

    folder = Path(scenegen.__file__).parent
    hashed = set(_generator_sources(folder))
    for package in ("config", "render"):
        modules = set((folder / package).glob("*.py"))
        assert len(modules) > 3 and modules <= hashed
    assert {folder / "presets.py", folder / "io" / "hdf5.py", folder / "sequence.py"} <= hashed
