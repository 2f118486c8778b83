"""The README's "Benchmark datasets" examples run as written (on a small dataset), and
the family example of docs/datasets.md is valid."""

import re
from pathlib import Path

import yaml

from scenegen.datasets import build_dataset, family_from_dict

ROOT = Path(__file__).resolve().parents[2]


def _section() -> str:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    start = text.index("## Benchmark datasets")
    return text[start : text.index("\n## ", start + 1)]


def test_family_example_is_valid():
    block = re.search(r"```yaml\n(.*?)```", _section(), flags=re.DOTALL).group(1)
    fam = family_from_dict(yaml.safe_load(block), source="README")
    assert fam.count == 400 and fam.grid_size == 4
    assert [d.params["clutter[0].count"] for d in fam.draws(5)] == [0, 200, 400, 600, 0]


def test_reading_example_runs(tmp_path, monkeypatch, capsys):
    code = re.search(r"```python\n(.*?)```", _section(), flags=re.DOTALL).group(1)
    monkeypatch.chdir(tmp_path)
    build_dataset("kams", "data/kams", count=8, frames=16, jobs=1)
    exec(compile(code, "README.md", "exec"), {})
    assert capsys.readouterr().out == "8 ['preset']\n"


def test_reference_family_example_is_valid():
    # docs/datasets.md "Family files": the annotated example is itself a valid family
    # (it gave both `base` and a `preset` axis, and an axis over entities kams-a lacks).
    text = (ROOT / "docs" / "datasets.md").read_text(encoding="utf-8")
    block = re.search(r"```yaml\n(.*?)```", text, flags=re.DOTALL).group(1)
    fam = family_from_dict(yaml.safe_load(block), source="docs/datasets.md")
    assert fam.count == 200 and fam.grid_size == 8
    draws = fam.draws(8)  # one per grid point, each a validated config
    assert {d.params["target_size"] for d in draws} == {0, 1}
