"""Scaling of the ``dps`` step: cost against particles N, objects K and frame size.

Each axis is swept with the others fixed (N = 300, K = 4, 320 × 240), for the trackers'
default Epanechnikov kernel and the nested-rectangle ("box", L = 3) kernel, on one
thread. The scene is drawn directly (no generator): a blocky random background and K
solid rectangles of distinct colours, 1/12 × 1/8 of the frame each, moving one pixel per
frame. A least-squares line through log cost against log x gives each axis's exponent:
the direct path's cost grows with the pixels a box covers (exponent ≈ 1 in frame area),
the box kernel's with the particle cloud's extent only (its per-box cost is O(L · bins)).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from scenegen.lab.bench.core import BenchRow, median_time
from scenegen.lab.bench.particle import threads
from trackers.registry import make

__all__ = ["AXES", "exponents", "run", "write_figure"]

_BASE = {"n": 300, "k": 4, "size": (320, 240)}
#: Swept values per axis.
AXES: dict[str, tuple] = {
    "n": (50, 150, 500, 1500, 5000),
    "k": (1, 2, 4, 8, 16),
    "size": ((160, 120), (320, 240), (640, 480), (1280, 720)),
}
_KERNELS = ("epanechnikov", "box")
_FRAMES = 4


def _scene(k: int, size: tuple[int, int], seed: int = 0):
    """Frames (F, H, W, 3) and initial boxes (K, 4) of the synthetic scaling scene."""
    width, height = size
    rng = np.random.default_rng(seed)
    coarse = rng.integers(0, 256, size=(height // 8 + 1, width // 8 + 1, 3), dtype=np.uint8)
    background = np.kron(coarse, np.ones((8, 8, 1), dtype=np.uint8))[:height, :width]
    bw, bh = max(width // 12, 4), max(height // 8, 4)
    cols = max(1, int(np.ceil(np.sqrt(k * width / height))))
    boxes = np.empty((k, 4))
    colours = rng.integers(0, 256, size=(k, 3), dtype=np.uint8)
    for i in range(k):
        gx, gy = i % cols, i // cols
        boxes[i] = [(gx + 0.5) * width / cols - bw / 2,
                    (gy + 0.5) * height / int(np.ceil(k / cols)) - bh / 2, bw, bh]
    frames = np.empty((_FRAMES, height, width, 3), dtype=np.uint8)
    for f in range(_FRAMES):
        frame = background.copy()
        for i in range(k):
            x, y = int(boxes[i, 0]) + f, int(boxes[i, 1])
            frame[y:y + bh, x:x + bw] = colours[i]
        frames[f] = frame
    return frames, boxes


def _step_seconds(n: int, k: int, size: tuple[int, int], kernel: str, repeats: int) -> float:
    frames, boxes = _scene(k, size)

    def track() -> None:
        tracker = make("dps", n_particles=n * k, rng=0, kernel=kernel)
        tracker.init(frames[0], boxes)
        for frame in frames[1:]:
            tracker.step(frame)

    with threads(1):
        return median_time(track, repeats) / (_FRAMES - 1)


def _x(axis: str, value) -> float:
    return float(value[0] * value[1]) if axis == "size" else float(value)


def _points(rows: list[BenchRow], axis: str, kernel: str) -> list[tuple[float, float]]:
    """(x, seconds) of the rows measured along ``axis`` with ``kernel``, by x."""
    return sorted((float(r.params["x"]), r.seconds) for r in rows
                  if r.params.get("axis") == axis and r.params.get("kernel") == kernel)


def exponents(rows: list[BenchRow]) -> dict[tuple[str, str], float]:
    """Fitted exponent b of cost ∝ x^b per (axis, kernel), from this module's rows.

    Parameters
    ----------
    rows : list of BenchRow
        Rows of :func:`run`; those with ``params`` ``"axis"``, ``"kernel"`` and ``"x"``
        are used, the others ignored.

    Returns
    -------
    dict of (str, str) to float
        The least-squares slope of log seconds against log x, per (axis, kernel) with at
        least two points (x: particles per object, objects, or frame area in pixels).
    """
    out = {}
    for axis in AXES:
        for kernel in _KERNELS:
            pts = _points(rows, axis, kernel)
            if len(pts) >= 2:
                x, t = np.log(np.array(pts)).T
                out[(axis, kernel)] = float(np.polyfit(x, t, 1)[0])
    return out


def run(repeats: int = 5) -> list[BenchRow]:
    """One row per (axis, value, kernel), then one row per fitted exponent.

    Parameters
    ----------
    repeats : int, default 5
        Timings per figure, clipped to 1..3 (the sweep is long).

    Returns
    -------
    list of BenchRow
        Seconds per ``dps`` step (frames/s as the rate) for each value of :data:`AXES`
        and each kernel, ``params`` giving the axis, kernel and x; then the fitted
        exponents of :func:`exponents` (unit ``"exponent"``, seconds 0).
    """
    rows: list[BenchRow] = []
    repeats = max(1, min(repeats, 3))  # the sweep is long; medians of 3 suffice here
    for axis, values in AXES.items():
        fixed = ", ".join(f"{a}={_BASE[a] if a != 'size' else '320x240'}"
                          for a in AXES if a != axis)
        group = f"scaling of the dps step against {axis} ({fixed}, 1 thread)"
        for value in values:
            params = {**_BASE, axis: value}
            for kernel in _KERNELS:
                t = _step_seconds(params["n"], params["k"], params["size"], kernel, repeats)
                label = f"{value[0]}x{value[1]}" if axis == "size" else str(value)
                rows.append(BenchRow(group, f"{kernel}, {axis}={label}", t, 1.0 / t,
                                     "frames/s", params={"axis": axis, "kernel": kernel,
                                                         "x": _x(axis, value)}))
    fits = exponents(rows)
    for (axis, kernel), b in fits.items():
        what = "frame area" if axis == "size" else ("particles per object" if axis == "n"
                                                    else "objects")
        rows.append(BenchRow("scaling: fitted exponent b of cost ∝ x^b",
                             f"{kernel} against {what}", 0.0, b, "exponent"))
    return rows


def write_figure(rows: list[BenchRow], path: str | Path) -> Path:
    """A PNG with one log-log panel per axis (both kernels, fitted exponents in the legend).

    Parameters
    ----------
    rows : list of BenchRow
        Rows of :func:`run` (the sweep rows are plotted, in ms per step).
    path : str or pathlib.Path
        The PNG to write (atomically); missing parent folders are created.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from scenegen.io.atomic import atomic_path

    fits = exponents(rows)
    fig = Figure(figsize=(12, 3.8))
    FigureCanvasAgg(fig)
    titles = {"n": "particles per object N", "k": "objects K", "size": "frame area (pixels)"}
    for i, axis in enumerate(AXES):
        ax = fig.add_subplot(1, 3, i + 1)
        for kernel, marker in zip(_KERNELS, ("o", "s"), strict=True):
            pts = _points(rows, axis, kernel)
            if pts:
                x, t = np.array(pts).T
                b = fits.get((axis, kernel), float("nan"))
                ax.loglog(x, t * 1e3, marker=marker, label=f"{kernel} (b = {b:.2f})")
        ax.set_xlabel(titles[axis])
        ax.set_ylabel("ms per step")
        ax.grid(True, which="both", alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=8)
    fig.suptitle("dps step cost (1 thread)")
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path, ".png") as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    return path
