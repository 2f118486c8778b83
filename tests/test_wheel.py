"""From a plain install of the wheel, in another project: the README's user test file runs.

Slow: builds the wheel, installs it (``--no-deps``) into a fresh venv that reuses this
venv's installed dependencies through a ``.pth`` line (no downloads), then runs the
README's example test file in an empty folder, first with ``--scenegen-regen`` (storing
the stochastic tracker's distribution), then twice more as a user's CI would.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def readme_user_test() -> str:
    """The Python block after ``<!-- user-test-file -->`` in the README."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    found = re.search(r"<!-- user-test-file -->\s*```python\n(.*?)```", text, re.S)
    assert found is not None, "README lacks the <!-- user-test-file --> block"
    return found.group(1)


def _run(cmd: list[str], cwd: Path, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    out = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=1200)
    assert out.returncode == 0, (
        f"{' '.join(cmd)} failed:\n{out.stdout[-3000:]}\n{out.stderr[-3000:]}"
    )
    return out


def test_readme_user_test_file_compiles():
    compile(readme_user_test(), "test_user.py", "exec")


@pytest.mark.slow
def test_wheel_in_a_fresh_venv_runs_the_readme_user_test(tmp_path):
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTEST_ADDOPTS")}
    wheels = tmp_path / "wheels"
    _run(
        [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(wheels), str(ROOT)],
        tmp_path,
        env,
    )
    (wheel,) = wheels.glob("scenegen-*.whl")
    venv = tmp_path / "venv"
    _run([sys.executable, "-m", "venv", "--without-pip", str(venv)], tmp_path, env)
    py = venv / "bin" / "python"
    code = "import sysconfig; print(sysconfig.get_paths()['purelib'])"
    purelib = Path(_run([str(py), "-c", code], tmp_path, env).stdout.strip())
    # This venv's packages (numpy, h5py, cv2, pytest, ...) after the fresh venv's own: the
    # wheel's scenegen comes first, and this venv's editable scenegen is never imported
    # (its finder is installed by a .pth file there, which a plain path entry does not run).
    (purelib / "_deps_from_project_venv.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    _run(
        [
            sys.executable,
            "-m",
            "pip",
            "--python",
            str(py),
            "install",
            "-q",
            "--no-deps",
            str(wheel),
        ],
        tmp_path,
        env,
    )
    project = tmp_path / "user-project"
    project.mkdir()
    (project / "test_user.py").write_text(readme_user_test())
    code = "import scenegen, trackers; print(scenegen.__file__, trackers.__file__)"
    where = _run([str(py), "-c", code], project, env).stdout
    assert str(ROOT) not in where and str(venv) in where, where
    env["SCENEGEN_CACHE"] = str(tmp_path / "cache")
    first = _run([str(py), "-m", "pytest", "-q", "--scenegen-regen"], project, env)
    assert "wrote:" in first.stdout and (project / "fixtures" / "expected").is_dir()
    # check_tracker regenerated the built-in edge fixtures into the cache
    assert (tmp_path / "cache" / "fixtures" / "one-pixel.h5").exists()
    for _ in range(2):
        again = _run([str(py), "-m", "pytest", "-q"], project, env)
        assert " passed" in again.stdout and "failed" not in again.stdout
