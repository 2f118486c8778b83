"""Old import path, kept for users: the same module as :mod:`scenegen.testing.pytest_plugin`."""

import sys

import scenegen.testing.pytest_plugin as _module

sys.modules[__name__] = _module
