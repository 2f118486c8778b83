"""The conformance suite on our 12 trackers and on cv2.TrackerMIL; the README's table."""

from __future__ import annotations

import functools
import re
from pathlib import Path

import pytest

import trackers
from scenegen.testing import check_tracker, checks_table, parametrize_with_checks
from trackers.adapters import opencv

# Which of our trackers recover a target after a short full occlusion (the particle
# filters, whose spread of hypotheses outlives a few frames without evidence); the others
# (mean shift, SOK, Kalman and SHM follow a colour mode and lose it) do not claim it.
HANDLES_OCCLUSION = {"condensation", "joint-pf", "ps", "dps", "annealed", "hybrid", "kams"}
MIL_OPTIONS = {"repeats": 3, "min_pass_rate": 2 / 3}
README = Path(__file__).resolve().parents[2] / "README.md"


def ours(name: str):
    factory = functools.partial(trackers.make, name)
    factory.__qualname__ = name  # the test ids and report rows
    return factory


def mil(**kw):
    return opencv("MIL", **kw)


mil.__qualname__ = "cv2.TrackerMIL"

OURS = [(ours(n), {"handles_occlusion": n in HANDLES_OCCLUSION}) for n in trackers.names()]


@parametrize_with_checks(OURS)
def test_our_trackers_conform(factory, check):
    check(factory)


@pytest.mark.parametrize("check", ["protocol", "edge_fixtures", "boxes"])
def test_mil_runs_everywhere(check):
    assert check_tracker(mil, checks=[check]).passed


def _table() -> str:
    reports = [check_tracker(f, report=True, handles_occlusion=True) for f, _ in OURS]
    reports.append(check_tracker(mil, report=True, handles_occlusion=True, **MIL_OPTIONS))
    return checks_table(reports)


@pytest.mark.slow
def test_readme_table_is_what_the_suite_finds():
    block = re.search(r"<!-- conformance-table -->\n(.*?)\n<!-- /conformance-table -->",
                      README.read_text(encoding="utf-8"), re.S)  # fmt: skip
    assert block is not None, "README lacks the conformance table markers"
    assert block.group(1).strip() == _table()
