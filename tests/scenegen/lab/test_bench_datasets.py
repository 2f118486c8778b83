"""The dataset bench row: its steady-state rate and a scaled-down run."""

import pytest

from scenegen.lab.bench import datasets as bench


def test_steady_rate_sums_workers_after_their_first_shard():
    res = [(0.0, {"pid": 1, "entries": [0, 1]}), (1.0, {"pid": 2, "entries": [0, 1]}),
           (2.0, {"pid": 1, "entries": [0, 1]}), (3.0, {"pid": 2, "entries": [0]}),
           (5.0, {"pid": 2, "entries": [0, 1]})]  # fmt: skip
    # worker 1: 2 sequences in 2 s; worker 2: 3 sequences in 4 s
    assert bench._steady(res) == pytest.approx(1.0 + 0.75)


@pytest.mark.slow
def test_scaled_down_rows(monkeypatch):
    monkeypatch.setattr(bench, "COUNT", 8)
    monkeypatch.setattr(bench, "FRAMES", 2)
    rows = bench.run(1)
    assert [r.unit for r in rows] == ["seq/min"] * 6 + ["seq/min per core"] * 3 + ["MiB"]
    assert all(r.rate > 0 for r in rows)
    assert sum(r.goal != "" for r in rows) == 2
