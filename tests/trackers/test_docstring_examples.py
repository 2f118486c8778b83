"""The Examples in the trackers' docstrings run and give what they show."""

import doctest
import importlib
import pkgutil

import pytest

import trackers

# trackers.adapters wraps optional third-party trackers; its examples need them.
MODULES = sorted(m.name for m in pkgutil.walk_packages(trackers.__path__, "trackers.")
                 if not m.name.startswith("trackers.adapters"))


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0
