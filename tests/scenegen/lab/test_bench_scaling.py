"""The scaling bench: its scene, its exponent fit and its figure (no timings asserted)."""

from __future__ import annotations

import numba
import numpy as np

from scenegen.lab.bench.core import BenchRow
from scenegen.lab.bench.particle import threads
from scenegen.lab.bench.scaling import _scene, exponents, write_figure


def test_scene_has_k_distinct_objects_inside_the_frame():
    frames, boxes = _scene(5, (160, 120))
    assert frames.shape == (4, 120, 160, 3) and boxes.shape == (5, 4)
    assert np.all(boxes[:, 0] >= 0) and np.all(boxes[:, 0] + boxes[:, 2] + 4 <= 160)
    assert np.all(boxes[:, 1] >= 0) and np.all(boxes[:, 1] + boxes[:, 3] <= 120)


def _rows(b: float) -> list[BenchRow]:
    xs = np.array([50.0, 150.0, 500.0, 1500.0])
    return [BenchRow("g", f"box {x}", 1e-3 * x**b, 1.0, "frames/s",
                     params={"axis": "n", "kernel": "box", "x": float(x)}) for x in xs]


def test_exponent_fit_recovers_a_power_law():
    assert abs(exponents(_rows(0.8))[("n", "box")] - 0.8) < 1e-9
    assert ("n", "epanechnikov") not in exponents(_rows(0.8))


def test_figure_is_a_png(tmp_path):
    path = write_figure(_rows(1.0), tmp_path / "scaling.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_threads_context_restores_the_thread_count():
    before = numba.get_num_threads()
    with threads(1) as n:
        assert n == 1 and numba.get_num_threads() == 1
    assert numba.get_num_threads() == before
