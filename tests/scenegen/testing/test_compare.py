"""The one NaN-aware comparison, shared by the fixtures and the pytest plugin."""

from __future__ import annotations

import numpy as np
import pytest

from scenegen.testing.compare import difference
from scenegen.testing.fixtures import EXPECTED_ATOL, compare_boxes


def test_difference_semantics():
    e = np.array([[1.0, np.nan], [3.0, 4.0]], np.float32)
    assert difference(e.copy(), e) is None
    assert difference(e + 0.1, e, atol=0.1 + 1e-6) is None
    assert difference(e * 1.1, e, rtol=0.1 + 1e-6) is None
    assert difference(e[:1], e) == "shape (1, 2), expected (2, 2)"
    got = e.copy()
    got[1, 0] = np.nan
    assert difference(got, e).startswith("NaN pattern differs first at (1, 0): got nan")
    got = e.copy()
    got[1, 1] = 4.5
    assert difference(got, e, atol=0.1) == (
        "1 of 4 values differ beyond atol=0.1, rtol=0.0 (largest difference 0.5); "
        "first at (1, 1): got 4.5, expected 4.0"
    )
    assert difference(np.array([1, 2]), np.array([1, 3]), atol=0.5).startswith("1 of 2")
    with pytest.raises(ValueError, match="tolerances"):
        difference(e, e, rtol=-1)


def test_compare_boxes_uses_the_fixture_tolerance():
    e = np.zeros((2, 1, 4), np.float32)
    assert compare_boxes(e + EXPECTED_ATOL / 2, e) is None
    assert compare_boxes(e + EXPECTED_ATOL * 2, e).startswith("8 of 8 values differ")


def test_difference_names_the_first_element_that_differs_and_is_exact_by_default():
    e = np.zeros((2, 3))
    got = e.copy()
    got[0, 2] = got[1, 0] = 2.0
    got[1, 1] = 5.0
    assert difference(got, e) == (
        "3 of 6 values differ beyond atol=0.0, rtol=0.0 (largest difference 5); "
        "first at (0, 2): got 2.0, expected 0.0"
    )
    got = e.copy()
    got[0, 1] = got[1, 2] = np.nan
    assert difference(got, e).startswith("NaN pattern differs first at (0, 1)")
    # The defaults compare exactly: the smallest difference counts.
    assert difference([1.0], [np.nextafter(1.0, 2.0)]) is not None
    assert difference([1.0], [1.0]) is None


def test_difference_takes_tolerances_by_keyword_and_refuses_negative_ones():
    with pytest.raises(TypeError):
        difference([1.0], [1.0], 0.1)  # atol by position: refused
    for kw in ({"atol": -0.5}, {"atol": -1e-12}, {"rtol": -0.5}):
        with pytest.raises(ValueError, match="tolerances must be >= 0"):
            difference([1.0], [1.0], **kw)


@pytest.mark.parametrize(
    ("got", "want", "largest"),
    [
        (np.array([0, 7], np.uint8), np.array([255, 7], np.uint8), "255"),
        (np.array([True, False]), np.array([False, False]), "1"),
    ],
    ids=["uint8", "bool"],
)
def test_differences_are_computed_in_float64(got, want, largest):
    # In their own dtype, uint8 would wrap (0 - 255 is 1) and bool cannot be subtracted.
    assert f"(largest difference {largest});" in difference(got, want)
