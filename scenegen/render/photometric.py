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

_LOG_GAIN_MAX = 700.0
"""Bound of an unbounded log gain: its exp stays finite (e^710 overflows to inf, and
0 x inf is NaN: a black pixel would have no defined value)."""


def illumination(
    p: Photometric | None, n: int, rng: np.random.Generator
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per-frame gain and offset (each shape (n,)); ones and zeros without a change.

    ``rng`` is the illumination's own stream (AR2 noise of the log gain, then the offset).

    Parameters
    ----------
    p : Photometric or None
        The photometric config: scripted ``keyframes`` (frame, gain, offset), else AR2
        paths from 0 of the log gain and of the offset (within ``[-margin, margin]`` when
        ``margin > 0``); None: no change.
    n : int
        Number of frames.
    rng : numpy.random.Generator
        The illumination's own stream (unused with keyframes).

    Returns
    -------
    gain, offset : ndarray of float64, shape (n,)
        Gain factor and offset (grey levels) per frame.

    Raises
    ------
    ConfigError
        An AR2 path beyond :data:`~scenegen.config.MAX_PATH`, naming
        ``photometric.gain`` or ``photometric.offset`` and the frame.
    """
    gain, offset = np.ones(n), np.zeros(n)
    if p is None:
        return gain, offset
    if p.keyframes:
        return keyframe_values(p.keyframes, n)
    if p.gain is not None:
        lim = p.gain.margin if p.gain.margin > 0 else np.inf
        log_gain = ar2_path(p.gain, 0.0, 0.0, n, rng=rng, lo=-lim, hi=lim, field="photometric.gain")
        gain = np.exp(np.clip(log_gain, -_LOG_GAIN_MAX, _LOG_GAIN_MAX))
    if p.offset is not None:
        lim = p.offset.margin if p.offset.margin > 0 else np.inf
        offset = ar2_path(
            p.offset, 0.0, 0.0, n, rng=rng, lo=-lim, hi=lim, field="photometric.offset"
        )
    return gain, offset


def illuminate(rgb: NDArray[np.uint8], gain: float, offset: float) -> NDArray[np.uint8]:
    """``clip(rint(gain * rgb + offset))`` of one frame (H, W, 3), through a lookup table.

    Parameters
    ----------
    rgb : ndarray of uint8, shape (H, W, 3)
        The frame.
    gain : float
        Factor on every channel.
    offset : float
        Added after the gain (grey levels).

    Returns
    -------
    ndarray of uint8, shape (H, W, 3)
        The lit frame, clipped to 0..255; ``rgb`` itself when ``gain == 1`` and
        ``offset == 0``.
    """
    if gain == 1.0 and offset == 0.0:
        return rgb
    lut = np.clip(np.rint(np.arange(256) * gain + offset), 0, 255).astype(np.uint8)
    return lut[rgb]


@lru_cache(maxsize=4096)
def line_kernel(dx: float, dy: float, reach: tuple[int, int] | None = None) -> NDArray[np.float32]:
    """Normalised box kernel along the segment from -(dx, dy)/2 to (dx, dy)/2, shape
    (2r+1, 2r+1) with r = ceil(max(|dx|, |dy|) / 2) (cached: read-only).

    ``reach`` = (qx, qy) keeps only the central (2 qy + 1, 2 qx + 1) window (where
    q < r): the weights are still those of the whole segment, and only the samples that
    fall in the window are drawn, so a smear far longer than the frame costs no more
    than the window.
    """
    r = int(np.ceil(max(abs(dx), abs(dy)) / 2))
    qx, qy = (r, r) if reach is None else (min(r, reach[0]), min(r, reach[1]))
    n = max(2, int(np.ceil(np.hypot(dx, dy))) * 2 + 1)
    if (qx, qy) == (r, r):
        s = np.linspace(-0.5, 0.5, n)
    else:  # the samples at |s| <= smax can land in the window (n may be huge)
        smax = min((q + 0.5) / abs(d) for q, d in ((qx, dx), (qy, dy)) if d != 0)
        lo = max(int(np.floor((0.5 - smax) * (n - 1))) - 1, 0)
        hi = min(int(np.ceil((0.5 + smax) * (n - 1))) + 1, n - 1)
        s = np.arange(lo, hi + 1) * (1.0 / (n - 1)) - 0.5  # as np.linspace computes
        if hi == n - 1:
            s[-1] = 0.5
    xs = np.rint(r + s * dx).astype(np.int64) - (r - qx)
    ys = np.rint(r + s * dy).astype(np.int64) - (r - qy)
    keep = (xs >= 0) & (xs <= 2 * qx) & (ys >= 0) & (ys <= 2 * qy)
    k = np.zeros((2 * qy + 1, 2 * qx + 1), dtype=np.float32)
    np.add.at(k, (ys[keep], xs[keep]), 1.0)
    k /= np.float32(n)
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
    rgb : ndarray of uint8, shape (H, W, 3)
        The frame, changed in place.
    lab : ndarray of uint16, shape (H, W)
        The frame's label image.
    label : int
        The entity's label in ``lab``.
    box : (c_min, r_min, c_max, r_max)
        Inclusive visible box of the entity.
    velocity : (vx, vy)
        Image velocity, pixels per frame.
    exposure : float
        The smear is ``exposure * velocity``, rounded to a quarter pixel; a smear
        shorter than 1 px on both axes leaves the frame unchanged.
    """
    dx = round(velocity[0] * exposure * 4) / 4
    dy = round(velocity[1] * exposure * 4) / 4
    if max(abs(dx), abs(dy)) < 1.0:
        return
    r = int(np.ceil(max(abs(dx), abs(dy)) / 2))
    h, w = lab.shape
    c0, r0 = max(box[0] - r, 0), max(box[1] - r, 0)
    c1, r1 = min(box[2] + r + 1, w), min(box[3] + r + 1, h)
    # Offsets beyond the region's size carry nothing within it: crop the kernel there.
    kern = line_kernel(dx, dy, (min(r, c1 - c0 - 1), min(r, r1 - r0 - 1)))
    region = rgb[r0:r1, c0:c1]
    m = (lab[r0:r1, c0:c1] == label).astype(np.float32)
    src = region.astype(np.float32)
    a = cv2.filter2D(m, -1, kern, borderType=cv2.BORDER_CONSTANT)
    c = cv2.filter2D(src * m[..., None], -1, kern, borderType=cv2.BORDER_CONSTANT)
    out = src * (1.0 - a[..., None]) + c
    region[:] = np.clip(np.rint(out), 0, 255).astype(np.uint8)


def jpeg(rgb: NDArray[np.uint8], quality: int) -> NDArray[np.uint8]:
    """One frame (H, W, 3) through JPEG encoding and decoding at ``quality`` (1..100).

    Parameters
    ----------
    rgb : ndarray of uint8, shape (H, W, 3)
        The frame.
    quality : int
        JPEG quality, 1..100 (higher: fewer artefacts).

    Returns
    -------
    ndarray of uint8, shape (H, W, 3)
        The decoded frame.
    """
    bgr = cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR)
    ok, buf = cv2.imencode(".jpg", bgr, [cv2.IMWRITE_JPEG_QUALITY, int(quality)])
    if not ok:  # pragma: no cover - OpenCV encodes any uint8 image
        raise RuntimeError("JPEG encoding failed")
    return cv2.cvtColor(cv2.imdecode(buf, cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB)
