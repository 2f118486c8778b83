"""What a numeric argument of the trackers accepts: the one test, used by the kernels,
the colour model and the parameter checks.

Numbers written as text and bools are refused everywhere (``"30"`` was read as 30 by
some entry points and ``True`` was 1); an integer argument also takes an integral
finite float (``100.0``, as a YAML or JSON file may write it).
"""

from __future__ import annotations

import numpy as np

__all__ = ["is_integral", "is_number"]


def is_number(value: object) -> bool:
    """Whether ``value`` is a real number (int or float, numpy's too), not a bool or text.

    Parameters
    ----------
    value : object
        The value given.

    Returns
    -------
    bool
        False for bools (Python's and numpy's), text, None and anything else.

    Examples
    --------
    >>> is_number(3), is_number(2.5), is_number(np.float32(1)), is_number(True), is_number("3")
    (True, True, True, False, False)
    """
    return (not isinstance(value, (bool, np.bool_))
            and isinstance(value, (int, float, np.integer, np.floating)))  # fmt: skip


def is_integral(value: object) -> bool:
    """Whether ``value`` is what an integer argument accepts: an integer or an integral
    finite float (``100.0``), numpy's too, but not a bool nor a number written as text.

    Parameters
    ----------
    value : object
        The value given.

    Returns
    -------
    bool
        True if :func:`is_number` and ``int(value)`` is ``value`` exactly (NaN and
        infinities are not).

    Examples
    --------
    >>> is_integral(3), is_integral(3.0), is_integral(3.5), is_integral(True), is_integral("3")
    (True, True, False, False, False)
    """
    return is_number(value) and bool(np.isfinite(value)) and int(value) == value
