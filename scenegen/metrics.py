"""Old import path, kept for users: the same module as :mod:`scenegen.evaluation.metrics`."""

import sys

import scenegen.evaluation.metrics as _module

sys.modules[__name__] = _module
