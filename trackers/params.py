"""Tracker parameters: one frozen dataclass per tracker family, validated on construction.

Every tracker class names its parameter dataclass in ``Params`` (a subclass of
``TrackerParams``). The constructor's keyword arguments are that dataclass's fields plus
``rng``; ``trackers.make(name, **params)``, ``trackers.registry.parameters(name)`` and
``trackers.registry.defaults(name)`` read the fields, so a parameter and its default are
written once, in the dataclass::

    >>> from trackers.particle import DPSParams
    >>> p = DPSParams(n_particles=200, n_groups=2)
    >>> p.n_particles, p.lam
    (200, 20.0)
    >>> DPSParams(n_particles=0)
    Traceback (most recent call last):
    ...
    ValueError: n_particles must be an integer in [1, 1000000], got 0

Each dataclass checks each of its fields once, in ``__post_init__``; an error is one line
that names the parameter and the bad value. Integer fields given as integral floats
(``100.0``) are stored as ``int``; float fields as ``float``. The checkers below are what
the ``__post_init__`` methods share.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = [
    "MAX_PARTICLES",
    "TrackerParams",
    "check_choice",
    "check_integer",
    "check_number",
    "check_particle_count",
]

MAX_PARTICLES = 1_000_000
"""Largest ``n_particles`` of any tracker. The papers use 40 to 600; the bound makes a
mistyped count fail at once (``n_particles=1e9`` took 24 GB of memory before it failed)."""


@dataclass(frozen=True)
class TrackerParams:
    """Base of the parameter dataclasses (no fields of its own).

    Subclasses are frozen dataclasses whose fields are the tracker's keyword parameters
    (``rng`` excepted) and whose ``__post_init__`` validates them.
    """

    @classmethod
    def names(cls) -> list[str]:
        """Field names, in declaration order (base classes' fields first).

        Returns
        -------
        list of str
            The names of the dataclass's fields (the tracker's keyword parameters but
            ``rng``).
        """
        return [f.name for f in dataclasses.fields(cls)]

    @classmethod
    def defaults(cls) -> dict[str, Any]:
        """Field name -> default value.

        Returns
        -------
        dict of str to Any
            Each field's default as the dataclass declares it, in declaration order.
        """
        return {f.name: f.default for f in dataclasses.fields(cls)}

    def replace(self, **changes: Any) -> TrackerParams:
        """A copy with ``changes`` applied (validated again).

        Parameters
        ----------
        **changes : Any
            New values of fields, by name.

        Returns
        -------
        TrackerParams
            A new instance of the same class (``dataclasses.replace``); ``self`` is
            unchanged.

        Raises
        ------
        TypeError
            For a name that is not a field.
        ValueError
            From ``__post_init__``, for a bad value, naming the parameter.
        """
        return dataclasses.replace(self, **changes)

    def _set(self, name: str, value: Any) -> None:
        """Store a normalised value in the frozen instance (``__post_init__`` only)."""
        object.__setattr__(self, name, value)


def check_integer(params: TrackerParams, name: str, *, low: int | None = None,
                  high: int | None = None, optional: bool = False) -> None:
    """Check that field ``name`` is an integer in [low, high] and store it as ``int``.

    With ``optional``, None is accepted as is.

    Parameters
    ----------
    params : TrackerParams
        The dataclass being validated (from its ``__post_init__``); the field is replaced
        by its ``int`` value in place.
    name : str
        Name of the field.
    low, high : int or None, optional
        Inclusive bounds; None (the default) leaves that side unbounded.
    optional : bool, default False
        Accept None.

    Raises
    ------
    ValueError
        ``"<name> must be an integer >= <low>, got <value>"`` (or the range it must lie in).
    """
    value = getattr(params, name)
    if optional and value is None:
        return
    ok = (not isinstance(value, bool) and isinstance(value, (int, float, np.integer, np.floating))
          and np.isfinite(value) and int(value) == value
          and (low is None or value >= low) and (high is None or value <= high))
    if not ok:
        if low is not None and high is not None:
            what = f"an integer in [{low}, {high}]"
        elif low is not None:
            what = f"an integer >= {low}"
        else:
            what = "an integer"
        none = " or None" if optional else ""
        raise ValueError(f"{name} must be {what}{none}, got {value!r}")
    params._set(name, int(value))


def check_particle_count(params: TrackerParams) -> None:
    """Check ``n_particles``: an integer in [1, :data:`MAX_PARTICLES`], stored as ``int``.

    Parameters
    ----------
    params : TrackerParams
        A dataclass with an ``n_particles`` field (from its ``__post_init__``).

    Raises
    ------
    ValueError
        ``"n_particles must be an integer in [1, 1000000], got <value>"``.
    """
    check_integer(params, "n_particles", low=1, high=MAX_PARTICLES)


def check_number(params: TrackerParams, name: str, *, low: float | None = None,
                 high: float | None = None, low_open: bool = False,
                 high_open: bool = False) -> None:
    """Check that field ``name`` is a finite number in its interval and store it as ``float``.

    ``low``/``high`` bound the interval, closed unless ``low_open``/``high_open``.
    The value is converted with ``float()``; booleans, text (``"30"``: a number written as
    text is refused, as by :func:`check_integer`, rather than read), unconvertible values
    and NaN/inf are rejected.

    Parameters
    ----------
    params : TrackerParams
        The dataclass being validated (from its ``__post_init__``); the field is replaced
        by its ``float`` value in place.
    name : str
        Name of the field.
    low, high : float or None, optional
        Bounds of the interval; None (the default) leaves that side unbounded.
    low_open, high_open : bool, default False
        Exclude ``low`` (``high``) itself from the interval.

    Raises
    ------
    ValueError
        ``"<name> must be <interval>, got <value>"``.
    """
    value = getattr(params, name)
    try:
        x = float(value)
    except (TypeError, ValueError):
        x = float("nan")
    if isinstance(value, (bool, str, bytes)):
        x = float("nan")
    ok = np.isfinite(x)
    if low is not None:
        ok = ok and (x > low if low_open else x >= low)
    if high is not None:
        ok = ok and (x < high if high_open else x <= high)
    if not ok:
        if low is not None and high is not None:
            what = (f"in {'(' if low_open else '['}{low:g}, {high:g}"
                    f"{')' if high_open else ']'}")
        elif low is not None:
            what = f"finite and {'>' if low_open else '>='} {low:g}"
        elif high is not None:
            what = f"finite and {'<' if high_open else '<='} {high:g}"
        else:
            what = "finite"
        raise ValueError(f"{name} must be {what}, got {value!r}")
    params._set(name, x)


def check_choice(params: TrackerParams, name: str, valid: Iterable[str], *,
                 what: str | None = None) -> None:
    """Check that field ``name`` is one of ``valid``.

    Parameters
    ----------
    params : TrackerParams
        The dataclass being validated (from its ``__post_init__``); left unchanged.
    name : str
        Name of the field.
    valid : iterable of str
        The accepted values.
    what : str or None, optional
        What the value is called in the error message; None (the default): ``name``.

    Raises
    ------
    ValueError
        ``"unknown <what> <value>; valid: <a, b, …>"`` (``what`` defaults to ``name``).
    """
    value = getattr(params, name)
    valid = list(valid)
    if not isinstance(value, str) or value not in valid:
        raise ValueError(f"unknown {what or name} {value!r}; valid: {', '.join(valid)}")
