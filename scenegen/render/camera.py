"""Camera motion: the per-frame pan offset of a :class:`~scenegen.config.Camera`.

The frame at time t shows the scene shifted by the offset (dx_t, dy_t): a scene point
(x, y) appears at (x - dx_t, y - dy_t). Offsets are whole pixels, so cropping the static
layer (drawn once on a background larger than the frame) is exact and every label pixel
stays the pixel of one silhouette.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from scenegen.config import Camera
from scenegen.render.motion import ar2_path

__all__ = ["ZOOM_LIMITS", "camera_offsets", "camera_zoom", "keyframe_values"]

ZOOM_LIMITS = (0.5, 2.0)
"""Smallest and largest zoom factor."""


def keyframe_values(
    keys: tuple[tuple[int, float, float], ...], n: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The two values of (frame, a, b) keyframes at frames 0..n-1 (each shape (n,)):
    linear in between, held before the first and after the last keyframe.

    Parameters
    ----------
    keys : tuple of (int, float, float)
        At least one keyframe ``(frame, a, b)``, frames increasing.
    n : int
        Number of frames.

    Returns
    -------
    a, b : ndarray of float64, shape (n,)
        The two values at each frame.
    """
    t = np.arange(n, dtype=np.float64)
    f = np.array([k[0] for k in keys], dtype=np.float64)
    a = np.interp(t, f, [k[1] for k in keys])
    b = np.interp(t, f, [k[2] for k in keys])
    return a, b


def camera_offsets(
    cam: Camera | None, n: int, rng: np.random.Generator
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Camera offsets (dx, dy), each shape (n,) int64, within ``[-extent, extent]``.

    ``rng`` is the camera's own stream (AR2 noise); ``None`` gives zeros.

    Parameters
    ----------
    cam : Camera or None
        The camera: scripted ``keyframes``, else an AR2 path per axis from 0 with its
        initial velocity (an axis without one stays at 0).
    n : int
        Number of frames.
    rng : numpy.random.Generator
        The camera's own stream (unused with keyframes).

    Returns
    -------
    dx, dy : ndarray of int64, shape (n,)
        The offsets (px), rounded to whole pixels and clipped to the extent.

    Raises
    ------
    ConfigError
        An AR2 path beyond :data:`~scenegen.config.MAX_PATH`, naming ``camera.x`` or
        ``camera.y`` and the frame.
    """
    if cam is None:
        return np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64)
    ex, ey = cam.extent
    if cam.keyframes:
        dx, dy = keyframe_values(cam.keyframes, n)
    else:
        dx, dy = np.zeros(n), np.zeros(n)
        if cam.x is not None:
            dx = ar2_path(cam.x, 0.0, cam.velocity[0], n, rng=rng, lo=-ex, hi=ex, field="camera.x")
        if cam.y is not None:
            dy = ar2_path(cam.y, 0.0, cam.velocity[1], n, rng=rng, lo=-ey, hi=ey, field="camera.y")
    ox = np.clip(np.rint(dx), -ex, ex).astype(np.int64)
    oy = np.clip(np.rint(dy), -ey, ey).astype(np.int64)
    return ox, oy


def camera_zoom(cam: Camera | None, n: int, rng: np.random.Generator) -> NDArray[np.float64]:
    """Zoom factor per frame (n,), within :data:`ZOOM_LIMITS` (ones without a zoom).

    ``rng`` is the zoom's own stream.

    Parameters
    ----------
    cam : Camera or None
        The camera; its ``zoom`` AR2 drives the log zoom from 0, within
        ``[-margin, margin]`` when ``margin > 0`` (and always within the limits).
    n : int
        Number of frames.
    rng : numpy.random.Generator
        The zoom's own stream.

    Returns
    -------
    ndarray of float64, shape (n,)
        The zoom factor per frame.

    Raises
    ------
    ConfigError
        An AR2 path beyond :data:`~scenegen.config.MAX_PATH`, naming ``camera.zoom``.
    """
    if cam is None or cam.zoom is None:
        return np.ones(n)
    lo, hi = np.log(ZOOM_LIMITS[0]), np.log(ZOOM_LIMITS[1])
    if cam.zoom.margin > 0:
        lo, hi = max(lo, -cam.zoom.margin), min(hi, cam.zoom.margin)
    log_zoom = ar2_path(cam.zoom, 0.0, 0.0, n, rng=rng, lo=lo, hi=hi, field="camera.zoom")
    return np.exp(np.clip(log_zoom, lo, hi))
