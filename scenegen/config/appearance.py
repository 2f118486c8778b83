"""How an entity looks: its :class:`Appearance` (a silhouette filled with a pattern) and
its :class:`Variation` (pose changes over time)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from scenegen.config.checks import _check_color
from scenegen.config.coerce import _coerce_fields
from scenegen.config.fields import PATTERN_FIELDS, _check_unused, _new
from scenegen.config.limits import MAX_SIDE
from scenegen.config.messages import _fail, _short
from scenegen.config.sources import check_source
from scenegen.errors import ConfigError

__all__ = ["Appearance", "Color", "Fit", "Pattern", "Shape", "Variation"]

Color = tuple[int, int, int]
Shape = Literal["rect", "ellipse", "triangle", "diamond"]
Pattern = Literal[
    "solid", "rings", "sectors", "stripes", "bands", "checker", "texture", "image", "perlin"
]
Fit = Literal["stretch", "tile", "crop"]


@dataclass(frozen=True)
class Appearance:
    """How an entity looks: a silhouette ``shape`` of ``size`` (w, h) filled with ``pattern``.

    Patterns: ``solid`` (first colour), ``rings`` (concentric rings), ``sectors`` (pie
    wedges: a multicoloured disc), ``stripes`` (diagonal stripes of ``stripe_width``),
    ``bands`` (horizontal parts, top to bottom: per-part colours such as head/torso/legs),
    ``checker`` (squares of ``stripe_width``), ``texture`` (the colours plus Gaussian
    texture of std ``texture_sigma``, drawn from the entity's random stream), ``perlin``
    (Perlin-like value noise of feature size ``noise_scale`` pixels mapped along the
    colours, from the entity's stream), ``image`` (the image ``source`` -- see
    :data:`SKIMAGE_NAMES` or a file path -- cut to ``crop`` = [x, y, w, h] if given and
    brought to ``size`` by ``fit``: ``stretch`` resizes, ``tile`` repeats from a window
    offset drawn from the entity's stream, ``crop`` covers and centres). The silhouette
    ``shape`` masks every pattern. ``tint`` multiplies ``image`` pixels per channel
    (``[255, 140, 0]`` turns a grey texture orange). A relative file ``source`` is
    relative to the config file's folder when the config is read from a file (and then
    recorded absolute: :func:`load_config`), else to the current directory. A field that
    the pattern does not use (``crop`` on a ``solid`` pattern, ``colors`` on an ``image``)
    is refused unless it holds its default: :data:`PATTERN_FIELDS`.

    Attributes
    ----------
    shape : {"rect", "ellipse", "triangle", "diamond"}
        The silhouette that masks the pattern. Default ``"rect"``.
    size : tuple of (int, int)
        Width and height (px), each in 1..:data:`MAX_SIDE`. Default ``(20, 20)``.
    pattern : {"solid", "rings", "sectors", "stripes", "bands", "checker", "texture", \
"image", "perlin"}
        What fills the silhouette. Default ``"solid"``.
    colors : tuple of (int, int, int)
        At least one RGB colour, each channel in 0..255. Default ``((255, 0, 0),)``.
    stripe_width : int
        Width of a stripe or side of a checker square (px), >= 1. Default 4.
    texture_sigma : float
        Std of the ``texture`` pattern's Gaussian texture (grey levels), >= 0. Default 20.
    source : str or None
        The ``image`` pattern's image: a name of :data:`SKIMAGE_NAMES` or a file path.
        Required by the ``image`` pattern. Default None.
    crop : tuple of (int, int, int, int) or None
        ``[x, y, w, h]`` (px) cut from ``source`` before fitting, with x, y >= 0 and
        w, h >= 1; None keeps the whole image. Default None.
    fit : {"stretch", "tile", "crop"}
        How the image is brought to ``size``. Default ``"stretch"``.
    tint : tuple of (int, int, int) or None
        Per-channel factor (0..255, 255 = unchanged) on ``image`` pixels. Default None.
    noise_scale : float
        Feature size of the ``perlin`` pattern (px), in 1..:data:`MAX_SIDE`. Default 8.

    Raises
    ------
    ConfigError
        A value out of its range, an ``image`` pattern without ``source``, a malformed
        ``source`` (empty, unknown ``skimage:`` name; a file is read only when planning),
        or a pattern-specific field set on a pattern that does not use it; the message
        names the field.
    """

    shape: Shape = "rect"
    size: tuple[int, int] = (20, 20)
    pattern: Pattern = "solid"
    colors: tuple[Color, ...] = ((255, 0, 0),)
    stripe_width: int = 4
    texture_sigma: float = 20.0
    source: str | None = _new(None)
    crop: tuple[int, int, int, int] | None = _new(None)
    fit: Fit = _new("stretch")
    tint: Color | None = _new(None)
    noise_scale: float = _new(8.0)

    def __post_init__(self) -> None:
        _coerce_fields(self)
        if self.pattern == "image" and self.source is None:
            _fail("source", "is required by the image pattern")
        self._check_image()
        if self.size[0] < 1 or self.size[1] < 1:
            _fail("size", f"width and height must be >= 1, got {_short(list(self.size))}")
        if max(self.size) > MAX_SIDE:
            _fail("size", f"width and height must be <= {MAX_SIDE}, got {_short(list(self.size))}")
        if len(self.colors) < 1:
            _fail("colors", "needs at least one colour")
        for i, c in enumerate(self.colors):
            _check_color(f"colors[{i}]", c)
        if self.stripe_width < 1:
            _fail("stripe_width", f"must be >= 1, got {_short(self.stripe_width)}")
        if self.texture_sigma < 0:
            _fail("texture_sigma", f"must be >= 0, got {_short(self.texture_sigma)}")
        if not 1 <= self.noise_scale <= MAX_SIDE:
            _fail("noise_scale", f"must be in 1..{MAX_SIDE}, got {_short(self.noise_scale)}")
        _check_unused(self, "pattern", PATTERN_FIELDS)

    def _check_image(self) -> None:
        if self.source is not None:
            try:
                check_source(self.source)
            except ConfigError as err:
                _fail("source", str(err))
        if self.crop is not None:
            if self.crop[0] < 0 or self.crop[1] < 0 or self.crop[2] < 1 or self.crop[3] < 1:
                _fail("crop", f"needs x, y >= 0 and w, h >= 1, got {_short(list(self.crop))}")
        if self.tint is not None:
            _check_color("tint", self.tint)


@dataclass(frozen=True)
class Variation:
    """Small pose changes of the appearance over time (SHM §5: hands change with pose).

    The angle is ``rotation * sin(2 pi t / period + phase)`` degrees and the brightness
    factor ``1 + shading * sin(2 pi t / period + phase)``.

    Attributes
    ----------
    rotation : float
        Amplitude of the rotation (degrees). Default 0.
    shading : float
        Amplitude of the brightness factor, in [0, 1). Default 0.
    period : float
        Period of both oscillations (frames), > 0. Default 40.
    phase : float
        Phase of both oscillations (radians). Default 0.

    Raises
    ------
    ConfigError
        ``period <= 0`` or ``shading`` outside [0, 1); the message names the field.
    """

    rotation: float = 0.0
    shading: float = 0.0
    period: float = 40.0
    phase: float = 0.0

    def __post_init__(self) -> None:
        _coerce_fields(self)
        if self.period <= 0:
            _fail("period", f"must be > 0, got {_short(self.period)}")
        if not 0 <= self.shading < 1:
            _fail("shading", f"must be in [0, 1), got {_short(self.shading)}")
