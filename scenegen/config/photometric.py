"""The :class:`Photometric` effects applied to the frames after compositing: illumination,
motion blur and JPEG compression."""

from __future__ import annotations

from dataclasses import dataclass

from scenegen.config.checks import _check_keyframes
from scenegen.config.coerce import _coerce_fields
from scenegen.config.limits import MAX_MOTION_BLUR
from scenegen.config.messages import _fail, _short
from scenegen.config.motion import AR2

__all__ = ["Photometric"]


@dataclass(frozen=True)
class Photometric:
    """Photometric effects applied to the frames after compositing, in this order:
    motion blur, illumination, then (``SceneConfig.sensor_noise``) noise, then JPEG.

    They change pixels only: labels, boxes, visibility and depth are those of the sharp
    silhouettes (computed before any effect), so ground truth stays exact.

    Attributes
    ----------
    gain, offset : AR2 or None
        Global illumination over time: every pixel becomes ``gain_t * p + offset_t``.
        ``gain`` is an AR2 of the *log* gain starting at 0 (its ``margin`` bounds
        ``|log gain|``; 0 means unbounded), ``offset`` an AR2 in grey levels starting at 0
        (``margin`` bounds ``|offset|``).
    keyframes : tuple of (frame, gain, offset)
        Scripted illumination instead (linear in between, held after the last).
    motion_blur : float
        Exposure as a fraction of the frame interval: the visible pixels of each entity
        drawn per frame are smeared along its image velocity (camera motion included)
        over ``motion_blur * |velocity|`` pixels. The static layer (background, clutter,
        static entities behind every moving one) is not blurred, unless a zoom makes
        every entity per-frame; a static entity in front of a moving one is drawn per
        frame, so a camera pan smears it.
    jpeg_quality : int or None
        Compress every frame as JPEG at this quality (1..100).
    """

    gain: AR2 | None = None
    offset: AR2 | None = None
    keyframes: tuple[tuple[int, float, float], ...] = ()
    motion_blur: float = 0.0
    jpeg_quality: int | None = None

    def __post_init__(self) -> None:
        _coerce_fields(self)
        if self.keyframes and (self.gain is not None or self.offset is not None):
            _fail("keyframes", "cannot be combined with gain or offset motion")
        _check_keyframes("keyframes", self.keyframes)
        if any(k[1] < 0 for k in self.keyframes):
            _fail("keyframes", "gains must be >= 0")
        if not 0 <= self.motion_blur <= MAX_MOTION_BLUR:
            _fail(
                "motion_blur",
                f"must be in [0, {MAX_MOTION_BLUR:g}], got {_short(self.motion_blur)}",
            )
        if self.jpeg_quality is not None and not 1 <= self.jpeg_quality <= 100:
            _fail("jpeg_quality", f"must be in 1..100, got {_short(self.jpeg_quality)}")
