"""Old import path, kept for users: the same module as :mod:`scenegen.testing.strategies`."""

import sys

import scenegen.testing.strategies as _module

sys.modules[__name__] = _module
