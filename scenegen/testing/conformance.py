"""A conformance suite for any tracker, in the spirit of scikit-learn's ``check_estimator``.

A tracker is anything with ``init(frame, boxes)`` and ``step(frame)`` returning an object
with ``boxes`` (K, 4) (the protocol of :mod:`trackers.protocol`, restated here because the
library never imports ``trackers``). :func:`check_tracker` builds trackers from a
*factory* (a class or any callable; it is given ``rng=seed`` when it accepts ``rng``) and
runs the named checks of :data:`CHECKS` on small generated scenes:

``protocol``
    The factory's object has callable ``init`` and ``step``.
``edge_fixtures``
    It runs without exception on every edge-case built-in fixture (``single-frame``,
    ``one-pixel``, ``enter-leave``, ``full-occlusion``, ``distractor-on-target``),
    started from the ground-truth boxes of the targets present at frame 0. Frames are
    passed read-only, so a tracker writing into its input fails here (and the message
    says so, whatever error the write raised).
``boxes``
    On those runs, and on a scene of two targets (K = 2), every estimate's ``boxes`` has
    shape (K, 4) and each row is either finite or all NaN (a lost target).
``deterministic``
    Two trackers made with the same seed give identical boxes, on a scene of one target
    and on the scene of two (only if the tracker claims it: ``deterministic`` attribute,
    default True, or the ``deterministic`` option).
``translation_equivariance``
    On a scene and the same scene seen by a camera shifted by (dx, dy) pixels, the
    estimated centres differ by (dx, dy) within ``equivariance_tol`` pixels, every frame.
``keeps_lone_target``
    A lone, slowly moving, unoccluded target on a textured background is kept: IoU with
    the ground truth at least ``iou_threshold`` in every frame.
``recovers_after_occlusion``
    A target hidden behind an occluder for 3 frames is found again: IoU at least
    ``iou_threshold`` in each of the last 4 frames (only if the tracker claims it:
    ``handles_occlusion`` attribute, default False, or the ``handles_occlusion`` option).

When boxes that fail ``keeps_lone_target`` or ``recovers_after_occlusion`` would pass
read as [cx, cy, w, h], [x0, y0, x1, y1] or [y, x, h, w], the message names that
convention.

A stochastic tracker is judged over ``repeats`` runs (seeds ``seed``, ``seed + 1``, ...):
the behavioural checks (equivariance, lone target, occlusion) pass when at least
``min_pass_rate`` of the runs pass, and their messages give the rate and the first three
failing runs (and how many more). ``check_tracker(..., report=True)`` returns a
:class:`ConformanceReport` instead of raising; :func:`parametrize_with_checks` makes one
pytest test per tracker and check.

Examples
--------
>>> import numpy as np
>>> class Still:                       # a tracker that never moves its boxes
...     def init(self, frame, boxes):
...         self.boxes = np.asarray(boxes, dtype=float)
...     def step(self, frame):
...         return type("E", (), {"boxes": self.boxes})()
>>> report = check_tracker(Still, report=True, checks=["protocol", "boxes"])
>>> report.passed
True
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

from scenegen.testing.checks import (
    CHECKS,
    EDGE_FIXTURES,
    NotApplicable,
    Options,
    SceneError,
    first_line,
    label,
)

__all__ = [
    "CHECKS",
    "EDGE_FIXTURES",
    "CheckResult",
    "ConformanceReport",
    "Options",
    "check_tracker",
    "checks_table",
    "parametrize_with_checks",
]


@dataclass(frozen=True)
class CheckResult:
    """One check's outcome: ``status`` is ``"passed"``, ``"failed"`` or ``"skipped"``.

    Attributes
    ----------
    name : str
        The check's name (a key of :data:`CHECKS`).
    status : {"passed", "failed", "skipped"}
        Its outcome.
    message : str
        What it found: why it failed or was skipped, or a note when it passed ("" if
        none).
    """

    name: str
    status: str
    message: str = ""


@dataclass(frozen=True)
class ConformanceReport:
    """What :func:`check_tracker` found, one :class:`CheckResult` per check run.

    Attributes
    ----------
    tracker : str
        The factory's name (:func:`~scenegen.testing.checks.label`).
    results : tuple of CheckResult
        One per check run, in the order run.
    options : Options
        The options the checks ran with.
    """

    tracker: str
    results: tuple[CheckResult, ...]
    options: Options = field(default_factory=Options)

    @property
    def passed(self) -> bool:
        """True if no check failed (skipped checks do not fail)."""
        return not self.failed

    @property
    def failed(self) -> list[str]:
        """Names of the failed checks."""
        return [r.name for r in self.results if r.status == "failed"]

    def status(self, name: str) -> str:
        """The status of check ``name`` (KeyError if it was not run).

        Parameters
        ----------
        name : str
            The check's name (a key of :data:`CHECKS`).

        Returns
        -------
        {"passed", "failed", "skipped"}
            Its outcome.

        Raises
        ------
        KeyError
            If no check ``name`` was run.
        """
        for r in self.results:
            if r.name == name:
                return r.status
        raise KeyError(f"check {name!r} was not run; ran: {', '.join(self.names())}")

    def names(self) -> list[str]:
        """Names of the checks run, in the order run.

        Returns
        -------
        list of str
            One name per result.
        """
        return [r.name for r in self.results]

    def as_dict(self) -> dict[str, Any]:
        """The report as plain data (for JSON).

        Returns
        -------
        dict
            ``{"tracker": str, "passed": bool, "checks": {name: {"status": str,
            "message": str}}}``, the checks in the order run.
        """
        return {
            "tracker": self.tracker,
            "passed": self.passed,
            "checks": {r.name: {"status": r.status, "message": r.message} for r in self.results},
        }

    def __str__(self) -> str:
        lines = [f"conformance of {self.tracker}:"]
        for r in self.results:
            lines.append(f"  {r.status:7s} {r.name}" + (f": {r.message}" if r.message else ""))
        return "\n".join(lines)


def _run_check(name: str, factory: Callable[..., Any], opts: Options) -> CheckResult:
    try:
        return CheckResult(name, "passed", CHECKS[name](factory, opts))
    except SceneError:
        raise  # the environment's fault, not the tracker's
    except NotApplicable as why:
        return CheckResult(name, "skipped", str(why))
    except AssertionError as err:
        return CheckResult(name, "failed", str(err))
    except (KeyboardInterrupt, GeneratorExit):
        raise
    except BaseException as err:  # the tracker's own errors (a SystemExit too) fail the check
        return CheckResult(name, "failed", f"{type(err).__name__}: {first_line(err)}")


def check_tracker(
    factory: Callable[..., Any], *, report: bool = False, **options: Any
) -> ConformanceReport:
    """Run the conformance checks on the trackers ``factory`` makes.

    Parameters
    ----------
    factory : callable
        A class or function returning a new tracker; called as ``factory(rng=seed)``
        when it accepts ``rng`` (or ``**kwargs``), else ``factory()``. Use
        ``functools.partial`` (or a lambda taking ``rng``) to fix other parameters.
    report : bool, default False
        Return the report even when a check fails, instead of raising.
    **options : Any
        The fields of :class:`Options` (``repeats``, ``min_pass_rate``,
        ``deterministic``, ``handles_occlusion``, ``iou_threshold``,
        ``equivariance_tol``, ``seed``, ``checks``; ``checks`` may be one name or a
        list).

    Returns
    -------
    ConformanceReport
        One result per check run; when ``protocol`` fails, every later check is
        skipped.

    Raises
    ------
    AssertionError
        Unless ``report``: naming every failed check and why.
    ValueError
        For an unknown option or check name, or a bad option value.
    SceneError
        If a conformance scene cannot be built (the environment's fault, say an
        unwritable fixture cache).
    """
    opts = make_options(options)
    results = [_run_check(n, factory, opts) for n in _names(opts)]
    if results and results[0].name == "protocol" and results[0].status == "failed":
        results = [results[0]] + [
            CheckResult(r.name, "skipped", "not a tracker (see protocol)") for r in results[1:]
        ]
    out = ConformanceReport(label(factory), tuple(results), opts)
    if not report and not out.passed:
        failed = [r for r in out.results if r.status == "failed"]
        raise AssertionError(
            f"{out.tracker} failed {len(failed)} conformance check(s): "
            + "; ".join(f"{r.name}: {r.message}" for r in failed)
        )
    return out


def make_options(options: dict[str, Any]) -> Options:
    """:class:`Options` from keyword options (``checks`` may be one name or a list).

    Raises
    ------
    ValueError
        For an unknown option or check name, or a bad option value.
    """
    valid = list(Options.__dataclass_fields__)
    for key in options:
        if key not in valid:
            raise ValueError(f"unknown option {key!r}; valid: {', '.join(valid)}")
    options = dict(options)
    if isinstance(options.get("checks"), str):
        options["checks"] = (options["checks"],)
    elif options.get("checks") is not None:
        options["checks"] = tuple(options["checks"])
    return Options(**options)


def _names(opts: Options) -> list[str]:
    return list(CHECKS) if opts.checks is None else list(opts.checks)


def _entries(factories: Iterable[Any]) -> list[tuple[Callable[..., Any], Options]]:
    out = []
    for entry in factories:
        if isinstance(entry, tuple):
            factory, options = entry
            try:
                out.append((factory, make_options(dict(options))))
            except ValueError as err:
                raise ValueError(f"options of {label(factory)}: {err}") from None
        else:
            out.append((entry, Options()))
    return out


def parametrize_with_checks(factories: Iterable[Any]) -> Any:
    """A ``pytest.mark.parametrize`` of ``(factory, check)``, one test per factory and check.

    Parameters
    ----------
    factories : iterable
        Factories, or ``(factory, options)`` pairs with :func:`check_tracker`'s options
        (``checks`` chooses the tests made for that factory; a bad option is a
        ``ValueError`` when the tests are collected).

    Returns
    -------
    pytest.MarkDecorator
        The ``parametrize`` mark over the arguments ``factory`` and ``check``, with test
        ids ``<factory label>-<check name>``.

    Raises
    ------
    ValueError
        For an unknown option or check name, or a bad option value, naming the factory.

    Examples
    --------
    ::

        from scenegen.testing import parametrize_with_checks

        @parametrize_with_checks([MyTracker, (make_noisy, {"repeats": 5, "min_pass_rate": 0.8})])
        def test_conformance(factory, check):
            check(factory)

    ``check(factory)`` raises AssertionError with the check's message if it fails, and
    calls ``pytest.skip`` if it does not apply.
    """
    import pytest

    params = []
    for factory, opts in _entries(factories):
        row = label(factory)
        for name in _names(opts):
            params.append(pytest.param(factory, _Check(name, opts), id=f"{row}-{name}"))
    return pytest.mark.parametrize(("factory", "check"), params)


@dataclass(frozen=True)
class _Check:
    """One named check with its options; called with the factory inside a test."""

    name: str
    options: Options = field(default_factory=Options)

    def __call__(self, factory: Callable[..., Any]) -> None:
        import pytest

        result = _run_check(self.name, factory, self.options)
        if result.status == "skipped":
            pytest.skip(f"{self.name}: {result.message}")
        if result.status == "failed":
            raise AssertionError(f"{label(factory)}: {self.name}: {result.message}")

    def __repr__(self) -> str:
        return self.name


def checks_table(reports: Iterable[ConformanceReport]) -> str:
    """A Markdown table: one row per report, one column per check (pass / FAIL / skip).

    Parameters
    ----------
    reports : iterable of ConformanceReport
        The reports, one row each in the order given.

    Returns
    -------
    str
        The table, without a final newline: a column for every check of :data:`CHECKS`,
        its cell ``pass``, ``FAIL``, ``–`` (skipped) or empty (not run).
    """
    reports = list(reports)
    names = list(CHECKS)
    mark = {"passed": "pass", "failed": "FAIL", "skipped": "–"}
    lines = [
        "| tracker | " + " | ".join(n.replace("_", " ") for n in names) + " |",
        "| --- |" + " --- |" * len(names),
    ]
    for r in reports:
        cells = []
        for n in names:
            try:
                cells.append(mark[r.status(n)])
            except KeyError:
                cells.append("")
        lines.append(f"| {r.tracker} | " + " | ".join(cells) + " |")
    return "\n".join(lines)
