"""Test configuration: hypothesis profiles chosen by HYPOTHESIS_PROFILE (``dev`` default),
and the ``deadline`` fixture.

``ci`` is derandomised (same examples on every run) with more examples; ``dev`` is quick;
``mutate`` (set by ``tools/mutation/mutate.py`` for some modules) is ``dev`` without
shrinking: a mutant needs only one failing example, not the smallest.
"""

import os

import pytest
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


@pytest.fixture
def deadline():
    """``with deadline(s): ...`` fails the test if the block has not returned within ``s``
    seconds (SIGALRM interrupts a read waiting on a FIFO); for checks that must never wait
    on a damaged input."""
    import contextlib
    import signal

    class Hung(BaseException):  # not an OSError: no `except OSError` may swallow it
        pass

    @contextlib.contextmanager
    def within(seconds: int):
        def expired(signum, frame):
            raise Hung(f"did not return within {seconds} s")

        old = signal.signal(signal.SIGALRM, expired)
        signal.alarm(seconds)
        try:
            yield
        finally:
            signal.alarm(0)
            signal.signal(signal.SIGALRM, old)

    return within
