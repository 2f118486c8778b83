"""``tools/mutation/mutate.py`` (``make mutate``): which surviving mutants its list of
equivalent ones (``tools/mutation/equivalent.py``) excuses, and the mutants ``--only``
selects. The equivalent mutants are matched by line text; a line can occur more than
once in a module's formula scope, and an entry meant for one copy must not excuse the
same mutation of another."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

TOOL = Path(__file__).resolve().parents[1] / "tools" / "mutation" / "mutate.py"


@pytest.fixture(scope="module")
def tool():
    spec = importlib.util.spec_from_file_location("mutate_tool", TOOL)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # dataclasses look their module up
    try:
        spec.loader.exec_module(mod)
        yield mod
    finally:
        del sys.modules[spec.name]


SOURCE = '''\
def first(x):
    if x == 0:
        return 1
    return x


def second(x):
    y = 2
    if x == 0:
        return 2
    z = 3
    if x == 0:
        return 3
    return x + y + z


def outside(x):
    if x == 0:
        return 4
'''
MUTANT = ("if x == 0:", "if x == -1:")


@pytest.fixture()
def sites(tool, tmp_path):
    path = tmp_path / "module.py"
    path.write_text(SOURCE)
    return tool.scope_sites(path, ("first", "second"))


def _rows(text: str) -> list[int]:
    return [i for i, line in enumerate(SOURCE.splitlines(), start=1) if line.strip() == text]


def test_the_scope_lines_know_their_function_and_the_line_above(sites):
    ifs = _rows("if x == 0:")
    assert len(ifs) == 4
    assert [sites[r].function for r in ifs[:3]] == ["first", "second", "second"]
    assert [sites[r].before for r in ifs[:3]] == ["def first(x):", "y = 2", "z = 3"]
    assert ifs[3] not in sites  # outside the scope


def test_an_entry_for_a_line_that_occurs_more_than_once_must_say_which(tool, sites):
    bare = tool.Equivalent.of((*MUTANT, "why"))
    (error,) = tool.ambiguities([bare], sites)
    assert "occurs 3 times in the scope (in first, second)" in error
    # In first once: enough. In second twice: the line above must tell them apart.
    assert tool.ambiguities([tool.Equivalent.of((*MUTANT, "why", "first"))], sites) == []
    (error,) = tool.ambiguities([tool.Equivalent.of((*MUTANT, "why", ("first", "second")))],
                                sites)
    assert "2 times in second" in error and "after" in error
    assert tool.ambiguities([tool.Equivalent.of((*MUTANT, "why", "second", "z = 3"))],
                            sites) == []
    # A function that does not hold the line, or a wrong line above it, is refused too.
    for entry in ((*MUTANT, "why", "outside"), (*MUTANT, "why", "second", "return 2")):
        (error,) = tool.ambiguities([tool.Equivalent.of(entry)], sites)
        assert "occurs 0 times" in error
    # A line unique in the scope needs nothing more; one found nowhere (a line since
    # changed) matches nothing and is not an error.
    for text in ("y = 2", "w = 5"):
        assert tool.ambiguities([tool.Equivalent.of((text, text + "0", "why"))], sites) == []


def test_an_entry_excuses_only_the_copies_it_names(tool, sites):
    ifs = _rows("if x == 0:")
    entries = [tool.Equivalent.of((*MUTANT, "the second's second", "second", "z = 3")),
               tool.Equivalent.of((*MUTANT, "first's", "first"))]

    def reason(row, original=MUTANT[0], mutated=MUTANT[1]):
        return tool.equivalent_reason(entries, sites, row, original, mutated)

    assert [reason(r) for r in ifs[:3]] == ["first's", None, "the second's second"]
    assert reason(ifs[0], mutated="if x != 0:") is None  # another mutation of the line
    unique = [tool.Equivalent.of(("y = 2", "y = 3", "any copy"))]
    assert tool.equivalent_reason(unique, sites, _rows("y = 2")[0], "y = 2", "y = 3") == \
        "any copy"


def test_every_entry_of_equivalent_py_names_its_line_unambiguously(tool):
    for name, mod in tool.MODULES.items():
        entries = [tool.Equivalent.of(e) for e in tool.EQUIVALENT.get(name, [])]
        sites = tool.scope_sites(tool.ROOT / mod.path, mod.scope)
        assert tool.ambiguities(entries, sites) == [], name


def test_only_selects_functions_of_the_scope_and_line_ranges(tool, tmp_path):
    path = tmp_path / "module.py"
    path.write_text(SOURCE)
    mod = tool.Module(str(path), ("first", "second"), ())
    assert tool.only_spans(path, mod, ("second", "2-3", "9")) == [(7, 14), (2, 3), (9, 9)]
    with pytest.raises(SystemExit, match="neither a line range nor a function"):
        tool.only_spans(path, mod, ("outside",))


def test_the_report_lists_the_mutants_killed_by_the_timeout(tool, tmp_path, monkeypatch,
                                                            capsys):
    """A timed-out mutant counts as killed, and the report lists it to be checked (a loop
    that cannot end, or a survivor that ran out of time under a short --timeout)."""
    from cosmic_ray.work_db import use_db
    from cosmic_ray.work_item import (
        MutationSpec,
        TestOutcome,
        WorkerOutcome,
        WorkItem,
        WorkResult,
    )

    path = tmp_path / "module.py"
    path.write_text(SOURCE)
    mod = tool.Module(str(path), ("first", "second"), ("tests/some_test.py",))
    monkeypatch.setattr(tool, "BUILD", tmp_path)
    row = _rows("if x == 0:")[0]
    diff = "--- a/module.py\n+++ b/module.py\n-    if x == 0:\n+    if x == -1:\n"
    outcomes = {"failed": (TestOutcome.KILLED, "1 failed"),
                "looped": (TestOutcome.KILLED, "timeout"),
                "kept": (TestOutcome.SURVIVED, "3 passed")}
    session = tmp_path / "toy.sqlite"
    with use_db(str(session)) as db:
        for job, (outcome, output) in outcomes.items():
            spec = MutationSpec(str(path), "core/NumberReplacer", 0, (row, 11), (row, 12))
            db.add_work_item(WorkItem(job, [spec]))
            db.set_result(job, WorkResult(worker_outcome=WorkerOutcome.NORMAL, output=output,
                                          test_outcome=outcome, diff=diff))
    assert tool.report("toy", mod, session) == (2, 1, 0)
    head = capsys.readouterr().out
    assert "2 killed / 3 non-equivalent mutants = 66.7 % (1 of the killed by the timeout" in head
    text = (tmp_path / "toy.txt").read_text()
    assert f"TIMEOUT looped line {row}: if x == 0: -> if x == -1:" in text
    assert "TIMEOUT failed" not in text and "SURVIVED kept" in text


@pytest.mark.parametrize("value", ["0", "-5", "nan", "inf"])
def test_a_timeout_that_is_not_a_positive_finite_number_is_refused(tool, value, capsys):
    with pytest.raises(SystemExit) as exc:
        tool.main(["sampling", "--count", "--timeout", value])
    assert exc.value.code == 2
    assert f"--timeout {float(value)}: must be a positive, finite number" in \
        capsys.readouterr().err


def test_retest_with_only_resets_only_the_survivors_on_its_lines(tool, tmp_path):
    """``--retest --only F`` runs F's survivors again and keeps every other result: a
    survivor outside F whose result were forgotten would be skipped as outside the choice
    and drop out of the module's report."""
    from cosmic_ray.work_db import use_db
    from cosmic_ray.work_item import (
        MutationSpec,
        TestOutcome,
        WorkerOutcome,
        WorkItem,
        WorkResult,
    )

    inside, outside = _rows("if x == 0:")[0], _rows("return x + y + z")[0]
    jobs = {"in-kept": (inside, TestOutcome.SURVIVED), "in-killed": (inside, TestOutcome.KILLED),
            "out-kept": (outside, TestOutcome.SURVIVED),
            "in-broken": (inside, TestOutcome.INCOMPETENT)}
    session = tmp_path / "toy.sqlite"
    with use_db(str(session)) as db:
        for job, (row, outcome) in jobs.items():
            spec = MutationSpec("module.py", "core/NumberReplacer", 0, (row, 0), (row, 1))
            db.add_work_item(WorkItem(job, [spec]))
            db.set_result(job, WorkResult(worker_outcome=WorkerOutcome.NORMAL, output="",
                                          test_outcome=outcome, diff=""))
    assert tool.reset_survivors(session, [(inside, inside)]) == 2
    with use_db(str(session)) as db:
        assert {job for job, _ in db.results} == {"in-killed", "out-kept"}
    assert tool.reset_survivors(session) == 1  # no --only: every survivor
    with use_db(str(session)) as db:
        assert {job for job, _ in db.results} == {"in-killed"}
