"""The one NaN-aware comparison of arrays against stored expectations.

Used by the regression fixtures (:func:`scenegen.testing.fixtures.compare_boxes`) and by
the pytest plugin's ``scenegen_expect`` (:func:`scenegen.testing.pytest_plugin.
assert_close_to_expected`), so both accept and report differences the same way.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["difference", "load_expected"]


def load_expected(path: Any) -> NDArray[Any] | None:
    """The array stored at ``path`` (``.npy``), or None if the file is not a readable one.

    An empty, truncated or foreign file (text, a pickle) is None rather than numpy's own
    error, so callers can name the file (or, when regenerating, rewrite it).

    Parameters
    ----------
    path : str or Path
        The ``.npy`` file (read without pickles).

    Returns
    -------
    ndarray or None
        The stored array, of its stored shape and dtype; None if the file is missing or
        not a readable ``.npy`` array.
    """
    import io

    from scenegen.io.atomic import read_regular

    try:  # read_regular: a FIFO or a device is refused at once (a ValueError)
        arr = np.load(io.BytesIO(read_regular(path)), allow_pickle=False)
    except (OSError, ValueError, EOFError):
        return None
    return arr if isinstance(arr, np.ndarray) else None


def _nan_mask(arr: NDArray[Any]) -> NDArray[np.bool_]:
    if arr.dtype.kind in "fc":
        return np.isnan(arr)
    return np.zeros(arr.shape, dtype=bool)


def _wide(arr: NDArray[Any]) -> NDArray[Any]:
    # Differences of float32 (or integer) values computed in float64, not in their dtype.
    return arr.astype(np.float64) if arr.dtype.kind in "biuf" else arr


def difference(
    actual: ArrayLike, expected: ArrayLike, *, atol: float = 0.0, rtol: float = 0.0
) -> str | None:
    """What differs between ``actual`` and ``expected``, or None if they agree.

    They agree when the shapes are equal, NaN is exactly where NaN is expected, and every
    other element satisfies ``|actual - expected| <= atol + rtol * |expected|`` (computed
    in float64).

    Parameters
    ----------
    actual, expected : array-like of the same shape
    atol, rtol : float
        Absolute and relative tolerances, >= 0.

    Returns
    -------
    str or None
        One phrase: the shapes, the first element whose NaN-ness differs, or how many
        elements differ with the largest difference and the first differing element.

    Raises
    ------
    ValueError
        If a tolerance is negative.

    Examples
    --------
    >>> difference([1.0, float("nan")], [1.0, float("nan")]) is None
    True
    >>> difference([1.0, 2.5], [1.0, 2.0], atol=0.1)
    '1 of 2 values differ beyond atol=0.1, rtol=0.0 (largest difference 0.5); first at (1,): got 2.5, expected 2.0'
    """  # noqa: E501
    if atol < 0 or rtol < 0:
        raise ValueError(f"tolerances must be >= 0, got atol={atol}, rtol={rtol}")
    arr, exp = np.asarray(actual), np.asarray(expected)
    if arr.shape != exp.shape:
        return f"shape {arr.shape}, expected {exp.shape}"
    nan_a, nan_e = _nan_mask(arr), _nan_mask(exp)
    if np.any(nan_a != nan_e):
        idx = tuple(int(i) for i in np.argwhere(nan_a != nan_e)[0])
        got, want = arr[idx].item(), exp[idx].item()
        return f"NaN pattern differs first at {idx}: got {got!r}, expected {want!r}"
    a, e = _wide(arr), _wide(exp)
    ok = np.isclose(a, e, atol=atol, rtol=rtol) | nan_a
    if ok.all():
        return None
    idx = tuple(int(i) for i in np.argwhere(~ok)[0])
    diff = np.abs(np.where(ok, 0, a - e))
    return (
        f"{int((~ok).sum())} of {ok.size} values differ beyond atol={atol}, rtol={rtol} "
        f"(largest difference {float(diff.max()):.6g}); first at {idx}: "
        f"got {arr[idx].item()!r}, expected {exp[idx].item()!r}"
    )
