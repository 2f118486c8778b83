"""Test tooling for tracker authors: the conformance suite, hypothesis strategies, the
pytest plugin, built-in fixtures.

Nothing here imports :mod:`trackers`: the tooling works for any tracker.
"""

from scenegen.testing.checks import SceneError
from scenegen.testing.conformance import (
    CHECKS,
    CheckResult,
    ConformanceReport,
    check_tracker,
    checks_table,
    parametrize_with_checks,
)

__all__ = [
    "CHECKS",
    "CheckResult",
    "ConformanceReport",
    "SceneError",
    "check_tracker",
    "checks_table",
    "parametrize_with_checks",
]
