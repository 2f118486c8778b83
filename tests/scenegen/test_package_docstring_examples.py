"""The Examples in scenegen's docstrings run and give what they show."""

import doctest
import importlib
import pkgutil

import pytest

import scenegen


def _modules() -> list[str]:
    """Every module of the package, but the old import paths (scenegen.experiments,
    scenegen.metrics, ...), which put another module in their place: its examples run
    under its own name."""
    names = []
    for info in pkgutil.walk_packages(scenegen.__path__, "scenegen."):
        if importlib.import_module(info.name).__name__ == info.name:
            names.append(info.name)
    return sorted(names)


MODULES = _modules()


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # an example that writes a file writes it here
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0
