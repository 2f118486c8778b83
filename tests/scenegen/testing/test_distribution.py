"""scenegen_expect_distribution: stochastic outputs pinned without flaky failures."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from scenegen.testing.distribution import assert_distribution_matches, distribution_difference

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



def _band(new, old, z, atol):
    """The module docstring's band, transcribed: z standard errors (ddof=1) plus atol."""
    se2 = np.var(new, axis=0, ddof=1) / len(new) + np.var(old, axis=0, ddof=1) / len(old)
    return z * np.sqrt(se2) + atol


@pytest.mark.parametrize(("z", "atol"), [(4.0, 0.0), (2.5, 0.0), (0.5, 0.01)])
def test_the_band_is_the_documented_formula_at_its_edge(z, atol):
    # Unequal run counts and spreads on each side, so that each term of the band counts:
    # a mean just inside the band agrees, just outside it does not.
    rng = np.random.default_rng(3)
    new0 = rng.normal(0.0, 0.02, (5, 3))
    old = rng.normal(0.0, 0.07, (9, 3))
    new0 -= new0.mean(axis=0) - old.mean(axis=0)  # equal means: the gap is the shift
    band = _band(new0, old, z, atol)
    assert distribution_difference(new0 + band * (1 - 1e-6), old, z=z, atol=atol) is None
    msg = distribution_difference(new0 + band * (1 + 1e-6), old, z=z, atol=atol)
    assert msg.startswith("3 of 3 elements out of band; first (0,): ")
    assert f"allowed |difference| <= {band[0]:.3g} " in msg
    # Out of band on one element only: that one is named.
    shift = np.array([0.0, 0.0, 1.0]) * band * 1.01
    assert distribution_difference(new0 + shift, old, z=z, atol=atol).startswith(
        "1 of 3 elements out of band; first (2,): "
    )


def test_z_and_atol_are_keywords_and_checked():
    ones = np.ones((3, 2))
    for z in (0.0, -1.0):
        with pytest.raises(ValueError, match="need z > 0"):
            distribution_difference(ones, ones, z=z)
    assert distribution_difference(ones, ones, z=0.5) is None
    with pytest.raises(ValueError, match="atol >= 0"):
        distribution_difference(ones, ones, atol=-1e-9)
    with pytest.raises(TypeError):
        distribution_difference(ones, ones, 4.0)  # z by position: refused
    with pytest.raises(TypeError):
        assert_distribution_matches(Path("unused.npy"), ones, 4.0)


def test_the_first_element_with_nan_on_one_side_is_named():
    stored = np.ones((2, 3))
    new = np.ones((2, 3))
    new[0, 1] = new[1, 2] = np.nan
    assert distribution_difference(new, stored).startswith(
        "element (1,) is NaN in some runs only"
    )
    new = np.ones((2, 3))
    new[:, 1] = new[:, 2] = np.nan
    assert distribution_difference(new, stored) == "element (1,) is NaN in the new runs only"
    assert distribution_difference(stored, new) == "element (1,) is NaN in the stored runs only"


@pytest.mark.parametrize("runs", [np.float64(0.5), np.ones(1), np.ones((1, 3))])
def test_fewer_than_two_runs_are_one_value_error(runs):
    with pytest.raises(ValueError, match="must have shape"):
        distribution_difference(runs, np.ones((3, 3)))
    with pytest.raises(ValueError, match="must have shape"):
        distribution_difference(np.ones((3, 3)), runs)


def test_the_stored_comparison_is_exact_but_for_the_band_by_default(tmp_path):
    # Constant runs: no spread, so with the default atol (0) any change of the mean is
    # out of band, and an atol given widens the band by itself.
    path = tmp_path / "d.npy"
    assert assert_distribution_matches(path, np.full((4, 2), 0.5), regen=True)
    assert not assert_distribution_matches(path, np.full((4, 2), 0.5))
    with pytest.raises(AssertionError, match="2 of 2 elements out of band"):
        assert_distribution_matches(path, np.full((4, 2), 0.5 + 1e-9))
    assert not assert_distribution_matches(path, np.full((4, 2), 0.75), atol=0.3)


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
