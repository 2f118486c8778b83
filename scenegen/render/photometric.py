"""Photometric effects on rendered frames: illumination, motion blur, JPEG compression.

Every effect changes pixels only, after the labels and the ground truth of the sharp
silhouettes are computed (docs/format.md): boxes, labels, visibility and depth stay
exact. All functions are deterministic (no randomness), so chunked rendering gives the
same bytes as rendering at once.
"""

from __future__ import annotations

from functools import lru_cache

import cv2
import numpy as np
from numpy.typing import NDArray

from scenegen.config import Photometric
from scenegen.render.camera import keyframe_values
from scenegen.render.motion import ar2_path

__all__ = ["illuminate", "illumination", "jpeg", "line_kernel", "motion_blur"]


def illumination(
    p: Photometric | None, n: int, rng: np.random.Generator
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per-frame gain and offset (each shape (n,)); ones and zeros without a change.

    ``rng`` is the illumination's own stream (AR2 noise of the log gain, then the offset).
    """
    gain, offset = np.ones(n), np.zeros(n)
    if p is None:
        return gain, offset
    if p.keyframes:
        return keyframe_values(p.keyframes, n)
    if p.gain is not None:
        lim = p.gain.margin if p.gain.margin > 0 else np.inf
        gain = np.exp(ar2_path(p.gain, 0.0, 0.0, n, rng=rng, lo=-lim, hi=lim))
    if p.offset is not None:
        lim = p.offset.margin if p.offset.margin > 0 else np.inf
        offset = ar2_path(p.offset, 0.0, 0.0, n, rng=rng, lo=-lim, hi=lim)
    return gain, offset


def illuminate(rgb: NDArray[np.uint8], gain: float, offset: float) -> NDArray[np.uint8]:
    """``clip(rint(gain * rgb + offset))`` of one frame (H, W, 3), through a lookup table."""
    if gain == 1.0 and offset == 0.0:
        return rgb
    lut = np.clip(np.rint(np.arange(256) * gain + offset), 0, 255).astype(np.uint8)
    return lut[rgb]


@lru_cache(maxsize=4096)
def line_kernel(dx: float, dy: float) -> NDArray[np.float32]:
    """Normalised box kernel along the segment from -(dx, dy)/2 to (dx, dy)/2, shape
    (2r+1, 2r+1) with r = ceil(max(|dx|, |dy|) / 2) (cached: read-only)."""
    r = int(np.ceil(max(abs(dx), abs(dy)) / 2))
    k = np.zeros((2 * r + 1, 2 * r + 1), dtype=np.float32)
    n = max(2, int(np.ceil(np.hypot(dx, dy))) * 2 + 1)
    s = np.linspace(-0.5, 0.5, n)
    xs = np.clip(np.rint(r + s * dx).astype(np.intp), 0, 2 * r)
    ys = np.clip(np.rint(r + s * dy).astype(np.intp), 0, 2 * r)
    np.add.at(k, (ys, xs), 1.0)
    k /= k.sum()
    k.setflags(write=False)
    return k


def motion_blur(
    rgb: NDArray[np.uint8],
    lab: NDArray[np.uint16],
    label: int,
    box: tuple[int, int, int, int],
    velocity: tuple[float, float],
    exposure: float,
) -> None:
    """Smear the visible pixels of entity ``label`` along ``velocity`` in place.

    With ``m`` the entity's visible mask and ``K`` the line kernel of length
    ``exposure * |velocity|``, the frame becomes ``rgb (1 - K*m) + K*(rgb m)``: the
    entity's colours spread over its neighbourhood, everything else is unchanged.

    Parameters
    ----------
    rgb : (H, W, 3) uint8
    lab : (H, W) uint16
    box : (c_min, r_min, c_max, r_max)
        Inclusive visible box of the entity.
    velocity : (vx, vy)
        Image velocity, pixels per frame.
    exposure : float
        The smear is ``exposure * velocity``, rounded to a quarter pixel.
    """
    dx = round(velocity[0] * exposure * 4) / 4
    dy = round(velocity[1] * exposure * 4) / 4
    if max(abs(dx), abs(dy)) < 1.0:
        return
    kern = line_kernel(dx, dy)
    r = kern.shape[0] // 2
    h, w = lab.shape
    c0, r0 = max(box[0] - r, 0), max(box[1] - r, 0)
    c1, r1 = min(box[2] + r + 1, w), min(box[3] + r + 1, h)
    region = rgb[r0:r1, c0:c1]
    m = (lab[r0:r1, c0:c1] == label).astype(np.float32)
    src = region.astype(np.float32)
    a = cv2.filter2D(m, -1, kern, borderType=cv2.BORDER_CONSTANT)
    c = cv2.filter2D(src * m[..., None], -1, kern, borderType=cv2.BORDER_CONSTANT)
    out = src * (1.0 - a[..., None]) + c
    region[:] = np.clip(np.rint(out), 0, 255).astype(np.uint8)


def jpeg(rgb: NDArray[np.uint8], quality: int) -> NDArray[np.uint8]:
    """One frame (H, W, 3) through JPEG encoding and decoding at ``quality`` (1..100)."""
    bgr = cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR)
    ok, buf = cv2.imencode(".jpg", bgr, [cv2.IMWRITE_JPEG_QUALITY, int(quality)])
    if not ok:  # pragma: no cover - OpenCV encodes any uint8 image
        raise RuntimeError("JPEG encoding failed")
    return cv2.cvtColor(cv2.imdecode(buf, cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB)
