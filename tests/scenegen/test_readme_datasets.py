"""The README's "Benchmark datasets" examples run as written (on a small dataset)."""

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
