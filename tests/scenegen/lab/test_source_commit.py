"""``results.json``'s ``written_by`` names the git commit of a checkout
(``scenegen.lab.experiments.outputs.source_commit``): a version number cannot tell two
commits apart, and asking git must never hang or fail a run."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from scenegen.lab.experiments.outputs import source_commit, written_by

ROOT = Path(__file__).resolve().parents[3]
GIT = shutil.which("git")
needs_git = pytest.mark.skipif(GIT is None, reason="git is not installed")


def _git(repo: Path, *args: str) -> str:
    out = subprocess.run(["git", "-C", str(repo), "-c", "user.name=t", "-c", "user.email=t@t",
                          *args], capture_output=True, text=True, check=True, timeout=60)
    return out.stdout.strip()


@pytest.fixture
def checkout(tmp_path: Path) -> Path:
    """A one-commit repository laid out like a scenegen checkout."""
    repo = tmp_path / "src"
    repo.mkdir()
    _git(repo, "init", "-q")
    (repo / "pyproject.toml").write_text("[project]\nname = 'scenegen'\n")
    (repo / "tracked.py").write_text("x = 1\n")
    _git(repo, "add", "pyproject.toml", "tracked.py")
    _git(repo, "commit", "-q", "-m", "one")
    return repo


@needs_git
def test_a_clean_checkout_gives_its_commit_and_edits_mark_it_dirty(checkout):
    head = _git(checkout, "rev-parse", "HEAD")[:12]
    assert source_commit(checkout) == head
    (checkout / "notes.txt").write_text("untracked files do not count\n")
    assert source_commit(checkout) == head
    (checkout / "tracked.py").write_text("x = 2\n")
    assert source_commit(checkout) == head + "+dirty"


@needs_git
def test_no_checkout_or_no_commit_gives_none(tmp_path, checkout):
    assert source_commit(tmp_path) is None  # no pyproject.toml, no .git
    shutil.rmtree(checkout / ".git")
    assert source_commit(checkout) is None
    _git(checkout, "init", "-q")  # a repository without a commit yet
    assert source_commit(checkout) is None


def test_a_hanging_or_missing_git_gives_none(tmp_path, checkout, monkeypatch):
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    hang = bin_dir / "git"
    hang.write_text("#!/bin/sh\nsleep 60\n")
    hang.chmod(0o755)
    monkeypatch.setenv("PATH", str(bin_dir))
    assert source_commit(checkout, timeout=0.5) is None  # time-boxed, not a hang
    hang.unlink()
    assert source_commit(checkout) is None  # no git at all
    monkeypatch.setenv("PATH", os.defpath)


def test_written_by_names_this_checkout_commit_after_the_version():
    who = written_by()
    if (ROOT / ".git").exists() and GIT is not None:
        assert re.fullmatch(r"[0-9a-f]{12}(\+dirty)?", who["scenegen commit"])
        assert who["scenegen commit"][:12] == _git(ROOT, "rev-parse", "HEAD")[:12]
        assert list(who)[:2] == ["scenegen", "scenegen commit"]
    else:  # an installed wheel or an exported tree: no commit to name
        assert "scenegen commit" not in who


def test_the_version_has_one_definition():
    import importlib.metadata
    import tomllib

    import scenegen

    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert "version" not in project and "version" in project["dynamic"]
    assert importlib.metadata.version("scenegen") == scenegen.__version__
