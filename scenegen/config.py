"""Declarative scenario configuration: frozen dataclasses validated on construction.

A scenario is described by a :class:`SceneConfig` built from Python objects, a dict, or a
YAML/JSON file (:func:`load_config`). Every error raises :class:`~scenegen.errors.ConfigError`
whose one-line message names the field path (``entities[1].motion.x.boundary``) and the bad
value.

Example
-------
>>> cfg = from_dict({
...     "width": 64, "height": 48, "n_frames": 10,
...     "entities": [{"name": "t1", "role": "target", "position": [20, 20],
...                   "appearance": {"shape": "ellipse", "size": [9, 9]},
...                   "motion": {"x": {"sigma": 1, "boundary": "reflect"},
...                              "y": {"sigma": 1, "boundary": "reflect"}}}]})
>>> cfg.entities[0].motion.x.a1
2.0
"""

from __future__ import annotations

import contextvars
import dataclasses
import functools
import json
import math
import re
import reprlib
import types
import typing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, get_args, get_origin

from scenegen.errors import ConfigError

__all__ = [
    "AR2",
    "AR2_FIELDS",
    "BACKGROUND_FIELDS",
    "CLUTTER_FIELDS",
    "MAX_BLUR",
    "MAX_COLORS",
    "MAX_FRAMES",
    "MAX_FRAME_ENTITIES",
    "MAX_MAGNITUDE",
    "MAX_PATH",
    "MAX_SIDE",
    "MAX_TEMPLATE_PIXELS",
    "MAX_VALUES",
    "PATTERN_FIELDS",
    "Appearance",
    "Background",
    "Camera",
    "ClutterSpec",
    "EntitySpec",
    "Motion",
    "Photometric",
    "SKIMAGE_NAMES",
    "SceneConfig",
    "Variation",
    "dump_yaml",
    "from_dict",
    "from_stored",
    "load_config",
    "load_data",
    "relative_to",
    "to_dict",
]

Color = tuple[int, int, int]
Shape = Literal["rect", "ellipse", "triangle", "diamond"]
Pattern = Literal[
    "solid", "rings", "sectors", "stripes", "bands", "checker", "texture", "image", "perlin"
]
Fit = Literal["stretch", "tile", "crop"]
Boundary = Literal["reflect", "clamp", "free"]
Role = Literal["target", "distractor", "occluder", "clutter"]

_MAX_ENTITIES = 65535  # labels are uint16 and 0 is the background

# Upper limits that keep a valid config within sane memory and time: a config beyond them
# is rejected with a ConfigError naming the field rather than attempted (a width of 10^9
# would otherwise fail deep inside the generator, or exhaust memory).
MAX_SIDE = 8192
"""Largest frame width or height, and largest appearance (template) side, in pixels."""
MAX_FRAMES = 1_000_000
"""Most frames in one sequence."""
MAX_FRAME_ENTITIES = 20_000_000
"""Most frames x entities (clutter items included). Planning keeps about 50 bytes per
entity per frame (trajectories, presence, depths), so this caps it near 1 GB; e.g.
20,000 frames of 1,000 entities."""
MAX_MAGNITUDE = 1e9
"""Largest absolute value of any number in a config (positions, velocities, sigmas,
frame indices, depths, ...): far beyond any canvas, and safe from int64 overflow."""
MAX_PATH = 1e18
"""Largest absolute value an :class:`AR2` path may reach (pixels; log units for a scale,
zoom or gain; grey levels for an offset). A path that goes beyond it (or overflows to
infinity) is refused when planned, naming the field and the frame: only an explosive
``a1, a2`` (a root of ``z^2 - a1 z - a2`` outside the unit circle) gets there, or a
sigma near :data:`MAX_MAGNITUDE` over most of :data:`MAX_FRAMES` frames. Twice it (a
2x zoom) still fits a 64-bit pixel index."""
MAX_COLORS = 256
"""Most colours drawn per clutter item (``n_colors``)."""
MAX_BLUR = 256.0
"""Largest background texture ``scale`` (Gaussian std, pixels): the blur costs time in
proportion to it."""
MAX_MOTION_BLUR = 4.0
"""Largest ``Photometric.motion_blur`` (exposure in frame intervals)."""
MAX_TEMPLATE_PIXELS = 2**24
"""Most appearance template pixels of a scene: every entity's ``appearance.size`` (a mimic's
that of its model) plus, per clutter group, ``count`` x its ``appearance.size``. Planning
keeps about 75 bytes per template pixel (pattern, mask, colour and alpha layers), so this
caps it near 1.2 GB; e.g. one 4096x4096 entity, or 65,535 clutter items of 16x16. The
presets use at most 154,500."""


def _fail(path: str, msg: str) -> typing.NoReturn:
    raise ConfigError(f"{path}: {msg}" if path else msg)


_STORED = contextvars.ContextVar("scenegen_config_stored", default=False)
"""True while :func:`from_stored` builds a config read back from a file."""


def _unused(path: str, msg: str) -> None:
    """Refuse a field that holds a value the scene would silently ignore (``msg`` says
    why), except in a config read back from a file (:func:`from_stored`): a file written
    before the refusal existed keeps it ignored, as it was when the file was made."""
    if not _STORED.get():
        _fail(path, msg)


def _check_color(path: str, c: Color) -> None:
    if len(c) != 3 or any(not 0 <= v <= 255 for v in c):
        _fail(path, f"colour must be three integers in 0..255, got {_short(list(c))}")


SKIMAGE_NAMES = (
    "astronaut", "brick", "camera", "cell", "chelsea", "clock", "coffee", "coins",
    "colorwheel", "grass", "gravel", "hubble_deep_field", "immunohistochemistry",
    "microaneurysms", "moon", "page", "retina", "rocket", "text",
)  # fmt: skip
"""Images of ``skimage.data`` an image ``source`` may name (``skimage:coffee``); all ship
with scikit-image (no download). ``skimage:lfw_subset[i]`` (``0 <= i < 200``) names one of
the 200 faces of ``skimage.data.lfw_subset``."""
N_FACES = 200


def check_source(source: str) -> None:
    """Validate the syntax of an image source (a file is read only when planning).

    Raises
    ------
    ConfigError
        Unknown ``skimage:`` name, face index out of range, or an empty source.
    """
    if not source:
        raise ConfigError("must be 'skimage:NAME' or a path to an image file, got ''")
    if not source.startswith("skimage:"):
        return
    name = source[len("skimage:") :]
    if name.startswith("lfw_subset[") and name.endswith("]") and name[11:-1].isdigit():
        if int(name[11:-1]) >= N_FACES:
            raise ConfigError(f"lfw_subset has faces 0..{N_FACES - 1}, got {_short(source)}")
        return
    if name not in SKIMAGE_NAMES:
        raise ConfigError(
            f"unknown image {_short(source)}; known: {', '.join(SKIMAGE_NAMES)}, lfw_subset[0..199]"
        )


_DRAWN = ("solid", "rings", "sectors", "stripes", "bands", "checker", "texture", "perlin")
PATTERN_FIELDS: dict[str, tuple[str, ...]] = {
    "colors": _DRAWN,
    "texture_sigma": ("texture",),
    "noise_scale": ("perlin",),
    "source": ("image",),
    "crop": ("image",),
    "fit": ("image",),
    "tint": ("image",),
}
"""The :class:`Appearance` fields that only some patterns use, with those patterns: on any
other pattern such a field must keep its default, else the config is refused naming the
field and the pattern (``appearance.crop: not used by pattern 'solid' (it applies to
pattern: image)``). ``stripe_width`` (used by ``stripes`` and ``checker``) is tolerated on
every pattern: the regression fixtures, scaled down, record it on every pattern."""
BACKGROUND_FIELDS: dict[str, tuple[str, ...]] = {
    "color": ("uniform", "texture", "perlin", "image"),
    "low": ("noise", "texture", "perlin"),
    "high": ("noise", "texture", "perlin"),
    "source": ("image",),
    "fit": ("image",),
}
"""The :class:`Background` fields that only some kinds use, as :data:`PATTERN_FIELDS`.
``scale`` (used by ``texture`` and ``perlin``) is tolerated on every kind: the regression
fixtures, scaled down, record it on every kind."""
CLUTTER_FIELDS: dict[str, tuple[str, ...]] = {
    "palette": PATTERN_FIELDS["colors"],
    "n_colors": PATTERN_FIELDS["colors"],
}
"""The :class:`ClutterSpec` fields that only some ``appearance.pattern`` values use (the
patterns that take colours: an ``image`` item takes its pixels from the image), as
:data:`PATTERN_FIELDS`."""
AR2_FIELDS: dict[str, tuple[str, ...]] = {"margin": ("reflect", "clamp")}
"""The :class:`AR2` fields that only some ``boundary`` rules use (``free`` has no limits
for a margin to move), as :data:`PATTERN_FIELDS`."""


def _check_unused(
    obj: Any, kind: str, users: dict[str, tuple[str, ...]], *, chosen: Any = None
) -> None:
    """Refuse a field that the chosen ``kind`` (an appearance's ``pattern``, a background's
    ``kind``) does not use, unless it holds its default: it would be silently ignored.

    ``users`` maps each kind-specific field of ``obj`` to the kinds that use it; ``chosen``
    is the kind's value when it is not ``obj``'s own field ``kind`` (a clutter group's
    ``appearance.pattern``)."""
    chosen = getattr(obj, kind) if chosen is None else chosen
    defaults = {f.name: f.default for f in dataclasses.fields(obj)}
    for name, kinds in users.items():
        if chosen not in kinds and getattr(obj, name) != defaults[name]:
            where = " | ".join(kinds)
            _unused(name, f"not used by {kind} {chosen!r} (it applies to {kind}: {where})")


def _new(default: Any) -> Any:
    """A field added after the first release: left out of :func:`to_dict` while it holds
    its default, so configs written before it existed still compare equal."""
    return field(default=default, metadata={"omit_default": True})


@dataclass(frozen=True)
class AR2:
    """Second-order autoregression of one coordinate (docs/algorithms.md §1).

    ``c_t = mean + a1 (c_{t-1} - mean) + a2 (c_{t-2} - mean) + sigma * eps_t``.
    ``a1 = 2, a2 = -1`` is constant velocity plus acceleration noise; ``a1 = 1 + d,
    a2 = -d`` damps the velocity. ``mean`` defaults to the initial value.

    ``boundary`` (required) says what happens at the frame border: ``reflect`` mirrors the
    coordinate and its previous value (so the velocity reverses) about the limit, ``clamp``
    stops it at the limit with zero velocity, ``free`` lets the entity leave the frame. The
    limits keep the entity's centre at least ``margin`` pixels plus half its size inside the
    frame (for ``scale`` the limits are ``[-margin, margin]`` around the mean in log units,
    and a margin of 0 means no limit on the path; whatever the path, the scale an entity is
    drawn at, and its boxes, stay within 1/20 to 20 times its size, so a ``free`` log scale
    beyond log 20 draws and boxes it at that limit). An entity's ``reflect``/``clamp`` axis
    needs 2 x margin + its size <= the frame's side, else its config is refused. The limits
    hold from frame 1 on: a ``position`` outside them (nearer the border than ``margin``
    plus half the size) is taken as given at frame 0, and at frame 1 ``reflect`` mirrors it
    about the limit (a jump of twice its distance outside) and ``clamp`` puts it on the
    limit. Such starts are allowed (an entity may enter from outside the frame); give one
    inside ``[margin + size / 2, side - margin - size / 2]`` for a path without that jump.
    A ``free`` boundary has no limits: a ``margin`` on it is refused unless 0
    (:data:`AR2_FIELDS`).

    Any ``a1, a2`` is accepted, including explosive ones (roots of ``z^2 - a1 z - a2``
    outside the unit circle; ``a1 = 2, a2 = -1`` has a double root at 1, a random walk of
    the velocity, and is not explosive). A ``reflect`` or ``clamp`` axis stays within its
    limits whatever they are, but a ``free`` one (or an unbounded scale, gain or offset)
    of an explosive AR2 grows geometrically: a path beyond :data:`MAX_PATH` in magnitude is
    refused when the scene is planned, with a ConfigError naming the field and the frame
    (``entities[0].motion.x: the AR2 path reaches 1.2e+18 at frame 7, ...``).
    """

    boundary: Boundary
    a1: float = 2.0
    a2: float = -1.0
    sigma: float = 0.0
    mean: float | None = None
    margin: float = 0.0

    def __post_init__(self) -> None:
        if self.sigma < 0:
            _fail("sigma", f"must be >= 0, got {_short(self.sigma)}")
        if self.margin < 0:
            _fail("margin", f"must be >= 0, got {_short(self.margin)}")
        _check_unused(self, "boundary", AR2_FIELDS)


@dataclass(frozen=True)
class Motion:
    """Per-coordinate AR2 motion of an entity's centre (x, y) and, optionally, log scale.

    ``velocity`` sets the initial velocity: the value before the first frame is
    ``position - velocity``.
    """

    x: AR2
    y: AR2
    scale: AR2 | None = None
    velocity: tuple[float, float] = (0.0, 0.0)


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
    """

    rotation: float = 0.0
    shading: float = 0.0
    period: float = 40.0
    phase: float = 0.0

    def __post_init__(self) -> None:
        if self.period <= 0:
            _fail("period", f"must be > 0, got {_short(self.period)}")
        if not 0 <= self.shading < 1:
            _fail("shading", f"must be in [0, 1), got {_short(self.shading)}")


_MIMIC_FIELDS = ("color_jitter", "mimic_offset")
"""The :class:`EntitySpec` fields that only a mimic uses."""


@dataclass(frozen=True)
class EntitySpec:
    """One entity of the scene.

    Attributes
    ----------
    name : str
        Unique name; it also keys the entity's own random stream, so adding or removing
        another entity never changes this one's trajectory.
    role : {'target', 'distractor', 'occluder', 'clutter'}
    appearance : Appearance
    position : (x, y) or None
        Initial centre in pixels. ``None`` only for a distractor with ``mimic``: it then
        starts at the mimicked target's drawn centre at its ``appear`` frame, plus
        ``mimic_offset``.
    motion : Motion or None
        ``None``: static.
    position_noise : float
        Std (pixels) of Gaussian noise added to the drawn centre every frame (KAMS
        "measurement noise"); the motion state itself is not perturbed.
    appear, disappear : int, int or None
        The entity exists for frames ``appear <= t < disappear``.
    depth : tuple of (frame, depth)
        Depth keyframes: from ``frame`` on the entity has ``depth`` (smaller is nearer).
        Two entities may never share a depth at the same frame.
    mimic : str or None
        Name of a target whose appearance this entity copies (distractors).
    mimic_offset : (dx, dy)
        Where a mimic without a ``position`` starts, relative to its model's centre.
    color_jitter : float
        Std of a per-channel colour offset applied to a mimicked appearance.
    variation : Variation or None

    ``color_jitter`` and ``mimic_offset`` are used only by a mimic (and ``mimic_offset``
    only without a ``position``; ``color_jitter`` only when the model's pattern has
    colours, not on an ``image``): elsewhere they are refused unless they hold their
    defaults, as they would be silently ignored. A mimic's own ``appearance`` is ignored
    (it draws its model's), yet tolerated: a regression fixture records one.
    """

    name: str
    role: Role
    appearance: Appearance = field(default_factory=Appearance)
    position: tuple[float, float] | None = None
    motion: Motion | None = None
    position_noise: float = 0.0
    appear: int = 0
    disappear: int | None = None
    depth: tuple[tuple[int, int], ...] = ((0, 0),)
    mimic: str | None = None
    mimic_offset: tuple[float, float] = (0.0, 0.0)
    color_jitter: float = 0.0
    variation: Variation | None = None

    def __post_init__(self) -> None:
        _check_name("name", self.name)
        if self.position_noise < 0:
            _fail("position_noise", f"must be >= 0, got {_short(self.position_noise)}")
        if self.appear < 0:
            _fail("appear", f"must be >= 0, got {_short(self.appear)}")
        if self.disappear is not None and self.disappear <= self.appear:
            _fail(
                "disappear",
                f"must be > appear ({_short(self.appear)}), got {_short(self.disappear)}",
            )
        if not self.depth:
            _fail("depth", "needs at least one (frame, depth) keyframe")
        frames = [f for f, _ in self.depth]
        if frames[0] != 0:
            _fail("depth", f"the first keyframe must be at frame 0, got {_short(frames[0])}")
        if any(b <= a for a, b in zip(frames, frames[1:], strict=False)):
            _fail("depth", f"keyframe frames must increase, got {_short(frames)}")
        if any(d < 0 for _, d in self.depth):
            _fail("depth", f"depths must be >= 0, got {_short([d for _, d in self.depth])}")
        if self.position is None and self.mimic is None:
            _fail("position", "is required unless the entity mimics a target")
        if self.color_jitter < 0:
            _fail("color_jitter", f"must be >= 0, got {_short(self.color_jitter)}")
        defaults = {f.name: f.default for f in dataclasses.fields(self)}
        moved = [name for name in _MIMIC_FIELDS if getattr(self, name) != defaults[name]]
        if self.mimic is None and moved:
            _unused(
                moved[0], "not used without mimic (it applies to an entity that mimics another)"
            )
        if self.mimic is not None and self.position is not None and "mimic_offset" in moved:
            _unused(
                "mimic_offset",
                "not used with a position (a mimic starts at its position, or without one at "
                "its model's centre plus mimic_offset)",
            )

    def depth_at(self, t: int) -> int:
        """Depth value at frame ``t`` (the last keyframe at or before ``t``)."""
        d = self.depth[0][1]
        for f, v in self.depth:
            if f <= t:
                d = v
        return d


@dataclass(frozen=True)
class ClutterSpec:
    """A group of ``count`` static clutter entities drawn behind every other entity.

    Each item takes ``appearance`` with its size drawn uniformly in
    ``[min_size, appearance.size]`` (keeping the aspect ratio) and ``n_colors`` colours
    drawn from ``palette``. ``placement`` is ``uniform`` (centres uniform over ``region``,
    default the whole frame) or ``grid`` (a jittered grid over ``region``).

    The items' colours come from ``palette``, never from ``appearance.colors``: that is
    ignored (tolerated, not refused: the regression fixture ``single-frame`` records one).
    An ``image`` item takes its pixels from the image: ``palette`` and ``n_colors`` are
    refused on it unless they hold their defaults (:data:`CLUTTER_FIELDS`).
    """

    count: int
    appearance: Appearance = field(default_factory=Appearance)
    palette: tuple[Color, ...] = ((255, 0, 0), (0, 160, 0), (0, 0, 255), (255, 200, 0))
    n_colors: int = 1
    min_size: int = 0
    placement: Literal["uniform", "grid"] = "uniform"
    region: tuple[float, float, float, float] | None = None
    name: str = "clutter"

    def __post_init__(self) -> None:
        _check_name("name", self.name)
        if self.count < 0:
            _fail("count", f"must be >= 0, got {_short(self.count)}")
        if not self.palette:
            _fail("palette", "needs at least one colour")
        for i, c in enumerate(self.palette):
            _check_color(f"palette[{i}]", c)
        if not 1 <= self.n_colors <= MAX_COLORS:
            _fail("n_colors", f"must be in 1..{MAX_COLORS}, got {_short(self.n_colors)}")
        if self.min_size < 0 or self.min_size > min(self.appearance.size):
            _fail(
                "min_size",
                f"must be in 0..{min(self.appearance.size)}, got {_short(self.min_size)}",
            )
        if self.region is not None and (self.region[2] <= 0 or self.region[3] <= 0):
            _fail("region", f"width and height must be > 0, got {_short(list(self.region))}")
        _check_unused(self, "pattern", CLUTTER_FIELDS, chosen=self.appearance.pattern)


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
    refused unless it holds its default: :data:`BACKGROUND_FIELDS`."""

    kind: Literal["uniform", "noise", "texture", "perlin", "image"] = "uniform"
    color: Color = (255, 255, 255)
    low: int = 0
    high: int = 255
    scale: float = 4.0
    source: str | None = _new(None)
    fit: Fit = _new("crop")

    def __post_init__(self) -> None:
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


def _check_keyframes(name: str, keys: tuple[tuple[int, float, float], ...]) -> None:
    frames = [k[0] for k in keys]
    if frames and frames[0] < 0:
        _fail(name, f"frames must be >= 0, got {_short(frames)}")
    if any(b <= a for a, b in zip(frames, frames[1:], strict=False)):
        _fail(name, f"keyframe frames must increase, got {_short(frames)}")


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
    """

    extent: tuple[int, int] = (32, 32)
    x: AR2 | None = None
    y: AR2 | None = None
    velocity: tuple[float, float] = (0.0, 0.0)
    keyframes: tuple[tuple[int, float, float], ...] = ()
    zoom: AR2 | None = _new(None)

    def __post_init__(self) -> None:
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


@dataclass(frozen=True)
class SceneConfig:
    """A whole scenario: canvas, background, entities, clutter and sensor noise.

    Attributes
    ----------
    width, height : int
        Frame size in pixels.
    n_frames : int
        Number of frames T.
    background : Background
    entities : tuple of EntitySpec
        Targets, distractors and occluders, in id order (ids 1, 2, ... in this order;
        clutter items follow).
    clutter : tuple of ClutterSpec
    sensor_noise : float
        Std of i.i.d. Gaussian pixel noise added to every frame (frames only, not labels).
    name : str
        The sequence name used in HDF5 files.
    camera : Camera or None
        A panning camera (``None``: fixed).
    photometric : Photometric or None
        Illumination change, motion blur and JPEG compression (``None``: none).
    """

    width: int
    height: int
    n_frames: int
    background: Background = field(default_factory=Background)
    entities: tuple[EntitySpec, ...] = ()
    clutter: tuple[ClutterSpec, ...] = ()
    sensor_noise: float = 0.0
    name: str = "scene"
    camera: Camera | None = _new(None)
    photometric: Photometric | None = _new(None)

    def __post_init__(self) -> None:
        for f in ("width", "height", "n_frames"):
            v = getattr(self, f)
            if v < 1:
                _fail(f, f"must be >= 1, got {_short(v)}")
        if self.sensor_noise < 0:
            _fail("sensor_noise", f"must be >= 0, got {_short(self.sensor_noise)}")
        _check_name("name", self.name)
        names: dict[str, int] = {}
        for i, e in enumerate(self.entities):
            if e.name in names:
                _fail(f"entities[{i}].name", f"duplicate name {_short(e.name)}")
            names[e.name] = i
        for i, e in enumerate(self.entities):
            if e.mimic is not None:
                if e.mimic not in names:
                    _fail(f"entities[{i}].mimic", f"no entity named {_short(e.mimic)}")
                if self.entities[names[e.mimic]].mimic is not None:
                    _fail(f"entities[{i}].mimic", f"{_short(e.mimic)} itself mimics another entity")
                pattern = self.entities[names[e.mimic]].appearance.pattern
                coloured = PATTERN_FIELDS["colors"]
                if e.color_jitter != 0 and pattern not in coloured:
                    _unused(
                        f"entities[{i}].color_jitter",
                        f"not used by pattern {pattern!r} of the mimicked {_short(e.mimic)}, "
                        f"which has no colours to jitter (it applies to pattern: "
                        f"{' | '.join(coloured)})",
                    )
        cnames = [c.name for c in self.clutter]
        for j, c in enumerate(self.clutter):
            if c.name in names or cnames.index(c.name) != j:
                _fail(f"clutter[{j}].name", f"duplicate name {_short(c.name)}")
        n_total = len(self.entities) + sum(c.count for c in self.clutter)
        if n_total > _MAX_ENTITIES:
            _fail("entities", f"at most {_MAX_ENTITIES} entities in all, got {_short(n_total)}")
        for f, limit in (("width", MAX_SIDE), ("height", MAX_SIDE), ("n_frames", MAX_FRAMES)):
            if getattr(self, f) > limit:
                _fail(f, f"must be <= {limit}, got {_short(getattr(self, f))}")
        if self.n_frames * n_total > MAX_FRAME_ENTITIES:
            _fail(
                "n_frames",
                f"{self.n_frames} frames x {n_total} entities exceeds {MAX_FRAME_ENTITIES:,} "
                "(planning would need too much memory)",
            )
        self._check_template_pixels()
        _check_magnitudes(self, "")
        if self.camera is not None:
            ex, ey = self.camera.extent
            if self.width + 2 * ex > MAX_SIDE or self.height + 2 * ey > MAX_SIDE:
                _fail(
                    "camera.extent",
                    f"the background (width + 2 ex, height + 2 ey) = "
                    f"{self.width + 2 * ex}x{self.height + 2 * ey} exceeds {MAX_SIDE}",
                )
        self._check_depth_ties()
        self._check_margins()

    def _check_margins(self) -> None:
        """A bounded (``reflect``/``clamp``) axis must leave the entity's centre room:
        2 x margin + its size <= the frame's side (otherwise the limits cross and it would
        move freely, out of the frame)."""
        by_name = {e.name: e for e in self.entities}
        for i, e in enumerate(self.entities):
            if e.motion is None:
                continue
            model = by_name.get(e.mimic, e) if e.mimic is not None else e
            w, h = model.appearance.size
            for axis, size, side, label in (("x", w, self.width, "width"),
                                            ("y", h, self.height, "height")):  # fmt: skip
                ar = getattr(e.motion, axis)
                if ar.boundary != "free" and 2 * ar.margin + size > side:
                    _fail(
                        f"entities[{i}].motion.{axis}.margin",
                        f"{ar.boundary} needs 2 x margin + the entity's {label} <= the "
                        f"frame's {label}: 2 x {_short(ar.margin)} + {size} > {side}",
                    )

    def __repr__(self) -> str:
        # Short: failing hypothesis examples print it (the whole config is in to_dict).
        roles: dict[str, int] = {}
        for e in self.entities:
            roles[e.role] = roles.get(e.role, 0) + 1
        ents = ", ".join(f"{n} {r}" for r, n in roles.items()) or "none"
        clutter = sum(c.count for c in self.clutter)
        return (
            f"SceneConfig(name={self.name!r}, {self.width}x{self.height}, "
            f"{self.n_frames} frames, entities: {ents}, clutter: {clutter}, "
            f"background: {self.background.kind})"
        )

    def _repr_pretty_(self, p: Any, cycle: bool) -> None:
        # Hypothesis (and IPython) pretty-print dataclasses field by field otherwise.
        p.text(repr(self))

    def _check_template_pixels(self) -> None:
        """At most MAX_TEMPLATE_PIXELS appearance template pixels; names the entity or
        clutter group that goes beyond."""
        models = {e.name: e for e in self.entities}
        total = 0
        items = [(f"entities[{i}].appearance.size", 1,
                  (models[e.mimic] if e.mimic is not None else e).appearance.size)
                 for i, e in enumerate(self.entities)]  # fmt: skip
        items += [(f"clutter[{j}].appearance.size", c.count, c.appearance.size)
                  for j, c in enumerate(self.clutter)]  # fmt: skip
        for where, count, (w, h) in items:
            total += count * w * h
            if total > MAX_TEMPLATE_PIXELS:
                _fail(
                    where,
                    f"the appearance templates (entities, and clutter count x size) would "
                    f"hold {total:,} pixels, more than {MAX_TEMPLATE_PIXELS:,}",
                )

    def _check_depth_ties(self) -> None:
        """No two entities share a depth at any frame: a sweep over the keyframes (a tie
        can only start where some entity's depth changes), O(keyframes log keyframes)."""
        changes: dict[int, list[tuple[int, int]]] = {}
        for i, e in enumerate(self.entities):
            for f, d in e.depth:
                if f < self.n_frames:
                    changes.setdefault(f, []).append((i, d))
        current: dict[int, int] = {}  # entity index -> depth
        holders: dict[int, set[int]] = {}  # depth -> entity indices
        for t in sorted(changes):
            for i, d in changes[t]:
                if i in current:
                    holders[current[i]].discard(i)
                current[i] = d
                holders.setdefault(d, set()).add(i)
            clashes = [sorted(holders[d]) for d in {d for _, d in changes[t]}]
            clashes = [c for c in clashes if len(c) > 1]
            if clashes:  # report as a scan in id order would: the first repeated depth
                first, i = min((c[1], c[0]) for c in clashes)[::-1]
                e, other, d = self.entities[i], self.entities[first].name, current[i]
                _fail(
                    f"entities[{i}].depth",
                    f"depth tie: {_short(e.name)} and {_short(other)} both have depth {d} "
                    f"at frame {t}",
                )


# --------------------------------------------------------------------------------------
# Parsing from plain data (dicts from YAML/JSON) with field paths in every error.


def _check_magnitudes(obj: Any, path: str) -> None:
    """Every number in a (nested) config is at most MAX_MAGNITUDE in absolute value."""
    if dataclasses.is_dataclass(obj):
        for f in dataclasses.fields(obj):
            _check_magnitudes(getattr(obj, f.name), f"{path}.{f.name}" if path else f.name)
    elif isinstance(obj, tuple):
        for i, v in enumerate(obj):
            _check_magnitudes(v, f"{path}[{i}]")
    elif isinstance(obj, (int, float)) and not isinstance(obj, bool):
        if not abs(obj) <= MAX_MAGNITUDE:  # also catches NaN
            _fail(path, f"must be at most {MAX_MAGNITUDE:g} in magnitude, got {_short(obj)}")


_REPR = reprlib.Repr()
_REPR.maxlevel, _REPR.maxstring, _REPR.maxlong, _REPR.maxother = 2, 30, 30, 30
_REPR.maxlist = _REPR.maxtuple = _REPR.maxdict = _REPR.maxset = 4
SHORT = 60
"""Most characters of a value echoed in an error message (:func:`_short`)."""


def _short(value: Any) -> str:
    """A short, escaped, one-line excerpt of ``value`` for error messages.

    Never longer than :data:`SHORT` characters plus a length note, never more than one
    line (``repr`` escapes newlines and other control characters), and cheap on huge or
    deeply nested values (only the first few items of the first levels are looked at).
    """
    try:
        text = _REPR.repr(value)
    except Exception:  # a value whose repr fails or recurses without end
        text = f"<{type(value).__name__}>"
    text = text.encode("ascii", "backslashreplace").decode("ascii")
    if len(text) > SHORT:
        text = f"{text[: SHORT - 3]}..."
    if isinstance(value, (str, bytes)) and len(value) > _REPR.maxstring:
        text += f" ({len(value)} characters)"
    elif isinstance(value, (list, tuple, dict, set)) and len(value) > _REPR.maxlist:
        text += f" ({len(value)} items)"
    return text


def _excerpt(text: str, limit: int = 150) -> str:
    """A message of a parser, escaped to one ASCII line and cut to ``limit`` characters."""
    text = text.encode("ascii", "backslashreplace").decode("ascii")
    return text if len(text) <= limit else f"{text[: limit - 3]}..."


def _key(key: Any) -> str:
    """A mapping key as it appears in a field path: plain when it is a simple name,
    else a short escaped excerpt (a key may hold newlines, quotes or megabytes)."""
    if isinstance(key, str) and key.isidentifier() and len(key) <= 40 and key.isascii():
        return key
    return _short(key)


MAX_NAME = 256
"""Longest sequence, entity or clutter name, in characters."""


def _check_name(path: str, name: str) -> None:
    """Names become HDF5 group names and fixed-length strings: no NUL, no '/', not '.'
    or '..', not empty, at most :data:`MAX_NAME` characters."""
    if not name:
        _fail(path, "must not be empty")
    if len(name) > MAX_NAME:
        _fail(path, f"must be at most {MAX_NAME} characters, got {len(name)}: {_short(name)}")
    if "\0" in name:
        _fail(path, f"must not contain a NUL character, got {_short(name)}")
    if "/" in name:
        _fail(path, f"must not contain '/', got {_short(name)}")
    if name in (".", ".."):
        _fail(path, f"must not be '.' or '..', got {_short(name)}")
    if not name.isprintable():
        _fail(path, f"must be printable (no newline or control character), got {_short(name)}")


def _type_name(tp: Any) -> str:
    return getattr(tp, "__name__", str(tp))


def _is_integer(value: Any) -> bool:
    """An int or a numpy integer scalar, not a bool."""
    import numpy as np

    return isinstance(value, (int, np.integer)) and not isinstance(value, bool)


def _is_number(value: Any) -> bool:
    """An int or float, or a numpy integer or floating scalar; not a bool."""
    import numpy as np

    return _is_integer(value) or isinstance(value, (float, np.floating))


def _convert(value: Any, tp: Any, path: str) -> Any:
    origin = get_origin(tp)
    if origin is typing.Union or origin is types.UnionType:
        args = get_args(tp)
        if value is None:
            if type(None) in args:
                return None
            _fail(path, "must not be null")
        inner = [a for a in args if a is not type(None)]
        return _convert(value, inner[0], path)
    if origin is Literal:
        choices = get_args(tp)
        if value not in choices:
            _fail(path, f"must be one of {', '.join(map(str, choices))}; got {_short(value)}")
        return value
    if dataclasses.is_dataclass(tp):
        if isinstance(value, tp):
            return value
        return _build(tp, value, path)
    if origin is tuple:
        args = get_args(tp)
        if isinstance(value, (str, bytes, dict)) or not hasattr(value, "__iter__"):
            _fail(path, f"must be a list, got {_short(value)}")
        items = list(value)
        if len(args) == 2 and args[1] is Ellipsis:
            return tuple(_convert(v, args[0], f"{path}[{i}]") for i, v in enumerate(items))
        if len(items) != len(args):
            _fail(path, f"must have {len(args)} items, got {_short(items)}")
        return tuple(
            _convert(v, a, f"{path}[{i}]") for i, (v, a) in enumerate(zip(items, args, strict=True))
        )
    if tp is bool:
        if not isinstance(value, bool):
            _fail(path, f"must be true or false, got {_short(value)}")
        return value
    if tp is int:
        if not _is_number(value):
            _fail(path, f"must be an integer, got {_short(value)}")
        if not _is_integer(value) and not float(value).is_integer():
            _fail(path, f"must be an integer, got {_short(value)}")
        return int(value)
    if tp is float:
        if not _is_number(value):
            _fail(path, f"must be a number, got {_short(value)}")
        if _is_integer(value) and abs(int(value)) > MAX_MAGNITUDE:
            _fail(path, f"must be at most {MAX_MAGNITUDE:g} in magnitude, got {_short(value)}")
        if not math.isfinite(value):
            _fail(path, f"must be finite, got {_short(value)}")
        return float(value)
    if tp is str:
        if not isinstance(value, str):
            _fail(path, f"must be a string, got {_short(value)}")
        return value
    _fail(path, f"cannot read a value of type {_type_name(tp)}")


def _check_count(path: str, value: Any) -> None:
    """Refuse a list of more entities or clutter groups than a scene may hold before its
    items are read (a million of them would take minutes and gigabytes to refuse)."""
    if isinstance(value, (list, tuple)) and len(value) > _MAX_ENTITIES:
        _fail(
            path,
            f"at most {_MAX_ENTITIES} items, got {len(value):,} (a scene holds at most "
            f"{_MAX_ENTITIES} entities)",
        )


def _normalise_depth(value: Any) -> Any:
    # A single number is shorthand for a constant depth from frame 0.
    if _is_number(value):
        return [[0, value]]
    return value


@functools.cache
def _hints(cls: type) -> dict[str, Any]:
    """The field types of a config dataclass (resolving them costs more than a field)."""
    return typing.get_type_hints(cls)


def _build(cls: type, data: Any, path: str) -> Any:
    if not isinstance(data, dict):
        _fail(path, f"must be a mapping, got {_short(data)}")
    hints = _hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls)}
    for key in data:
        if key not in fields:
            _fail(
                f"{path}.{_key(key)}" if path else _key(key),
                f"unknown field; valid fields: {', '.join(fields)}",
            )
    kwargs = {}
    for name, f in fields.items():
        sub = f"{path}.{name}" if path else name
        if name not in data:
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                _fail(sub, "is required")
            continue
        value = data[name]
        if cls is EntitySpec and name == "depth":
            value = _normalise_depth(value)
        if cls is SceneConfig and name in ("entities", "clutter"):
            _check_count(sub, value)
        kwargs[name] = _convert(value, hints[name], sub)
    try:
        return cls(**kwargs)
    except ConfigError as err:
        msg = str(err)
        raise ConfigError(f"{path}.{msg}" if path else msg) from None


def from_dict(data: Any, *, folder: str | Path | None = None) -> SceneConfig:
    """Build and validate a :class:`SceneConfig` from plain data (as read from YAML/JSON).

    Parameters
    ----------
    data : dict
    folder : str or Path, optional
        The folder that relative image file ``source`` paths are relative to (the file the
        data came from: :func:`load_config` passes its folder): they are recorded joined
        to it (:func:`relative_to`). ``None`` leaves them as given: relative to the current
        directory when the scene is planned.

    Raises
    ------
    ConfigError
        Naming the field path and the bad value.
    """
    config = _build(SceneConfig, data, "")
    return config if folder is None else _sources_relative_to(config, Path(folder))


def from_stored(data: Any) -> SceneConfig:
    """:func:`from_dict` for a config read back from a file's ``config`` attribute.

    A field that holds a value the scene ignores (``not used by ...``; refused in a new
    config since it would be silently ignored) is tolerated here: files written before
    such a refusal existed stay readable and valid, and render as they did. Every other
    check applies.

    Raises
    ------
    ConfigError
        Naming the field path and the bad value.
    """
    token = _STORED.set(True)
    try:
        return _build(SceneConfig, data, "")
    finally:
        _STORED.reset(token)


def relative_to(path: str | Path, folder: str | Path | None) -> Path:
    """``path`` read from a file in ``folder``: joined to it when relative (``None``: as
    given). The one rule for every path a config or family file names (image sources,
    a family's ``base`` config)."""
    p = Path(path)
    return p if folder is None or p.is_absolute() else Path(folder) / p


def _sources_relative_to(config: SceneConfig, folder: Path) -> SceneConfig:
    """``config`` with every relative image file source joined to ``folder``."""

    def fix(obj: Any) -> Any:
        src = obj.source
        if src is None or src.startswith("skimage:") or Path(src).is_absolute():
            return obj
        return dataclasses.replace(obj, source=str(relative_to(src, folder)))

    background = fix(config.background)
    entities = tuple(dataclasses.replace(e, appearance=fix(e.appearance)) for e in config.entities)
    clutter = tuple(dataclasses.replace(c, appearance=fix(c.appearance)) for c in config.clutter)
    if (background, entities, clutter) == (config.background, config.entities, config.clutter):
        return config
    return dataclasses.replace(config, background=background, entities=entities, clutter=clutter)


def _plain(value: Any) -> Any:
    if dataclasses.is_dataclass(value):
        return {
            f.name: _plain(getattr(value, f.name))
            for f in dataclasses.fields(value)
            if not (f.metadata.get("omit_default") and getattr(value, f.name) == f.default)
        }
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    return value


def to_dict(config: SceneConfig) -> dict[str, Any]:
    """The fully resolved config as plain data; ``from_dict(to_dict(c)) == c``."""
    return _plain(config)


MAX_CONFIG_BYTES = 4 * 2**20
"""Largest config (or family) file read, in bytes."""
MAX_ALIASES = 1000
"""Most YAML aliases (``*name``) in one config."""
MAX_NODES = 100_000
"""Most YAML nodes that aliases may add to a config once expanded: a few hundred bytes of
nested aliases ("billion laughs") would otherwise expand to billions of values. A document
without aliases is bounded by :data:`MAX_CONFIG_BYTES` and :data:`MAX_VALUES` alone, as a
JSON one is."""


MAX_VALUES = 250_000
"""Most values (mappings, lists, keys and scalars) in one config or family file, YAML or
JSON alike, counted as the file is read: a file of a million list items is refused up
front rather than taking a minute and a gigabyte to read (a YAML value costs about a
kilobyte while it is read). The largest preset has under 1,000."""

_YAML_CORE = (
    ("bool", r"true|True|TRUE|false|False|FALSE", "tTfF"),
    ("int", r"[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+", "-+0123456789"),
    ("float", r"[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
              r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN)", "-+0123456789."),
    ("null", r"~|null|Null|NULL|", "~nN"),
)  # fmt: skip
"""The plain scalars that are not strings in the YAML 1.2 core schema (tag, pattern, first
characters; an empty scalar is also null): ``010`` is 10, ``0o10`` 8, ``1e9`` a float,
and ``yes``, ``no``, ``on``, ``off``, ``1_000``, ``1:30`` and ``2024-01-01`` are strings
(YAML 1.1, PyYAML's default, reads them as booleans, numbers and dates)."""


@functools.cache
def _yaml_core() -> tuple[type, type]:
    """The YAML loader and dumper of configs: PyYAML's safe ones with the implicit scalars
    of the YAML 1.2 core schema (:data:`_YAML_CORE`). The dumper quotes a string that
    either YAML 1.1 or 1.2 would read as something else, so what it writes reads back the
    same here and in any YAML reader."""
    import yaml

    class CoreLoader(yaml.SafeLoader):
        pass

    class CoreDumper(yaml.SafeDumper):
        pass

    # YAML 1.1's implicit booleans, numbers, dates and '=' go; merge keys ('<<') stay.
    CoreLoader.yaml_implicit_resolvers = {
        first: [(tag, rx) for tag, rx in resolvers if tag == "tag:yaml.org,2002:merge"]
        for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
    }
    for name, pattern, first in _YAML_CORE:
        rx = re.compile(f"^(?:{pattern})$")
        starts = [*first, ""] if name == "null" else list(first)
        for cls in (CoreLoader, CoreDumper):
            cls.add_implicit_resolver(f"tag:yaml.org,2002:{name}", rx, starts)

    def construct_int(loader: Any, node: Any) -> int:
        text = loader.construct_scalar(node)
        if text[:2] in ("0o", "0x"):
            return int(text[2:], 8 if text[1] == "o" else 16)
        return int(text, 10)  # a leading zero is decimal: 010 is 10

    CoreLoader.add_constructor("tag:yaml.org,2002:int", construct_int)
    return CoreLoader, CoreDumper


def dump_yaml(data: Any) -> str:
    """``data`` (plain data, as :func:`to_dict` gives) as YAML text that :func:`load_data`
    reads back equal: a string such as ``'1e9'``, ``'no'`` or ``'010'`` is quoted."""
    import yaml

    return yaml.dump(data, Dumper=_yaml_core()[1], sort_keys=False)


def _too_many_values() -> ConfigError:
    return ConfigError(f"more than {MAX_VALUES:,} values (lists, mappings, keys, scalars)")


def _count_values(data: Any) -> None:
    """Raise :func:`_too_many_values` if ``data`` (as JSON gives it) holds more than
    :data:`MAX_VALUES` values, counted as a YAML file's are."""
    count, stack = 0, [data]
    while stack:
        value = stack.pop()
        count += 1
        if count > MAX_VALUES:
            raise _too_many_values()
        if isinstance(value, dict):
            count += len(value)  # the keys
            stack.extend(value.values())
        elif isinstance(value, list):
            stack.extend(value)


def _core_parsing_loader() -> type:
    """The loader class :func:`_load_yaml` builds on: :func:`_yaml_core`'s loader, its
    scanning and parsing done by libyaml when PyYAML has it (the pure-Python scanner took
    about 17 of the 23 s a 240,000-value file cost; libyaml makes it 2.5 s). Composing
    stays in Python (PyYAML's ``Composer`` over libyaml's events), so the value and alias
    counts below see every node as it is composed and stop a large document early."""
    import yaml

    core = _yaml_core()[0]
    if not getattr(yaml, "__with_libyaml__", False):
        return core
    from yaml._yaml import CParser

    class CoreParsingLoader(
        yaml.composer.Composer, CParser, yaml.constructor.SafeConstructor, yaml.resolver.Resolver
    ):
        yaml_implicit_resolvers = core.yaml_implicit_resolvers
        yaml_constructors = core.yaml_constructors

        def __init__(self, stream: str) -> None:
            CParser.__init__(self, stream)
            yaml.composer.Composer.__init__(self)
            yaml.constructor.SafeConstructor.__init__(self)
            yaml.resolver.Resolver.__init__(self)

    return CoreParsingLoader


def _load_yaml(text: str) -> Any:
    """The data of a YAML document read with the YAML 1.2 core schema (:func:`_yaml_core`),
    at most :data:`MAX_VALUES` values, the alias count and the expansion bounded, and
    duplicate keys refused."""
    import yaml

    class Loader(_core_parsing_loader()):  # type: ignore[misc]
        aliases = 0
        values = 0

        def compose_node(self, parent: Any, index: Any) -> Any:
            if self.check_event(yaml.AliasEvent):
                Loader.aliases += 1
                if Loader.aliases > MAX_ALIASES:
                    raise ConfigError(f"more than {MAX_ALIASES} YAML aliases")
            else:
                Loader.values += 1
                if Loader.values > MAX_VALUES:
                    raise _too_many_values()
            return super().compose_node(parent, index)

        def construct_mapping(self, node: Any, deep: bool = False) -> Any:
            if isinstance(node, yaml.MappingNode):
                seen: set[Any] = set()
                for key_node, _ in node.value:
                    if key_node.tag == "tag:yaml.org,2002:merge":
                        continue  # '<<' merges keys that the mapping's own may override
                    key = self.construct_object(key_node, deep=True)
                    try:
                        if key in seen:
                            line = key_node.start_mark.line + 1
                            raise ConfigError(f"duplicate key {_short(key)} (line {line})")
                        seen.add(key)
                    except TypeError:  # an unhashable key: the constructor names it
                        pass
            return super().construct_mapping(node, deep=deep)

    loader = Loader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        _expanded_size(node)
        return loader.construct_document(node)
    finally:
        loader.dispose()


def _expanded_size(root: Any) -> int:
    """Nodes of a composed YAML document with every alias expanded (shared nodes counted
    once per reference); raises ConfigError when the aliases add more than MAX_NODES to
    the document's own nodes, or on a recursive alias."""
    import yaml

    sizes: dict[int, int] = {}
    active: set[int] = set()
    stack: list[tuple[Any, bool]] = [(root, False)]
    while stack:
        node, done = stack.pop()
        key = id(node)
        if done:
            active.discard(key)
            if isinstance(node, yaml.MappingNode):
                children = [c for pair in node.value for c in pair]
            elif isinstance(node, yaml.SequenceNode):
                children = node.value
            else:
                children = []
            total = 1 + sum(sizes[id(c)] for c in children)
            # A node's subtree has at most len(sizes) + 1 distinct nodes so far: what the
            # aliases added is at least total minus that, and exactly so at the root.
            if total - (len(sizes) + 1) > MAX_NODES:
                raise ConfigError(f"the YAML's aliases expand to more than {MAX_NODES:,} values")
            sizes[key] = total
            continue
        if key in sizes:
            continue
        if key in active:
            raise ConfigError("a YAML alias refers to a node that contains it")
        active.add(key)
        stack.append((node, True))
        if isinstance(node, yaml.MappingNode):
            stack.extend((c, False) for pair in node.value for c in pair)
        elif isinstance(node, yaml.SequenceNode):
            stack.extend((c, False) for c in node.value)
    return sizes[id(root)]


def json_object(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """A JSON object, refusing a key given twice (``json.loads`` would keep the last): the
    ``object_pairs_hook`` of every JSON file scenegen reads.

    Raises
    ------
    ConfigError
        ``duplicate key 'NAME'``.
    """
    out: dict[str, Any] = {}
    for k, v in pairs:
        if k in out:
            raise ConfigError(f"duplicate key {_short(k)}")
        out[k] = v
    return out


def _parser_message(err: Exception) -> str:
    """One line of a YAML or JSON parser's error: what is wrong, and where."""
    problem, mark = getattr(err, "problem", None), getattr(err, "problem_mark", None)
    if isinstance(problem, str) and problem:  # yaml's MarkedYAMLError: several lines
        where = f" (line {mark.line + 1}, column {mark.column + 1})" if mark is not None else ""
        return f"{problem}{where}"
    lines = [line.strip() for line in str(err).splitlines() if line.strip()]
    return " ".join(lines) or type(err).__name__


def load_data(path: str | Path, what: str = "config") -> Any:
    """The plain data of a YAML (``.yaml``/``.yml``) or JSON (``.json``) file, unvalidated.

    The file must be UTF-8 text (a byte-order mark is allowed, in JSON too) of at most
    :data:`MAX_CONFIG_BYTES` holding at most :data:`MAX_VALUES` values; YAML aliases are
    bounded (:data:`MAX_ALIASES`, :data:`MAX_NODES`) and a key given twice in one mapping
    is refused, in YAML and JSON alike. YAML is read with the YAML 1.2 core schema
    (:data:`_YAML_CORE`): ``010`` is 10 and ``no`` a string, where YAML 1.1 read 8 and
    false. Scenario configs (:func:`load_config`) and family files
    (:func:`scenegen.datasets.load_family`) are read by it.

    Parameters
    ----------
    path : str or Path
    what : str
        What the file holds, for messages ("config", "family").

    Raises
    ------
    ConfigError
        One line naming the file: not a regular file (a FIFO, a device), unreadable, too
        big, not UTF-8, another extension, empty, not valid YAML/JSON (the parser's problem
        and its line and column), more than :data:`MAX_VALUES` values, an alias bomb or a
        duplicate key.
    """
    from scenegen.io.atomic import describe_special_file

    p = Path(path)
    special = describe_special_file(p)
    if special is not None:  # a FIFO waits for a writer; /dev/zero never ends
        raise ConfigError(special)
    try:
        if p.stat().st_size > MAX_CONFIG_BYTES:
            raise ConfigError(
                f"{p}: {what} is {p.stat().st_size:,} bytes, more than {MAX_CONFIG_BYTES:,}"
            )
        text = p.read_text(encoding="utf-8-sig")  # a byte-order mark (Notepad's) is dropped
    except OSError as err:
        raise ConfigError(f"{p}: cannot read {what}: {err.strerror or err}") from None
    except UnicodeDecodeError as err:
        raise ConfigError(f"{p}: {what} is not UTF-8 text ({err.reason})") from None
    try:
        if p.suffix.lower() in (".yaml", ".yml"):
            data = _load_yaml(text)
            if data is None:  # no document, or only comments, or a bare null
                raise ConfigError(f"{what} is empty (a YAML mapping of fields is expected)")
            return data
        if p.suffix.lower() == ".json":
            data = json.loads(text, object_pairs_hook=json_object)
            _count_values(data)
            return data
        raise ConfigError(f"{p}: {what} must be .yaml, .yml or .json, got {_short(p.suffix)}")
    except ConfigError as err:
        raise ConfigError(str(err) if str(err).startswith(f"{p}: ") else f"{p}: {err}") from None
    except Exception as err:  # parser errors of yaml/json: report as one line
        msg = _excerpt(_parser_message(err))
        raise ConfigError(f"{p}: not valid {p.suffix[1:].upper()}: {msg}") from None


def load_config(path: str | Path, *, folder: str | Path | None = None) -> SceneConfig:
    """Read a YAML (``.yaml``/``.yml``) or JSON (``.json``) config file and validate it.

    A relative image file ``source`` is relative to the config file's folder, not to the
    current directory, and the config records it as an absolute path (so the scene can be
    generated, and its file re-rendered by ``validate --deep``, from any directory).

    Parameters
    ----------
    path : str or Path
    folder : str or Path, optional
        Join relative sources to this folder instead of the file's absolute folder (a
        family keeps them relative to its own file: :func:`from_dict`).

    Raises
    ------
    ConfigError
        If the file cannot be read or parsed (:func:`load_data`), or the config is
        invalid (message prefixed with the file name).
    """
    p = Path(path)
    data = load_data(p, "config")
    try:
        return from_dict(data, folder=p.absolute().parent if folder is None else folder)
    except ConfigError as err:
        raise ConfigError(f"{p}: {err}") from None
