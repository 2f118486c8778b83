"""The README's "Testing your own tracker with scenegen" example runs as written.

The section lives in README.md only (a copy in docs/ had drifted from it).
"""

import re
from pathlib import Path

pytest_plugins = ["pytester"]

ROOT = Path(__file__).resolve().parents[2]
HEADING = "Testing your own tracker with scenegen"


def _example() -> tuple[Path, str]:
    source = ROOT / "README.md"
    text = source.read_text(encoding="utf-8")
    section = text[text.index(f"## {HEADING}\n") :]  # not the contents line
    match = re.search(r"```python\n(.*?)```", section, flags=re.DOTALL)
    assert match is not None, f"{source}: no python code block after {HEADING!r}"
    return source, match.group(1)


def test_example_is_short():
    source, code = _example()
    assert len(code.splitlines()) < 20, f"{source}: the example has {len(code.splitlines())} lines"


def test_example_runs_as_written(pytester):
    _, code = _example()
    pytester.makepyfile(test_my_tracker=code)
    # In a fresh process, as a user runs it (seeded): first store the expectation, then
    # compare with it.
    seeded = ("-q", "--hypothesis-seed=0")
    pytester.runpytest_subprocess(*seeded, "--scenegen-regen").assert_outcomes(passed=2)
    assert (pytester.path / "fixtures" / "expected" / "kams-a" / "meanshift.npy").exists()
    pytester.runpytest_subprocess(*seeded).assert_outcomes(passed=2)
