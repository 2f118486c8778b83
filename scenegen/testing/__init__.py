"""Test tooling for tracker authors: hypothesis strategies, the pytest plugin, fixtures.

Nothing here imports :mod:`trackers`: the tooling works for any tracker.
"""

__all__: list[str] = []
