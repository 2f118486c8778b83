"""The entities of a scene: an :class:`EntitySpec` (a target, distractor or occluder) and a
:class:`ClutterSpec` (a group of static clutter items)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Literal

from scenegen.config.appearance import Appearance, Color, Variation
from scenegen.config.checks import _check_color, _check_name
from scenegen.config.coerce import _coerce_fields
from scenegen.config.fields import _MIMIC_FIELDS, CLUTTER_FIELDS, _check_unused, _unused
from scenegen.config.limits import MAX_COLORS
from scenegen.config.messages import _fail, _short
from scenegen.config.motion import Motion

__all__ = ["ClutterSpec", "EntitySpec", "Role"]

Role = Literal["target", "distractor", "occluder", "clutter"]


@dataclass(frozen=True)
class EntitySpec:
    """One entity of the scene.

    ``color_jitter`` and ``mimic_offset`` are used only by a mimic (and ``mimic_offset``
    only without a ``position``; ``color_jitter`` only when the model's pattern has
    colours, not on an ``image``): elsewhere they are refused unless they hold their
    defaults, as they would be silently ignored. A mimic's own ``appearance`` is ignored
    (it draws its model's), yet tolerated: a regression fixture records one.

    Attributes
    ----------
    name : str
        Unique name; it also keys the entity's own random stream, so adding or removing
        another entity never changes this one's trajectory.
    role : {'target', 'distractor', 'occluder', 'clutter'}
        What the entity is to a tracker.
    appearance : Appearance
        How it looks. Default :class:`Appearance` ().
    position : (x, y) or None
        Initial centre in pixels. ``None`` only for a distractor with ``mimic``: it then
        starts at the mimicked target's drawn centre at its ``appear`` frame, plus
        ``mimic_offset``.
    motion : Motion or None
        ``None``: static.
    position_noise : float
        Std (pixels) of Gaussian noise added to the drawn centre every frame (KAMS
        "measurement noise"); the motion state itself is not perturbed. >= 0.
    appear, disappear : int, int or None
        The entity exists for frames ``appear <= t < disappear`` (``appear >= 0``;
        ``disappear`` None: to the end).
    depth : tuple of (frame, depth)
        Depth keyframes: from ``frame`` on the entity has ``depth`` (smaller is nearer).
        Two entities may never share a depth at the same frame. The first keyframe is at
        frame 0, frames increase, depths are >= 0. Default ``((0, 0),)``.
    mimic : str or None
        Name of a target whose appearance this entity copies (distractors).
    mimic_offset : (dx, dy)
        Where a mimic without a ``position`` starts, relative to its model's centre.
    color_jitter : float
        Std of a per-channel colour offset applied to a mimicked appearance. >= 0.
    variation : Variation or None
        Pose changes over time; None: none.

    Raises
    ------
    ConfigError
        A bad name, a negative ``position_noise``, ``appear`` or ``color_jitter``,
        ``disappear <= appear``, bad depth keyframes, no ``position`` without ``mimic``,
        or a mimic-only field set where it is not used; the message names the field.
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
        _coerce_fields(self)
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
        """Depth value at frame ``t`` (the last keyframe at or before ``t``).

        Parameters
        ----------
        t : int
            Frame index (frames); before 0 it gives the first keyframe's depth.

        Returns
        -------
        int
            The ``depth`` of the last keyframe whose frame is <= ``t`` (smaller is nearer).
        """
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

    Attributes
    ----------
    count : int
        Number of items, >= 0.
    appearance : Appearance
        The items' shape, pattern and largest size. Default :class:`Appearance` ().
    palette : tuple of (int, int, int)
        RGB colours the items' colours are drawn from (at least one). Default red, green,
        blue and yellow.
    n_colors : int
        Colours drawn per item, in 1..:data:`MAX_COLORS`. Default 1.
    min_size : int
        Smallest item side (px), in 0..min(appearance.size); 0: every item at
        ``appearance.size``. Default 0.
    placement : {"uniform", "grid"}
        How the centres are placed over ``region``. Default ``"uniform"``.
    region : tuple of (float, float, float, float) or None
        ``(x, y, w, h)`` (px, scene coordinates) the centres are placed in, w, h > 0;
        None: the whole frame. Default None.
    name : str
        Name of the group: item ``j`` is named ``{name}-{j}`` and the group's random
        stream is keyed by it. Default ``"clutter"``.

    Raises
    ------
    ConfigError
        A value out of its range or a bad name, or ``palette`` / ``n_colors`` set on an
        ``image`` appearance; the message names the field.
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
        _coerce_fields(self)
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
