"""Image sources and procedural textures for entity appearances and backgrounds.

A *source* names an image: ``skimage:NAME`` (shipped with
scikit-image, no download), ``skimage:lfw_subset[i]`` (face ``i`` of the 200 faces of
``skimage.data.lfw_subset``) or a path to an image file (read with OpenCV, falling back
to ``skimage.io``). Loaded images are cached per source. Grey images are replicated to
three channels; an alpha channel is dropped.

Procedural textures (:func:`value_noise`) draw from the caller's random stream, so every
entity's texture is keyed by its own name.
"""

from __future__ import annotations

import io
import re
from functools import lru_cache
from pathlib import Path

import cv2
import numpy as np
from numpy.typing import NDArray

from scenegen.config import check_source
from scenegen.errors import ConfigError

__all__ = [
    "fit_image",
    "load_source",
    "palette_map",
    "random_window",
    "tinted",
    "value_noise",
]

_LFW = re.compile(r"lfw_subset\[(\d+)\]\Z")


def _rgb(img: NDArray[np.generic]) -> NDArray[np.uint8]:
    """uint8 RGB (h, w, 3) of an image: integers scaled from their type's range (16-bit
    files: 0..65535), floats from [0, 1]."""
    if img.dtype != np.uint8:
        scale = 255.0
        if img.dtype.kind in "iu":
            scale = 255.0 / float(np.iinfo(img.dtype).max)
        elif img.dtype.kind == "b":
            scale = 255.0
        img = np.clip(np.rint(np.asarray(img, dtype=np.float64) * scale), 0, 255).astype(np.uint8)
    if img.ndim == 2:
        img = np.repeat(img[..., None], 3, axis=2)
    return np.ascontiguousarray(img[..., :3])


@lru_cache(maxsize=64)
def _load_cached(source: str, cwd: str) -> NDArray[np.uint8]:
    """The image of ``source``; ``cwd`` is the current directory for a relative file path
    ("" otherwise): part of the cache key, and named when the file is missing."""
    if source.startswith("skimage:"):
        import skimage.data

        name = source[len("skimage:") :]
        m = _LFW.match(name)
        img = skimage.data.lfw_subset()[int(m.group(1))] if m else getattr(skimage.data, name)()
    else:
        path = Path(cwd) / source
        if not path.is_file():
            where = f" (relative to the current directory {cwd!r})" if cwd else ""
            raise ConfigError(f"no such image file {source!r}{where}")
        try:
            img = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
        except cv2.error:  # OpenCV refuses it (say more pixels than it allows): try skimage
            img = None
        if img is not None and img.ndim == 3:
            img = cv2.cvtColor(img[..., :3], cv2.COLOR_BGR2RGB)
        if img is None:
            buf = io.BytesIO()
            try:
                import skimage.io

                # From memory: imageio's probing of its plugins opens a path and leaves
                # the file open (a ResourceWarning) when none of them can read it.
                buf = io.BytesIO(path.read_bytes())
                img = skimage.io.imread(buf)
            except Exception as err:  # any reader failure: one line naming the file
                text = str(err).strip().splitlines()
                why = text[0].replace(repr(buf), path.name) if text else type(err).__name__
                raise ConfigError(f"cannot read image file {source!r}: {why}") from None
        if img.ndim not in (2, 3) or img.size == 0:
            raise ConfigError(f"image file {source!r} is not a 2-D image (shape {img.shape})")
    out = _rgb(img)
    out.setflags(write=False)
    return out


def load_source(source: str, field: str) -> NDArray[np.uint8]:
    """The image (h, w, 3) uint8 named by ``source`` (cached; read-only).

    A relative file path is relative to the current directory (a config file's are made
    absolute when it is loaded: :func:`scenegen.config.load_config`).

    Parameters
    ----------
    source : str
        ``skimage:NAME``, ``skimage:lfw_subset[i]`` or a path to an image file.
    field : str
        The config field path that named ``source``, prefixed to an error message.

    Returns
    -------
    ndarray of uint8, shape (h, w, 3)
        The RGB image, read-only: grey replicated to three channels, alpha dropped,
        16-bit and float images scaled to 0..255.

    Raises
    ------
    ConfigError
        ``field: ...`` naming the source when it is unknown, missing or unreadable (and
        the current directory, for a relative path).
    """
    try:
        check_source(source)
        relative = not source.startswith("skimage:") and not Path(source).is_absolute()
        return _load_cached(source, str(Path.cwd()) if relative else "")
    except ConfigError as err:
        raise ConfigError(f"{field}: {err}") from None


def fit_image(
    img: NDArray[np.uint8], w: int, h: int, fit: str, offset: tuple[int, int] = (0, 0)
) -> NDArray[np.uint8]:
    """``img`` (ih, iw, 3) brought to (h, w, 3).

    ``stretch`` resizes (area interpolation when shrinking), ``tile`` repeats the image
    from ``offset`` (x, y), ``crop`` scales it to cover (h, w) keeping the aspect ratio
    and takes the centred window.

    Parameters
    ----------
    img : ndarray of uint8, shape (ih, iw, 3)
        The image.
    w, h : int
        Width and height of the result (px).
    fit : {"stretch", "tile", "crop"}
        How the image is brought to (h, w).
    offset : tuple of (int, int), default (0, 0)
        For ``tile``: the (x, y) pixel of ``img`` at the result's top-left corner (taken
        modulo the image size); ignored otherwise.

    Returns
    -------
    ndarray of uint8, shape (h, w, 3)
        A new array (a copy even when ``stretch`` keeps the size).

    Raises
    ------
    ValueError
        ``fit`` is none of the three.
    """
    ih, iw = img.shape[:2]
    if fit == "stretch":
        if (ih, iw) == (h, w):
            return img.copy()
        interp = cv2.INTER_AREA if w <= iw and h <= ih else cv2.INTER_LINEAR
        return cv2.resize(img, (w, h), interpolation=interp)
    if fit == "tile":
        ys = (np.arange(h) + offset[1]) % ih
        xs = (np.arange(w) + offset[0]) % iw
        return np.ascontiguousarray(img[ys][:, xs])
    if fit == "crop":
        s = max(w / iw, h / ih)
        nw, nh = max(w, int(np.ceil(iw * s))), max(h, int(np.ceil(ih * s)))
        interp = cv2.INTER_AREA if s < 1 else cv2.INTER_LINEAR
        big = cv2.resize(img, (nw, nh), interpolation=interp)
        x0, y0 = (nw - w) // 2, (nh - h) // 2
        return np.ascontiguousarray(big[y0 : y0 + h, x0 : x0 + w])
    raise ValueError(f"unknown fit {fit!r}")


def random_window(
    img: NDArray[np.uint8], w: int, h: int, rng: np.random.Generator
) -> NDArray[np.uint8]:
    """A (h, w, 3) window of ``img`` at an offset drawn from ``rng`` (tiled if smaller).

    Parameters
    ----------
    img : ndarray of uint8, shape (ih, iw, 3)
        The image.
    w, h : int
        Width and height of the window (px).
    rng : numpy.random.Generator
        Draws the offset: x uniform in 0..max(iw - w, 0), y in 0..max(ih - h, 0).

    Returns
    -------
    ndarray of uint8, shape (h, w, 3)
        The window, as :func:`fit_image` with ``fit="tile"`` from the drawn offset.
    """
    ih, iw = img.shape[:2]
    ox = int(rng.integers(0, max(iw - w, 0) + 1))
    oy = int(rng.integers(0, max(ih - h, 0) + 1))
    return fit_image(img, w, h, "tile", (ox, oy))


def value_noise(
    w: int, h: int, scale: float, rng: np.random.Generator, octaves: int = 3
) -> NDArray[np.float32]:
    """Perlin-like value noise (h, w) in [0, 1]: ``octaves`` lattices of uniform values
    with spacing ``scale``, ``scale / 2``, ... pixels, smoothly (bicubically) interpolated
    and summed with halving weights, then stretched to [0, 1].

    Parameters
    ----------
    w, h : int
        Width and height of the texture (px).
    scale : float
        Lattice spacing of the first octave (px); values below 1 count as 1, and no
        octave's spacing goes below 1.
    rng : numpy.random.Generator
        Draws the lattice values.
    octaves : int, default 3
        Number of lattices summed.

    Returns
    -------
    ndarray of float32, shape (h, w)
        The noise, its minimum at 0 and its maximum at 1 (all 0 when constant).
    """
    out = np.zeros((h, w), dtype=np.float32)
    amp, total = 1.0, 0.0
    step = max(float(scale), 1.0)
    for _ in range(octaves):
        gw, gh = int(np.ceil(w / step)) + 2, int(np.ceil(h / step)) + 2
        grid = rng.random((gh, gw), dtype=np.float32)
        bw, bh = int(round(gw * step)), int(round(gh * step))
        if bw * bh <= 4 * w * h + 2**20:
            big = cv2.resize(grid, (bw, bh), interpolation=cv2.INTER_CUBIC)[:h, :w]
        else:
            # A lattice much coarser than the texture: the 2-D resize would fill
            # (w + 2 step) x (h + 2 step) to keep w x h. Along x, keep w columns, then
            # along y: a cost linear in the step (values within a float rounding).
            rows = cv2.resize(grid, (bw, gh), interpolation=cv2.INTER_CUBIC)[:, :w]
            big = cv2.resize(np.ascontiguousarray(rows), (w, bh), interpolation=cv2.INTER_CUBIC)[:h]
        out += amp * big
        total += amp
        amp /= 2
        step = max(step / 2, 1.0)
    lo, hi = float(out.min()), float(out.max())
    return (out - lo) / max(hi - lo, 1e-6)


def palette_map(v: NDArray[np.float32], colors: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """Values ``v`` (h, w) in [0, 1] mapped piecewise linearly along ``colors`` (n, 3);
    one colour is shaded from a quarter of the colour (0) to the colour (1).

    Parameters
    ----------
    v : ndarray of float32, shape (h, w)
        Values in [0, 1].
    colors : array_like of uint8, shape (n, 3)
        The RGB colours that ``v`` = 0, 1 / (n - 1), ..., 1 map to, or one colour.

    Returns
    -------
    ndarray of uint8, shape (h, w, 3)
        The RGB image, rounded to the nearest integer.
    """
    cols = np.asarray(colors, dtype=np.float32)
    if len(cols) == 1:
        cols = np.stack([cols[0] * 0.25, cols[0]])
    pos = v * (len(cols) - 1)
    i = np.minimum(pos.astype(np.intp), len(cols) - 2)
    frac = (pos - i)[..., None]
    rgb = cols[i] * (1 - frac) + cols[i + 1] * frac
    return np.clip(np.rint(rgb), 0, 255).astype(np.uint8)


def tinted(img: NDArray[np.uint8], tint: tuple[int, int, int] | None) -> NDArray[np.uint8]:
    """``img`` multiplied channel-wise by ``tint`` / 255 (unchanged if None).

    Parameters
    ----------
    img : ndarray of uint8, shape (h, w, 3)
        The RGB image.
    tint : tuple of (int, int, int) or None
        Per-channel factor times 255 (255 leaves a channel unchanged).

    Returns
    -------
    ndarray of uint8, shape (h, w, 3)
        The tinted image, rounded; ``img`` itself when ``tint`` is None.
    """
    if tint is None:
        return img
    t = np.asarray(tint, dtype=np.float32) / 255.0
    return np.clip(np.rint(img.astype(np.float32) * t), 0, 255).astype(np.uint8)
