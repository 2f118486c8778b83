"""Shared fixtures of the lab tests: the command-line tools under ``tools/`` as modules."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

import pytest

TOOLS = Path(__file__).resolve().parents[3] / "tools"


def load_tool(relpath: str) -> ModuleType:
    """Import ``tools/<relpath>`` (not a package) as a module."""
    path = TOOLS / relpath
    spec = importlib.util.spec_from_file_location(path.stem, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def tool(request) -> ModuleType:
    """The tool named by the test module's ``TOOL`` (a path under ``tools/``)."""
    return load_tool(str(request.module.TOOL.relative_to(TOOLS)))
