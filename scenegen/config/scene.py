"""A whole scenario: the :class:`SceneConfig` of canvas, background, entities, clutter,
camera and photometric effects, and the checks that span its parts (names, counts,
sizes, depth ties, margins, magnitudes)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

from scenegen.config.background import Background
from scenegen.config.camera import Camera
from scenegen.config.checks import _check_name
from scenegen.config.coerce import _coerce_fields
from scenegen.config.entities import ClutterSpec, EntitySpec
from scenegen.config.fields import PATTERN_FIELDS, _new, _unused
from scenegen.config.limits import (
    _MAX_ENTITIES,
    MAX_FRAME_ENTITIES,
    MAX_FRAMES,
    MAX_MAGNITUDE,
    MAX_SIDE,
    MAX_TEMPLATE_PIXELS,
)
from scenegen.config.messages import _fail, _short
from scenegen.config.photometric import Photometric

__all__ = ["SceneConfig"]


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
        _coerce_fields(self)
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
