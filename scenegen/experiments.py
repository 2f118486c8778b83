"""Old import path, kept for users: the same package as :mod:`scenegen.lab.experiments`."""

import sys

import scenegen.lab.experiments as _module
from scenegen.lab.experiments import definitions, figures, runner, summary

for _sub in (definitions, figures, runner, summary):
    sys.modules[f"{__name__}.{_sub.__name__.rsplit('.', 1)[1]}"] = _sub
sys.modules[__name__] = _module
