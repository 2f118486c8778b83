"""Test configuration: hypothesis profiles chosen by HYPOTHESIS_PROFILE (``dev`` default).

``ci`` is derandomised (same examples on every run) with more examples; ``dev`` is quick;
``mutate`` (set by ``tools/mutation/mutate.py`` for some modules) is ``dev`` without
shrinking: a mutant needs only one failing example, not the smallest.
"""

import os

from hypothesis import HealthCheck, Phase, settings

settings.register_profile(
    "ci",
    derandomize=True,
    deadline=None,
    max_examples=30,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
settings.register_profile(
    "dev",
    derandomize=True,
    deadline=None,
    max_examples=15,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
settings.register_profile(
    "mutate",
    parent=settings.get_profile("dev"),
    phases=(Phase.explicit, Phase.reuse, Phase.generate),
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "dev"))
