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

Each parameter is also *documented* once: a dataclass declares, in its class variable
``FIELD_DOCS``, the type text and description of every field it declares itself (a field
it redeclares, say with another default, included). The ``Parameters`` sections of the
dataclass and of its tracker class are generated from those entries by the class
decorator :func:`documented` (the pattern of scipy's and matplotlib's shared docstring
parts): a line ``{parameters}`` in the class docstring becomes one numpydoc entry per
field, in field order, with the default read from the field itself, and a parameter
dataclass gets the one ``Raises`` section of its checks (:data:`PARAMS_RAISES`)::

    >>> from dataclasses import dataclass
    >>> @documented()
    ... @dataclass(frozen=True)
    ... class GridParams(TrackerParams):
    ...     '''Parameters of a grid search.
    ...
    ...     Parameters
    ...     ----------
    ...     {parameters}
    ...     '''
    ...     FIELD_DOCS = {"kernel": (choices(("cone", "box")), "Window kernel."),
    ...                   "cells": ("int", "Cells per side, >= 1.")}
    ...     kernel: str = "cone"
    ...     cells: int = 3
    >>> print(GridParams.__doc__.split("----------")[1].rstrip())
    <BLANKLINE>
        kernel : {"cone", "box"}, default "cone"
            Window kernel.
        cells : int, default 3
            Cells per side, >= 1.
    <BLANKLINE>
        Raises
        ------
        ValueError
            For a bad value, naming the parameter.

A field that no ``FIELD_DOCS`` of its declaring class documents is refused when the
class is decorated (at import), so a parameter cannot be added undocumented, nor its
default written in the text drift from the code's.
"""

from __future__ import annotations

import dataclasses
import inspect
import sys
import textwrap
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any, ClassVar, TypeVar

import numpy as np

from trackers.numbers import is_integral

__all__ = [
    "MAX_PARTICLES",
    "PARAMETERS_MARKER",
    "RNG_RANDOM",
    "RNG_UNUSED",
    "FieldDoc",
    "TrackerParams",
    "check_choice",
    "check_integer",
    "check_number",
    "check_particle_count",
    "choices",
    "documented",
    "is_integral",
    "parameter_entries",
]

#: A parameter's documentation: its numpydoc type text (``"int"``, ``'{"hsv", "rgb"}'``,
#: ``"float or None"``; no default, which is read from the field) and its description.
FieldDoc = tuple[str, str]

#: The line of a class docstring that :func:`documented` replaces by the parameters.
PARAMETERS_MARKER = "{parameters}"

#: The ``Raises`` section :func:`documented` gives a parameter dataclass (its checks in
#: ``__post_init__``), after its parameters, unless its docstring has one of its own.
PARAMS_RAISES = ("Raises", "------", "ValueError", "    For a bad value, naming the parameter.")

#: The ``rng`` entry (``extra`` of :func:`documented`) of a tracker that draws random numbers.
RNG_RANDOM: dict[str, FieldDoc] = {
    "rng": ("numpy.random.Generator, int or None, default None",
            "Source of all randomness; the same seed gives the same track."),
}

#: The ``rng`` entry of a deterministic tracker.
RNG_UNUSED: dict[str, FieldDoc] = {
    "rng": ("numpy.random.Generator, int or None, default None",
            "Unused (the tracker is deterministic); accepted like every tracker's."),
}

_T = TypeVar("_T", bound=type)

MAX_PARTICLES = 1_000_000
"""Largest ``n_particles`` of any tracker. The papers use 40 to 600; the bound makes a
mistyped count fail at once (``n_particles=1e9`` took 24 GB of memory before it failed)."""


@dataclass(frozen=True)
class TrackerParams:
    """Base of the parameter dataclasses (no fields of its own).

    Subclasses are frozen dataclasses whose fields are the tracker's keyword parameters
    (``rng`` excepted) and whose ``__post_init__`` validates them; they document the
    fields they declare in ``FIELD_DOCS`` (see :func:`documented`).
    """

    #: Field name -> (type text, description) of the fields this class itself declares;
    #: read by :func:`parameter_entries`.
    FIELD_DOCS: ClassVar[dict[str, FieldDoc]] = {}

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
    ok = (is_integral(value)
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


def choices(values: Iterable[str]) -> str:
    """The numpydoc type text of a choice among ``values``: ``{"a", "b"}``.

    Build it from the constant the ``__post_init__`` check uses (``RESAMPLERS``, ...), so
    that the documented choices are the accepted ones.

    Parameters
    ----------
    values : iterable of str
        The accepted values (a mapping gives its keys), in the order to show.

    Returns
    -------
    str
        The values in double quotes, comma-separated, in braces.

    Examples
    --------
    >>> choices(("hsv", "rgb"))
    '{"hsv", "rgb"}'
    """
    return "{" + ", ".join(f'"{v}"' for v in values) + "}"


def _default_text(field: dataclasses.Field) -> str:
    """``default <value>`` of a field (strings in double quotes); "" for a required one."""
    if field.default is not dataclasses.MISSING:
        value = field.default
    elif field.default_factory is not dataclasses.MISSING:
        value = field.default_factory()
    else:
        return ""
    return f', default "{value}"' if isinstance(value, str) else f", default {value!r}"


def _declaring_class(params: type, name: str) -> type:
    """The class of ``params``'s MRO that declares field ``name`` last (the dataclass's)."""
    for klass in params.__mro__:
        if name in inspect.get_annotations(klass):
            return klass
    raise AssertionError(f"{params.__name__}: field {name!r} has no annotation")


#: Width of the generated lines, ``indent`` not counted (as ``inspect.getdoc`` shows them).
_WIDTH = 88


def _entry(name: str, type_text: str, description: str, indent: str) -> list[str]:
    """The numpydoc lines of one parameter, at ``indent``, its description wrapped to
    ``_WIDTH`` characters after the indentation; a blank line in ``description`` starts
    a new paragraph."""
    lines = [f"{indent}{name} : {type_text}"]
    for i, paragraph in enumerate(description.split("\n\n")):
        if i:
            lines.append("")
        lines += textwrap.wrap(" ".join(paragraph.split()), width=len(indent) + _WIDTH,
                               initial_indent=indent + "    ",
                               subsequent_indent=indent + "    ",
                               break_long_words=False, break_on_hyphens=False)
    return lines


def parameter_entries(params: type[TrackerParams], indent: str = "") -> list[str]:
    """The numpydoc ``Parameters`` entries of the fields of ``params``, in field order.

    Each entry is ``name : <type text>, default <value>`` with the default read from the
    field (strings in double quotes), then the description, wrapped and indented by
    four more spaces. Type text and description come from the ``FIELD_DOCS`` of the
    class of ``params``'s MRO that declares the field (the most derived one, which sets
    its default).

    Parameters
    ----------
    params : type of TrackerParams
        A parameter dataclass.
    indent : str, default ""
        Prefix of the entries' first lines (the docstring's indentation).

    Returns
    -------
    list of str
        The lines, without line ends.

    Raises
    ------
    TypeError
        If a field is not documented by its declaring class, or a ``FIELD_DOCS`` of the
        MRO documents a name that its class does not declare (a stale entry); the message
        names the class and the field.

    Examples
    --------
    >>> from trackers.meanshift import MeanShiftParams
    >>> for line in parameter_entries(MeanShiftParams)[:2]:
    ...     print(line)
    kernel : {"epanechnikov", "cone"}, default "cone"
        Histogram kernel of the target's colour model: "cone" (the KAMS paper's linear
    """
    for klass in params.__mro__:
        docs = vars(klass).get("FIELD_DOCS", {})
        stale = [n for n in docs if n not in inspect.get_annotations(klass)]
        if stale:
            raise TypeError(f"{klass.__name__}.FIELD_DOCS documents {', '.join(stale)}, "
                            f"not a field that {klass.__name__} declares")
    lines: list[str] = []
    for field in dataclasses.fields(params):
        owner = _declaring_class(params, field.name)
        doc = vars(owner).get("FIELD_DOCS", {}).get(field.name)
        if doc is None:
            raise TypeError(f"{params.__name__}: parameter {field.name!r} (declared by "
                            f"{owner.__name__}) is not documented: add it to "
                            f"{owner.__name__}.FIELD_DOCS")
        type_text, description = doc
        lines += _entry(field.name, type_text + _default_text(field), description, indent)
    return lines


def documented(params: type[TrackerParams] | None = None, *,
               extra: Mapping[str, FieldDoc] | None = None) -> Callable[[_T], _T]:
    """Class decorator: fill the ``Parameters`` section of the class's docstring.

    The docstring's line ``{parameters}`` (:data:`PARAMETERS_MARKER`, alone on its line,
    at the docstring's indentation, under the ``Parameters`` heading) is replaced by
    :func:`parameter_entries` of ``params`` at that indentation, followed by the
    ``extra`` entries (a tracker's ``rng``: :data:`RNG_RANDOM`, :data:`RNG_UNUSED`). A
    parameter dataclass whose docstring has no ``Raises`` section gets
    :data:`PARAMS_RAISES` after its parameters. Decorate a parameter dataclass *above*
    ``@dataclass``. Under ``python -OO`` the docstring is left as it is (stripped); the
    fields are checked all the same.

    Parameters
    ----------
    params : type of TrackerParams or None, default None
        The dataclass whose fields are documented; None: the decorated class itself if
        it is a ``TrackerParams`` dataclass, else its ``Params`` (a tracker class).
    extra : mapping of str to (str, str), optional
        More entries after the fields, name -> (type text, description); the type text
        is written as given (with its default, if any).

    Returns
    -------
    callable
        The decorator; it returns the class it is given, its ``__doc__`` replaced.

    Raises
    ------
    TypeError
        When decorating: a field without documentation (:func:`parameter_entries`),
        ``params`` that is not a ``TrackerParams`` dataclass or differs from the class's
        ``Params``, or a docstring without exactly one marker line.
    """

    def decorate(cls: _T) -> _T:
        own = cls if issubclass(cls, TrackerParams) else getattr(cls, "Params", None)
        source = own if params is None else params
        if source is None or not (isinstance(source, type) and issubclass(source, TrackerParams)
                                  and dataclasses.is_dataclass(source)):
            raise TypeError(f"{cls.__name__}: documented() needs a TrackerParams dataclass, "
                            f"got {source!r}")
        if own is not None and source is not own:
            raise TypeError(f"{cls.__name__}: documented({source.__name__}) but its "
                            f"parameters are {own.__name__}")
        doc = cls.__doc__
        if doc is None or sys.flags.optimize >= 2:
            # python -OO stripped the docstring (``dataclass`` then writes the signature
            # in its place): nothing to fill, the fields are checked all the same.
            parameter_entries(source)
            return cls
        lines = doc.split("\n")
        at = [i for i, line in enumerate(lines) if line.strip() == PARAMETERS_MARKER]
        if len(at) != 1:
            raise TypeError(f"{cls.__name__}: the docstring needs one line "
                            f"{PARAMETERS_MARKER!r} in its Parameters section, found "
                            f"{len(at)}")
        line = lines[at[0]]
        indent = line[: len(line) - len(line.lstrip())]
        block = parameter_entries(source, indent)
        for name, (type_text, description) in (extra or {}).items():
            block += _entry(name, type_text, description, indent)
        if own is cls and not any(line.strip() == "Raises" for line in lines):
            block += ["", *(indent + part for part in PARAMS_RAISES), ""]
        lines[at[0]: at[0] + 1] = block
        cls.__doc__ = "\n".join(lines)
        return cls

    return decorate
