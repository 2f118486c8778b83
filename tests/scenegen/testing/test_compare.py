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
