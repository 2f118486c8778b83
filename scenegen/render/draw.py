"""Entity appearance: RGBA templates drawn from an :class:`~scenegen.config.Appearance`.

Drawing returns a template (the entity alone, alpha 255 on its pixels); placing and
compositing are separate steps (:mod:`scenegen.render`).
"""

from __future__ import annotations

from dataclasses import replace
from functools import lru_cache

import cv2
import numpy as np
from numpy.typing import NDArray

from scenegen.config import Appearance
from scenegen.errors import ConfigError
from scenegen.render import textures

__all__ = ["draw_template", "jitter_colors", "shape_mask", "transform_template"]


@lru_cache(maxsize=512)
def shape_mask(shape: str, w: int, h: int) -> NDArray[np.bool_]:
    """Boolean silhouette (h, w) of ``shape``, tested at pixel centres; never empty."""
    yy, xx = np.mgrid[0:h, 0:w]
    u = (xx + 0.5) / w * 2 - 1  # in [-1, 1]
    v = (yy + 0.5) / h * 2 - 1
    if shape == "rect":
        m = np.ones((h, w), dtype=bool)
    elif shape == "ellipse":
        m = u * u + v * v <= 1.0
    elif shape == "diamond":
        m = np.abs(u) + np.abs(v) <= 1.0
    elif shape == "triangle":  # apex up
        m = np.abs(u) <= (v + 1) / 2
    else:
        raise ValueError(f"unknown shape {shape!r}")
    if not m.any():  # tiny sizes: keep the centre pixel
        m[h // 2, w // 2] = True
    m.setflags(write=False)
    return m


@lru_cache(maxsize=512)
def _pattern_index(pattern: str, w: int, h: int, n: int, stripe: int) -> NDArray[np.intp]:
    """Colour index (h, w) per pixel for the deterministic patterns."""
    yy, xx = np.mgrid[0:h, 0:w]
    cx, cy = w / 2, h / 2
    px, py = xx + 0.5 - cx, yy + 0.5 - cy
    if pattern in ("solid", "texture"):
        idx = np.zeros((h, w), dtype=np.intp)
    elif pattern == "rings":
        r = np.sqrt((px / max(cx, 0.5)) ** 2 + (py / max(cy, 0.5)) ** 2)
        idx = np.minimum((r * n).astype(np.intp), n - 1)
    elif pattern == "sectors":
        ang = (np.arctan2(py, px) + np.pi) / (2 * np.pi)
        idx = np.minimum((ang * n).astype(np.intp), n - 1)
    elif pattern == "stripes":
        idx = ((xx + yy) // stripe) % n
    elif pattern == "bands":
        idx = np.minimum(yy * n // h, n - 1)
    elif pattern == "checker":
        idx = ((xx // stripe) + (yy // stripe)) % n
    else:
        raise ValueError(f"unknown pattern {pattern!r}")
    idx = idx.astype(np.intp)
    idx.setflags(write=False)
    return idx


def draw_template(
    app: Appearance,
    *,
    rng: np.random.Generator | None = None,
    size: tuple[int, int] | None = None,
    field: str = "appearance",
) -> NDArray[np.uint8]:
    """Draw the entity alone as an RGBA template.

    Parameters
    ----------
    app : Appearance
    rng : numpy.random.Generator, optional
        Needed only by the ``texture`` pattern.
    size : (w, h), optional
        Overrides ``app.size`` (clutter items of varying size).
    field : str
        Config path of ``app``, named by errors about its image source.

    Returns
    -------
    ndarray of shape (h, w, 4), uint8
        RGB colours and alpha 255 inside the silhouette, 0 outside, cropped to the
        silhouette's box.
    """
    w, h = size if size is not None else app.size
    colors = np.asarray(app.colors, dtype=np.uint8)
    if app.pattern in ("image", "perlin"):
        if rng is None:
            raise ValueError(f"the {app.pattern} pattern needs an rng")
        return _masked(app.shape, w, h, _textured_rgb(app, w, h, rng, field))
    return paint_template(
        app.shape, app.pattern, w, h, colors,
        stripe_width=app.stripe_width, texture_sigma=app.texture_sigma, rng=rng,
    )  # fmt: skip


def paint_template(
    shape: str,
    pattern: str,
    w: int,
    h: int,
    colors: NDArray[np.uint8],
    *,
    stripe_width: int = 4,
    texture_sigma: float = 20.0,
    rng: np.random.Generator | None = None,
) -> NDArray[np.uint8]:
    """:func:`draw_template` without an :class:`Appearance` (validated inputs, fast path
    for hundreds of clutter items): ``colors`` is (n, 3) uint8."""
    if pattern != "texture":
        # One gather through a cached index map (n = transparent) does the whole template.
        lut = np.zeros((len(colors) + 1, 4), dtype=np.uint8)
        lut[:-1, :3] = colors
        lut[:-1, 3] = 255
        return lut[_masked_index(shape, pattern, w, h, len(colors), stripe_width)]
    if rng is None:
        raise ValueError("the texture pattern needs an rng")
    mask, crop = _mask_and_crop(shape, w, h)
    # Smooth noise keyed to the entity's stream; colour cycles over the palette.
    noise = rng.standard_normal((h, w, 3)) * texture_sigma
    idx = _pattern_index(pattern, w, h, len(colors), stripe_width)
    if len(colors) > 1:
        tint = rng.integers(0, len(colors), size=(max(h // 4, 1), max(w // 4, 1)))
        tint = cv2.resize(tint.astype(np.float32), (w, h), interpolation=cv2.INTER_NEAREST)
        idx = tint.astype(np.intp)
    rgb = np.clip(np.rint(colors[idx] + noise), 0, 255).astype(np.uint8)
    out = np.zeros((h, w, 4), dtype=np.uint8)
    out[mask, :3] = rgb[mask]
    out[mask, 3] = 255
    return out if crop is None else np.ascontiguousarray(out[crop])


def _textured_rgb(
    app: Appearance, w: int, h: int, rng: np.random.Generator, field: str
) -> NDArray[np.uint8]:
    """The (h, w, 3) pixels of an ``image`` or ``perlin`` appearance before masking."""
    if app.pattern == "perlin":
        v = textures.value_noise(w, h, app.noise_scale, rng)
        return textures.palette_map(v, np.asarray(app.colors, dtype=np.uint8))
    assert app.source is not None  # validated by Appearance
    img = textures.load_source(app.source, f"{field}.source")
    if app.crop is not None:
        x, y, cw, ch = app.crop
        ih, iw = img.shape[:2]
        if x + cw > iw or y + ch > ih:
            raise ConfigError(
                f"{field}.crop: {list(app.crop)} exceeds the {iw}x{ih} image {app.source!r}"
            )
        img = img[y : y + ch, x : x + cw]
    if app.fit == "tile":
        rgb = textures.random_window(img, w, h, rng)
    else:
        rgb = textures.fit_image(img, w, h, app.fit)
    return textures.tinted(rgb, app.tint)


def _masked(shape: str, w: int, h: int, rgb: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """RGBA template of ``rgb`` (h, w, 3) inside the silhouette, cropped to its box."""
    mask, crop = _mask_and_crop(shape, w, h)
    out = np.zeros((h, w, 4), dtype=np.uint8)
    out[mask, :3] = rgb[mask]
    out[mask, 3] = 255
    return out if crop is None else np.ascontiguousarray(out[crop])


@lru_cache(maxsize=2048)
def _masked_index(
    shape: str, pattern: str, w: int, h: int, n: int, stripe: int
) -> NDArray[np.intp]:
    """Colour index per pixel of the tight silhouette box; ``n`` marks transparent pixels."""
    mask, crop = _mask_and_crop(shape, w, h)
    idx = np.where(mask, _pattern_index(pattern, w, h, n, stripe), n)
    if crop is not None:
        idx = np.ascontiguousarray(idx[crop])
    idx.setflags(write=False)
    return idx


@lru_cache(maxsize=512)
def _mask_and_crop(
    shape: str, w: int, h: int
) -> tuple[NDArray[np.bool_], tuple[slice, slice] | None]:
    """The silhouette and, if it does not fill its (h, w) box, the slices of its tight box."""
    mask = shape_mask(shape, w, h)
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    if rows[0] == 0 and cols[0] == 0 and rows[-1] == h - 1 and cols[-1] == w - 1:
        return mask, None
    return mask, (slice(rows[0], rows[-1] + 1), slice(cols[0], cols[-1] + 1))


def _tight(tpl: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """Crop an RGBA template to the box of its nonzero alpha (unchanged if empty)."""
    alpha = tpl[..., 3] > 0
    if not alpha.any():
        return tpl
    rows, cols = np.flatnonzero(alpha.any(axis=1)), np.flatnonzero(alpha.any(axis=0))
    return np.ascontiguousarray(tpl[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1])


def jitter_colors(app: Appearance, std: float, *, rng: np.random.Generator) -> Appearance:
    """A copy of ``app`` whose colours are offset by N(0, std^2) per channel (distractors).

    Parameters
    ----------
    app : Appearance
        The appearance to copy.
    std : float
        Std of the offsets (grey levels); <= 0 returns ``app`` unchanged, drawing nothing.
    rng : numpy.random.Generator
        Draws one normal per colour channel (also for an ``image`` pattern, which keeps
        ``app``: the stream keeps its place).

    Returns
    -------
    Appearance
        ``app`` with its colours offset, rounded and clipped to 0..255.
    """
    if std <= 0:
        return app
    cols = np.asarray(app.colors, dtype=np.float64)
    cols = np.clip(np.rint(cols + rng.standard_normal(cols.shape) * std), 0, 255).astype(int)
    if app.pattern == "image":  # no colours to jitter; the draws keep the stream's place
        return app
    return replace(app, colors=tuple(tuple(int(v) for v in c) for c in cols))


def transform_template(
    tpl: NDArray[np.uint8], *, scale: float = 1.0, angle: float = 0.0, shade: float = 1.0
) -> NDArray[np.uint8]:
    """Scale (nearest neighbour), rotate (degrees, counter-clockwise) and shade a template.

    The result is cropped to the tight box of its alpha, so the amodal box of the drawn
    entity is the template's extent. Shape (h', w', 4).

    Parameters
    ----------
    tpl : ndarray of uint8, shape (h, w, 4)
        The RGBA template.
    scale : float, default 1.0
        Size factor; each side is rounded and at least 1 px.
    angle : float, default 0.0
        Rotation (degrees, counter-clockwise), about the template's centre.
    shade : float, default 1.0
        Factor on the RGB channels (clipped to 0..255 and truncated).

    Returns
    -------
    ndarray of uint8, shape (h', w', 4)
        The transformed template, cropped to its alpha; a copy of ``tpl`` when nothing of
        it remains visible.
    """
    out = tpl
    if scale != 1.0:
        h, w = tpl.shape[:2]
        nw, nh = max(1, int(round(w * scale))), max(1, int(round(h * scale)))
        out = cv2.resize(out, (nw, nh), interpolation=cv2.INTER_NEAREST)
    if angle != 0.0:
        h, w = out.shape[:2]
        diag = int(np.ceil(np.hypot(h, w))) + 2
        pad = np.zeros((diag, diag, 4), dtype=np.uint8)
        oy, ox = (diag - h) // 2, (diag - w) // 2
        pad[oy : oy + h, ox : ox + w] = out
        m = cv2.getRotationMatrix2D((diag / 2, diag / 2), angle, 1.0)
        out = cv2.warpAffine(pad, m, (diag, diag), flags=cv2.INTER_NEAREST, borderValue=0)
    if shade != 1.0:
        out = out.copy()
        out[..., :3] = np.clip(out[..., :3].astype(np.float64) * shade, 0, 255).astype(np.uint8)
    if not (out[..., 3] > 0).any():
        return tpl.copy()
    return _tight(out)
