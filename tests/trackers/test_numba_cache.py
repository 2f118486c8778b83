"""Numba's cache follows the kernels' sources as a whole (trackers.kernels.numba_cache)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from trackers.kernels.numba_cache import STAMP_NAME, drop_stale, sources_digest

ROOT = Path(__file__).resolve().parents[2]


def test_drop_stale_removes_the_cache_files_only_when_a_source_changed(tmp_path):
    (tmp_path / "a.py").write_text("x = 1\n")
    cache = tmp_path / "__pycache__"
    cache.mkdir()
    old = [cache / "a.f-1.py311.nbi", cache / "a.f-1.py311.1.nbc"]
    for path in old:
        path.write_bytes(b"compiled")
    pyc = cache / "a.cpython-311.pyc"
    pyc.write_bytes(b"bytecode")
    assert drop_stale(tmp_path)  # no stamp yet: the cache cannot be trusted
    assert not any(p.exists() for p in old) and pyc.exists()
    assert (cache / STAMP_NAME).read_text() == sources_digest(tmp_path)
    for path in old:
        path.write_bytes(b"compiled")
    assert not drop_stale(tmp_path)  # nothing changed: the cache is kept
    assert all(p.exists() for p in old)
    (tmp_path / "b.py").write_text("y = 2\n")  # a new module counts too
    assert drop_stale(tmp_path) and not any(p.exists() for p in old)
    (tmp_path / "b.py").write_text("y = 3\n")  # same size, another content
    assert drop_stale(tmp_path)
    assert not drop_stale(tmp_path)
    assert not list(cache.glob("*.tmp"))


def test_a_folder_that_cannot_be_written_is_left_alone(tmp_path):
    (tmp_path / "a.py").write_text("x = 1\n")
    (tmp_path / "__pycache__").write_text("a file where the folder would be")
    assert drop_stale(tmp_path) is False


def _run(package: Path, code: str) -> str:
    env = {**os.environ, "PYTHONPATH": f"{package.parent}{os.pathsep}{ROOT}"}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                         text=True, timeout=300, check=True)
    return out.stdout.strip()


def test_a_kernel_calling_another_modules_kernel_recompiles_when_that_module_changes(tmp_path):
    # Numba keys a cache entry on its own file: b.g, compiled with a.f inside it, keeps
    # the old a.f after a.f's file changes (checked by hand: it prints 1 then 1 without the
    # package's drop_stale call). With it, the second run sees the new a.f.
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "__init__.py").write_text(
        "from pathlib import Path\n"
        "from trackers.kernels.numba_cache import drop_stale\n"
        "drop_stale(Path(__file__).parent)\n"
    )
    (package / "a.py").write_text(
        "from numba import njit\n\n\n@njit(cache=True)\ndef f():\n    return 1\n"
    )
    (package / "b.py").write_text(
        "from numba import njit\n\nfrom pkg.a import f\n\n\n"
        "@njit(cache=True)\ndef g():\n    return f()\n"
    )
    assert _run(package, "from pkg.b import g; print(g())") == "1"
    assert list((package / "__pycache__").glob("b.g-*.nbi"))  # it was cached
    (package / "a.py").write_text(
        "from numba import njit\n\n\n@njit(cache=True)\ndef f():\n    return 2\n"
    )
    assert _run(package, "from pkg.b import g; print(g())") == "2"


def test_the_kernels_package_keeps_its_stamp():
    import trackers.kernels

    folder = Path(trackers.kernels.__file__).parent
    stamp = folder / "__pycache__" / STAMP_NAME
    if os.access(folder / "__pycache__", os.W_OK):
        assert stamp.read_text() == sources_digest(folder)
