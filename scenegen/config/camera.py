"""The :class:`Camera`: a pan (and zoom) over a background larger than the frame."""

from __future__ import annotations

from dataclasses import dataclass

from scenegen.config.checks import _check_keyframes
from scenegen.config.coerce import _coerce_fields
from scenegen.config.fields import _new, _unused
from scenegen.config.limits import MAX_SIDE
from scenegen.config.messages import _fail, _short
from scenegen.config.motion import AR2

__all__ = ["Camera"]


@dataclass(frozen=True)
class Camera:
    """A camera panning over a background larger than the frame.

    The background (and everything static: clutter, static occluders) extends ``extent``
    = (ex, ey) pixels beyond the frame on every side. Entity positions and motion are in
    *scene* coordinates, which equal frame coordinates when the camera is at rest; the
    frame shows the scene shifted by the camera offset (dx, dy), a whole number of pixels
    with ``|dx| <= ex``, ``|dy| <= ey``. The offset follows ``x`` and ``y`` (AR2 from 0 with
    initial ``velocity``, refused on an axis without its AR2; their boundary, ``reflect``
    or ``clamp``, applies at the extent; ``margin`` is ignored) or the scripted
    ``keyframes`` ((frame, dx, dy), linear in between and held after the last; an offset
    beyond the extent is refused). Every ground-truth field is in the coordinates of the
    rendered frame.

    ``zoom`` (AR2 of the log zoom from 0; ``margin`` bounds ``|log zoom|``, 0 means the
    limits 1/2 and 2; ``reflect`` or ``clamp``) magnifies the view about the frame centre:
    a scene point p appears at ``c + zoom * (p - d - c)`` with c the frame centre and d
    the offset.

    ``boundary: free`` is refused on a camera AR2: the view cannot leave the background,
    nor the zoom its limits, so a free path would leave the view stuck at the limit while
    it went on beyond (until it came back, if ever). Within the limits ``reflect`` and
    ``clamp`` move exactly as ``free`` would. With a zoom the background
    is then resampled per frame (bilinear, mirrored beyond its edge) and every entity,
    static ones included, is drawn per frame at ``scale * zoom`` (nearest neighbour, as
    for any scale change), so labels stay exact.

    Attributes
    ----------
    extent : tuple of (int, int)
        (ex, ey): how far the background reaches beyond the frame on each side (px), each
        in 0..:data:`MAX_SIDE`. Default ``(32, 32)``.
    x, y : AR2 or None
        The offset's motion per axis (px), ``reflect`` or ``clamp``; None: no motion on
        that axis. Default None.
    velocity : tuple of (float, float)
        Initial (x, y) velocity of the offset (px/frame); non-zero only on an axis with
        its AR2. Default ``(0, 0)``.
    keyframes : tuple of (int, float, float)
        Scripted offsets ``(frame, dx, dy)`` (frames increasing from >= 0; px within the
        extent); not with ``x`` or ``y``. Default ``()``.
    zoom : AR2 or None
        Motion of the log zoom, ``reflect`` or ``clamp``; None: no zoom. Default None.

    Raises
    ------
    ConfigError
        ``extent`` out of range, a ``free`` boundary, ``keyframes`` with ``x`` or ``y``,
        a velocity without its axis' AR2, keyframe frames not increasing or an offset
        beyond the extent; the message names the field.
    """

    extent: tuple[int, int] = (32, 32)
    x: AR2 | None = None
    y: AR2 | None = None
    velocity: tuple[float, float] = (0.0, 0.0)
    keyframes: tuple[tuple[int, float, float], ...] = ()
    zoom: AR2 | None = _new(None)

    def __post_init__(self) -> None:
        _coerce_fields(self)
        if not (0 <= self.extent[0] <= MAX_SIDE and 0 <= self.extent[1] <= MAX_SIDE):
            _fail("extent", f"must be in 0..{MAX_SIDE}, got {_short(list(self.extent))}")
        for axis in ("x", "y", "zoom"):
            ar = getattr(self, axis)
            if ar is not None and ar.boundary == "free":
                limits = "its limits" if axis == "zoom" else f"the extent {list(self.extent)}"
                _fail(
                    f"{axis}.boundary",
                    f"free is not allowed on a camera: the view cannot go beyond {limits} "
                    "and would stick there while the path went on; use reflect or clamp",
                )
        if self.keyframes and (self.x is not None or self.y is not None):
            _fail("keyframes", "cannot be combined with x or y motion")
        for i, axis in enumerate(("x", "y")):
            if self.velocity[i] != 0 and getattr(self, axis) is None:
                _unused(
                    "velocity",
                    f"the {axis} velocity is not used without {axis} motion (it starts the "
                    f"camera's {axis} AR2), got {_short(list(self.velocity))}",
                )
        _check_keyframes("keyframes", self.keyframes)
        for i, (_, dx, dy) in enumerate(self.keyframes):
            if abs(dx) > self.extent[0] or abs(dy) > self.extent[1]:
                _fail(
                    f"keyframes[{i}]",
                    f"offset ({dx:g}, {dy:g}) is beyond the extent "
                    f"{_short(list(self.extent))}: the view would leave the background",
                )
