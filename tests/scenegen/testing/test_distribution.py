"""scenegen_expect_distribution: stochastic outputs pinned without flaky failures."""

from __future__ import annotations

import numpy as np
import pytest

from scenegen.testing.distribution import distribution_difference

pytest_plugins = ["pytester"]


def test_band_is_z_standard_errors_plus_atol():
    rng = np.random.default_rng(0)
    stored = rng.normal(0.6, 0.05, size=(8, 2))
    assert distribution_difference(stored + 0.01, stored) is None
    msg = distribution_difference(stored + 0.2, stored)
    assert msg.startswith("2 of 2 elements out of band; first (0,): mean ")
    assert "over 8 runs" in msg and "(z=4, atol=0)" in msg
    constant = np.full((5, 1), 0.5)
    assert distribution_difference(constant + 0.01, constant) is not None
    assert distribution_difference(constant + 0.01, constant, atol=0.02) is None


def test_false_alarms_are_rare_for_an_unchanged_tracker():
    # 2000 pairs of 5-run samples of one distribution: the z=4 band almost never fails.
    rng = np.random.default_rng(1)
    fails = sum(
        distribution_difference(rng.normal(0, 1, (5, 1)), rng.normal(0, 1, (5, 1))) is not None
        for _ in range(2000)
    )
    assert fails <= 20  # 0.4% at R=5, 0.06% at R=10 (measured over 20000 pairs)


@pytest.mark.parametrize(
    ("new", "needle"),
    [
        (np.array([[1.0, np.nan], [1.0, 2.0]]), "NaN in some runs only"),
        (np.array([[np.nan, 1.0], [np.nan, 1.0]]), "NaN in the new runs only"),
        (np.ones((3, 3)), "per-run shape (3,), stored (2,)"),
    ],
)
def test_nan_and_shapes(new, needle):
    stored = np.array([[1.0, 2.0], [1.1, 2.1]])
    if "shape" in needle:
        with pytest.raises(AssertionError, match=r"per-run shape \(3,\), stored \(2,\)"):
            distribution_difference(new, stored)
    else:
        assert needle in distribution_difference(new, stored)
    with pytest.raises(ValueError, match="R >= 2 runs"):
        distribution_difference(np.ones((1, 2)), stored)


def test_plugin_pins_an_unseeded_tracker_across_sessions(pytester):
    pytester.makepyfile(
        test_stochastic="""
        import numpy as np

        SHIFT = 0.0
        SESSION = 0  # stands for a tracker whose runs differ from session to session
        rng = np.random.default_rng(SESSION)

        def test_pinned(scenegen_expect_distribution):
            runs = 0.6 + SHIFT + rng.normal(0, 0.05, size=10)  # one mean IoU per run
            scenegen_expect_distribution("mil/mean-iou", runs)
        """
    )
    pytester.runpytest("-q", "--scenegen-regen").assert_outcomes(passed=1)
    assert (pytester.path / "fixtures" / "expected" / "mil" / "mean-iou.npy").exists()
    text = (pytester.path / "test_stochastic.py").read_text()
    for session in (1, 2, 3):  # other runs each session: still within the band
        pytester.makepyfile(test_stochastic=text.replace("SESSION = 0", f"SESSION = {session}"))
        pytester.runpytest("-q").assert_outcomes(passed=1)
    pytester.makepyfile(test_stochastic=text.replace("SHIFT = 0.0", "SHIFT = 0.2"))
    changed = pytester.runpytest("-q")
    changed.assert_outcomes(failed=1)
    changed.stdout.fnmatch_lines(["*mean-iou.npy: 1 of 1 elements out of band*"])


def test_a_damaged_stored_distribution_names_its_file(tmp_path):
    from scenegen.testing.distribution import assert_distribution_matches

    path = tmp_path / "d.npy"
    path.write_bytes(b"")  # was numpy's EOFError, naming no file
    with pytest.raises(AssertionError, match=r"d\.npy: not a readable \.npy file"):
        assert_distribution_matches(path, np.ones((3, 2)))
    assert assert_distribution_matches(path, np.ones((3, 2)), regen=True)
    assert not assert_distribution_matches(path, np.ones((3, 2)))
