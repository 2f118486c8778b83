"""The static :class:`Background` of a scene."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from scenegen.config.appearance import Color, Fit
from scenegen.config.checks import _check_color
from scenegen.config.coerce import _coerce_fields
from scenegen.config.fields import BACKGROUND_FIELDS, _check_unused, _new
from scenegen.config.limits import MAX_BLUR
from scenegen.config.messages import _fail, _short
from scenegen.config.sources import check_source
from scenegen.errors import ConfigError

__all__ = ["Background"]


@dataclass(frozen=True)
class Background:
    """The static background: ``uniform`` (``color``), ``noise`` (i.i.d. uniform pixels in
    ``[low, high]`` per channel), ``texture`` (noise smoothed by a Gaussian of std
    ``scale`` pixels, tinted by ``color``), ``perlin`` (Perlin-like value noise of feature
    size ``scale`` pixels in ``[low, high]``, tinted by ``color``) or ``image`` (the image
    ``source`` -- :data:`SKIMAGE_NAMES` or a file path -- brought to the background's size
    by ``fit``: ``stretch`` resizes, ``tile`` repeats, ``crop`` scales to cover and takes
    the centre; multiplied per channel by ``color`` / 255, so the default white leaves it
    unchanged; a relative file path as for :class:`Appearance`). With a :class:`Camera`
    the background is larger than the frame by the camera's ``extent`` on every side. A
    field that the kind does not use (``low`` on ``uniform``, ``color`` on ``noise``) is
    refused unless it holds its default: :data:`BACKGROUND_FIELDS`.

    Attributes
    ----------
    kind : {"uniform", "noise", "texture", "perlin", "image"}
        What the background is made of. Default ``"uniform"``.
    color : tuple of (int, int, int)
        RGB colour (0..255): the ``uniform`` colour, the tint of ``texture`` and
        ``perlin``, the per-channel factor times 255 of ``image``. Default white.
    low, high : int
        Grey-level range of ``noise``, ``texture`` and ``perlin``, with
        ``0 <= low <= high <= 255``. Defaults 0 and 255.
    scale : float
        Gaussian std of ``texture``, feature size of ``perlin`` (px), in
        (0, :data:`MAX_BLUR`]. Default 4.
    source : str or None
        The ``image`` kind's image (:data:`SKIMAGE_NAMES` or a file path); required by
        it. Default None.
    fit : {"stretch", "tile", "crop"}
        How the image is brought to the background's size. Default ``"crop"``.

    Raises
    ------
    ConfigError
        A value out of its range, an ``image`` kind without ``source``, a malformed
        ``source``, or a kind-specific field set on a kind that does not use it; the
        message names the field.
    """

    kind: Literal["uniform", "noise", "texture", "perlin", "image"] = "uniform"
    color: Color = (255, 255, 255)
    low: int = 0
    high: int = 255
    scale: float = 4.0
    source: str | None = _new(None)
    fit: Fit = _new("crop")

    def __post_init__(self) -> None:
        _coerce_fields(self)
        if self.kind == "image" and self.source is None:
            _fail("source", "is required by kind: image")
        if self.source is not None:
            try:
                check_source(self.source)
            except ConfigError as err:
                _fail("source", str(err))
        _check_color("color", self.color)
        if not 0 <= self.low <= self.high <= 255:
            _fail("low", f"need 0 <= low <= high <= 255, got low={_short(self.low)} "
                         f"high={_short(self.high)}")
        if not 0 < self.scale <= MAX_BLUR:
            _fail("scale", f"must be in (0, {MAX_BLUR:g}], got {_short(self.scale)}")
        _check_unused(self, "kind", BACKGROUND_FIELDS)
