"""Hypothesis strategies for property tests on generated scenes.

Every strategy is a plural noun and validates its arguments when it is called (an
:class:`hypothesis.errors.InvalidArgument` names the argument and the bad value). They draw
*parameters* — sizes, trajectories, roles, colours from a fixed palette, seeds — never raw
pixels, and shrink towards simple scenes: one static target, few frames, small canvas, no
clutter, no noise.

=================  ======================================================================
strategy           draws
=================  ======================================================================
``ar2_params``     :class:`~scenegen.config.AR2` motion of one coordinate
``entity_specs``   one :class:`~scenegen.config.EntitySpec` on a given canvas
``scene_configs``  a whole :class:`~scenegen.config.SceneConfig`, with switches for
                   occlusion, clutter, distractors, noise, entities leaving the frame
                   and realistic appearance (images, textures, camera, blur, light)
``sequences``      a rendered :class:`~scenegen.sequence.Sequence` (config + seed)
``boxes``          one box ``[x, y, w, h]`` (ndarray of shape (4,)) on a given canvas
=================  ======================================================================

Argument names are shared: ``width``/``height`` (canvas, pixels), ``min_size``/``max_size``
(entity or box side, pixels), ``max_sigma`` (AR2 noise std, pixels per frame),
``max_speed`` (initial speed per coordinate, pixels per frame), ``margin`` (pixels kept
between an entity and the border), ``boundaries`` (AR2 boundary rules).

A failing example is readable: configs and sequences print one line, and each drawn
config is attached with ``note()`` as YAML, with the command that regenerates the scene::

    scene config (YAML, saved as /tmp/scenegen-examples/scene-1a2b3c4d5e6f.yaml):
    width: 40 ...
    regenerate: scenegen generate --config /tmp/scenegen-examples/scene-1a2b3c4d5e6f.yaml
    --seed 7 -o scene.h5

Examples
--------
>>> import scenegen
>>> from hypothesis import given
>>> from scenegen.testing.strategies import scene_configs
>>> @given(scene_configs(max_frames=5, clutter=True))
... def test_renders(config):
...     assert scenegen.generate(config, seed=0).n_frames <= 5
"""

from __future__ import annotations

import math
from collections.abc import Sequence as SequenceABC
from dataclasses import replace
from pathlib import Path
from typing import Any, cast

import numpy as np
from hypothesis import note
from hypothesis import strategies as st
from hypothesis.errors import InvalidArgument
from hypothesis.strategies import SearchStrategy
from numpy.typing import NDArray

from scenegen.config import (
    AR2,
    Appearance,
    Background,
    Camera,
    ClutterSpec,
    EntitySpec,
    Motion,
    Photometric,
    SceneConfig,
)
from scenegen.sequence import Sequence

__all__ = ["ar2_params", "boxes", "entity_specs", "example_file", "scene_configs", "sequences"]

BOUNDARIES = ("reflect", "clamp", "free")
ROLES = ("target", "distractor", "occluder")
MAX_SEED = 2**32 - 1
# Simplest first: hypothesis shrinks sampled_from towards the first element.
_SHAPES = ("rect", "ellipse", "diamond", "triangle")
_PATTERNS = ("solid", "stripes", "bands", "checker", "rings", "sectors", "texture")
_COLORS = (
    (220, 40, 40),
    (40, 160, 60),
    (40, 70, 220),
    (240, 200, 0),
    (200, 40, 200),
    (0, 190, 190),
    (250, 140, 0),
    (30, 30, 30),
)
_BACKGROUND_COLORS = ((255, 255, 255), (128, 128, 128), (0, 0, 0), (200, 200, 180))
_OCCLUDER_COLORS = ((90, 90, 90), (160, 120, 80), (20, 20, 60))
_MAX_CLUTTER = 100  # "clutter everywhere" on a 120x90 canvas, still fast to render
_MAX_SENSOR_NOISE = 10.0
# Real images and textures shipped with scikit-image (no download), simplest first.
_IMAGE_SOURCES = (
    "skimage:coffee", "skimage:chelsea", "skimage:lfw_subset[12]", "skimage:brick",
    "skimage:grass", "skimage:gravel", "skimage:astronaut",
)  # fmt: skip
_FITS = ("stretch", "tile", "crop")
_MAX_POSITION_NOISE = 3.0


# --------------------------------------------------------------------------------------
# Argument validation (hypothesis api-style: validate everything, fail loudly).


def _check_int(name: str, value: Any, *, min_value: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InvalidArgument(f"{name}={value!r} must be an integer")
    if min_value is not None and value < min_value:
        raise InvalidArgument(f"{name}={value!r} must be >= {min_value}")
    return int(value)


def _check_float(name: str, value: Any, *, min_value: float = 0.0) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InvalidArgument(f"{name}={value!r} must be a number")
    if not math.isfinite(value) or value < min_value:
        raise InvalidArgument(f"{name}={value!r} must be finite and >= {min_value}")
    return float(value)


def _check_bool(name: str, value: Any) -> bool:
    if not isinstance(value, bool):
        raise InvalidArgument(f"{name}={value!r} must be True or False")
    return value


def _check_range(lo_name: str, lo: float, hi_name: str, hi: float) -> None:
    if lo > hi:
        raise InvalidArgument(f"{lo_name}={lo!r} must be <= {hi_name}={hi!r}")


def _check_strategy(name: str, value: Any) -> None:
    if not isinstance(value, SearchStrategy):
        raise InvalidArgument(f"{name}={value!r} must be a hypothesis strategy")


def _check_choices(name: str, value: Any, allowed: tuple[str, ...]) -> tuple[str, ...]:
    if isinstance(value, str) or not isinstance(value, SequenceABC) or not value:
        raise InvalidArgument(f"{name}={value!r} must be a non-empty sequence of strings")
    for v in value:
        if v not in allowed:
            raise InvalidArgument(f"{name} holds {v!r}; allowed: {', '.join(allowed)}")
    if len(set(value)) != len(value):
        raise InvalidArgument(f"{name}={value!r} has duplicates")
    return tuple(value)


def _check_max_size(max_size: Any, min_size: int) -> int:
    out = _check_int("max_size", max_size, min_value=1)
    _check_range("min_size", min_size, "max_size", out)
    return out


def _check_margin(margin: Any, boundaries: tuple[str, ...]) -> float:
    m = _check_float("margin", margin)
    if m > 0 and "free" in boundaries:
        raise InvalidArgument(
            f"margin={margin!r} keeps entities inside the frame, which boundary 'free' does "
            "not: leave 'free' out of boundaries (or exits=False), or set margin=0"
        )
    return m


def _check_fits(min_size: int, margin: float, width: int, height: int, what: str) -> None:
    if min_size + 2 * margin > min(width, height):
        raise InvalidArgument(
            f"min_size={min_size} plus twice margin={margin} does not fit the {what} "
            f"{width}x{height}"
        )


# --------------------------------------------------------------------------------------
# Small building blocks: numbers on a grid of hundredths, so that drawn configs read well
# in failure reports, round-trip through JSON and shrink to round values.


# The internal helpers take ``draw`` and are plain functions, not strategies: building
# strategies inside a draw costs more than the draw itself (every draw of a scene would
# validate dozens of new strategy objects).


def _hundredths(draw: Any, lo: float, hi: float) -> float:
    """A float in [lo, hi] on a 0.01 grid; shrinks towards the value nearest 0.

    An interval narrower than the grid step (an odd margin) gives its midpoint.
    """
    a, b = math.ceil(lo * 100), math.floor(hi * 100)
    if a > b:
        return (lo + hi) / 2
    return draw(st.integers(a, b)) / 100


def _draw_appearance(draw: Any, sizes_w: tuple[int, int], sizes_h: tuple[int, int]) -> Appearance:
    shape = draw(st.sampled_from(_SHAPES))
    size = (draw(st.integers(*sizes_w)), draw(st.integers(*sizes_h)))
    pattern = draw(st.sampled_from(_PATTERNS))
    colors = tuple(draw(st.lists(st.sampled_from(_COLORS), min_size=1, max_size=4)))
    app = Appearance(shape=shape, size=size, pattern=pattern, colors=colors)
    if pattern in ("stripes", "checker"):
        app = replace(app, stripe_width=draw(st.integers(1, 6)))
    if pattern == "texture":  # a field another pattern does not use is refused
        app = replace(app, texture_sigma=_hundredths(draw, 0, 40))
    return app


# --------------------------------------------------------------------------------------
# ar2_params


def ar2_params(
    *,
    boundaries: SequenceABC[str] = BOUNDARIES,
    max_sigma: float = 2.0,
    margin: float = 0.0,
) -> SearchStrategy[AR2]:
    """AR2 motion of one coordinate (docs/algorithms.md §1), ``a1 = 1 + d, a2 = -d``.

    ``d`` in [0, 1] spans a random walk (0), damped velocity and constant velocity plus
    acceleration noise (1); ``sigma`` is in [0, ``max_sigma``]. Shrinks towards a
    noiseless random walk (no motion at all from rest) with the first boundary rule.

    Parameters
    ----------
    boundaries : sequence of {'reflect', 'clamp', 'free'}
        The boundary rules to draw from, simplest first.
    max_sigma : float
        Largest noise std, pixels per frame (>= 0).
    margin : float
        The AR2 ``margin`` (pixels); must be 0 when ``boundaries`` holds ``free``.

    Returns
    -------
    SearchStrategy of AR2
    """
    bounds = _check_choices("boundaries", boundaries, BOUNDARIES)
    sig = _check_float("max_sigma", max_sigma)
    m = _check_margin(margin, bounds)
    return _ar2_params(bounds, sig, m)


def _draw_ar2(draw: Any, boundaries: tuple[str, ...], max_sigma: float, margin: float) -> AR2:
    boundary = draw(st.sampled_from(boundaries))
    d = _hundredths(draw, 0, 1)
    sigma = _hundredths(draw, 0, max_sigma)
    return AR2(boundary=boundary, a1=1.0 + d, a2=-d, sigma=sigma, margin=margin)


_ar2_params = st.composite(_draw_ar2)


# --------------------------------------------------------------------------------------
# entity_specs


def entity_specs(
    *,
    width: int,
    height: int,
    n_frames: int = 1,
    name: str = "entity",
    roles: SequenceABC[str] = ("target",),
    min_size: int = 3,
    max_size: int = 24,
    max_speed: float = 3.0,
    max_sigma: float = 2.0,
    margin: float = 0.0,
    noise: bool = False,
    exits: bool = False,
) -> SearchStrategy[EntitySpec]:
    """One entity on a ``width`` x ``height`` canvas of ``n_frames`` frames.

    The entity is static (shrinks to this) or moves by AR2 in x and y with an initial
    velocity of at most ``max_speed`` per coordinate. Its size (w, h) lies in
    [``min_size``, ``max_size``] and fits the canvas less ``margin`` on every side; its
    centre starts inside that area. Depth is 0: :func:`scene_configs` assigns distinct
    depths.

    Parameters
    ----------
    width, height : int
        Canvas size in pixels (>= 1).
    n_frames : int
        Frames of the scene (>= 1): bounds the appear/disappear frames.
    name : str
        The entity's name (non-empty).
    roles : sequence of {'target', 'distractor', 'occluder'}
        Roles to draw from, simplest first. (A distractor drawn here has its own
        appearance; :func:`scene_configs` makes distractors that mimic a target.)
    min_size, max_size : int
        Bounds on the entity's width and height, pixels (1 <= min_size <= max_size).
    max_speed : float
        Largest initial speed per coordinate, pixels per frame (>= 0).
    max_sigma : float
        Largest AR2 noise std, pixels per frame (>= 0).
    margin : float
        Pixels kept between the entity's box and the border (reflect/clamp motion);
        must be 0 with ``exits``.
    noise : bool
        Allow per-frame position noise (up to 3 px std).
    exits : bool
        Allow leaving the frame: ``free`` boundaries, a start up to half the entity
        outside the frame, and appear/disappear frames inside the sequence.

    Returns
    -------
    SearchStrategy of EntitySpec
    """
    w = _check_int("width", width, min_value=1)
    h = _check_int("height", height, min_value=1)
    t = _check_int("n_frames", n_frames, min_value=1)
    if not isinstance(name, str) or not name:
        raise InvalidArgument(f"name={name!r} must be a non-empty string")
    role_choices = _check_choices("roles", roles, ROLES)
    lo = _check_int("min_size", min_size, min_value=1)
    hi = _check_max_size(max_size, lo)
    speed = _check_float("max_speed", max_speed)
    sig = _check_float("max_sigma", max_sigma)
    ex = _check_bool("exits", exits)
    m = _check_margin(margin, BOUNDARIES if ex else ())
    nz = _check_bool("noise", noise)
    _check_fits(lo, m, w, h, "canvas")
    return _entity_specs(w, h, t, name, role_choices, lo, hi, speed, sig, m, nz, ex, True)


def _draw_entity(
    draw: Any,
    width: int,
    height: int,
    n_frames: int,
    name: str,
    roles: tuple[str, ...],
    min_size: int,
    max_size: int,
    max_speed: float,
    max_sigma: float,
    margin: float,
    noise: bool,
    exits: bool,
    may_start_outside: bool,
) -> EntitySpec:
    role = draw(st.sampled_from(roles))
    span_w = max(1, min(max_size, int(width - 2 * margin)))
    span_h = max(1, min(max_size, int(height - 2 * margin)))
    app = _draw_appearance(draw, (min(min_size, span_w), span_w), (min(min_size, span_h), span_h))
    ew, eh = app.size
    # The centre starts inside the allowed area; with exits it may start half outside.
    slack_x = ew / 2 if exits and may_start_outside else 0.0
    slack_y = eh / 2 if exits and may_start_outside else 0.0
    x = _hundredths(draw, margin + ew / 2 - slack_x, width - margin - ew / 2 + slack_x)
    y = _hundredths(draw, margin + eh / 2 - slack_y, height - margin - eh / 2 + slack_y)
    boundaries = BOUNDARIES if exits else BOUNDARIES[:2]
    motion = None
    if draw(st.booleans()):  # shrinks to a static entity
        motion = Motion(
            x=_draw_ar2(draw, boundaries, max_sigma, margin),
            y=_draw_ar2(draw, boundaries, max_sigma, margin),
            velocity=(
                _hundredths(draw, -max_speed, max_speed),
                _hundredths(draw, -max_speed, max_speed),
            ),
        )
    position_noise = _hundredths(draw, 0, _MAX_POSITION_NOISE) if noise else 0.0
    appear, disappear = 0, None
    if exits:
        appear = draw(st.integers(0, n_frames - 1))
        if draw(st.booleans()):
            disappear = draw(st.integers(appear + 1, n_frames))
    return EntitySpec(
        name=name,
        role=role,
        appearance=app,
        position=(x, y),
        motion=motion,
        position_noise=position_noise,
        appear=appear,
        disappear=disappear,
    )


_entity_specs = st.composite(_draw_entity)


# --------------------------------------------------------------------------------------
# scene_configs


def scene_configs(
    *,
    min_width: int = 32,
    max_width: int = 120,
    min_height: int = 24,
    max_height: int = 90,
    min_frames: int = 1,
    max_frames: int = 8,
    min_entities: int = 1,
    max_entities: int = 3,
    min_size: int = 3,
    max_size: int = 24,
    max_speed: float = 3.0,
    max_sigma: float = 2.0,
    margin: float = 0.0,
    occlusion: bool = False,
    clutter: bool = False,
    distractors: bool = False,
    noise: bool = False,
    exits: bool = False,
    realistic: bool = False,
) -> SearchStrategy[SceneConfig]:
    """Whole scenes: canvas, background, entities (targets first), clutter, noise.

    The first entity is always a target present at frame 0, without position noise
    (trackers start from it). The
    others are targets unless a switch allows another role. Entities get distinct constant
    depths; occluders lie in front of everything, clutter behind. A switch allows a
    feature — examples with and without it are drawn, and failures shrink to scenes without
    it; ``False`` never draws it.

    Parameters
    ----------
    min_width, max_width, min_height, max_height : int
        Canvas bounds in pixels (>= 1).
    min_frames, max_frames : int
        Bounds on the number of frames (>= 1).
    min_entities, max_entities : int
        Bounds on the number of entities other than clutter: targets, distractors and
        occluders (>= 1).
    min_size, max_size : int
        Bounds on entity width and height in pixels (``min_size=1`` allows 1-pixel
        objects); each draw is capped by the canvas less ``margin``.
    max_speed, max_sigma : float
        Largest initial speed and AR2 noise std per coordinate, pixels per frame.
    margin : float
        Pixels kept between every entity and the border (0 without; needs ``exits=False``).
        Clutter also stays inside this area.
    occlusion : bool
        Allow static occluders drawn over a target (partly or totally hiding it),
        appearing at frame 0 or later; needs ``max_entities >= 2``.
    clutter : bool
        Allow static clutter in the target palette, up to 100 items ("clutter everywhere").
    distractors : bool
        Allow distractors that mimic a target (recoloured copies starting near it,
        appearing at any frame); needs ``max_entities >= 2``.
    noise : bool
        Allow sensor noise, per-entity position noise, and noise or texture backgrounds.
    exits : bool
        Allow entities to leave the frame (``free`` boundaries), to start half outside it
        (all but the first target), and to appear or vanish mid-sequence.
    realistic : bool
        Allow image and Perlin-texture appearances (``skimage:`` photographs, faces and
        textures), image or Perlin backgrounds, a panning camera (AR2 or scripted), and
        photometric effects (illumination change, motion blur, JPEG).

    Returns
    -------
    SearchStrategy of SceneConfig
    """
    w0 = _check_int("min_width", min_width, min_value=1)
    w1 = _check_int("max_width", max_width, min_value=1)
    _check_range("min_width", w0, "max_width", w1)
    h0 = _check_int("min_height", min_height, min_value=1)
    h1 = _check_int("max_height", max_height, min_value=1)
    _check_range("min_height", h0, "max_height", h1)
    t0 = _check_int("min_frames", min_frames, min_value=1)
    t1 = _check_int("max_frames", max_frames, min_value=1)
    _check_range("min_frames", t0, "max_frames", t1)
    e0 = _check_int("min_entities", min_entities, min_value=1)
    e1 = _check_int("max_entities", max_entities, min_value=1)
    _check_range("min_entities", e0, "max_entities", e1)
    s0 = _check_int("min_size", min_size, min_value=1)
    s1 = _check_max_size(max_size, s0)
    speed = _check_float("max_speed", max_speed)
    sig = _check_float("max_sigma", max_sigma)
    switches = {
        k: _check_bool(k, v)
        for k, v in (
            ("occlusion", occlusion),
            ("clutter", clutter),
            ("distractors", distractors),
            ("noise", noise),
            ("exits", exits),
            ("realistic", realistic),
        )
    }
    m = _check_margin(margin, BOUNDARIES if switches["exits"] else ())
    _check_fits(s0, m, w0, h0, "smallest canvas")
    for flag in ("occlusion", "distractors"):
        if switches[flag] and e1 < 2:
            raise InvalidArgument(
                f"{flag}=True needs room for a second entity: max_entities={e1} must be >= 2"
            )
    return _scene_configs((w0, w1), (h0, h1), (t0, t1), (e0, e1), (s0, s1), speed, sig, m, switches)


def _draw_occluder(
    draw: Any, name: str, over: EntitySpec, cfg: tuple[int, int, int], margin: float
) -> EntitySpec:
    width, height, n_frames = cfg
    tw, th = over.appearance.size
    # Larger than the target by a drawn padding (total occlusion when centred on it).
    pad = draw(st.integers(0, 8))
    ow = max(1, min(tw + 2 * pad, int(width - 2 * margin)))
    oh = max(1, min(th + 2 * pad, int(height - 2 * margin)))
    ox, oy = cast(tuple[float, float], over.position)  # targets always have a position
    dx = _hundredths(draw, -ow / 2, ow / 2)
    dy = _hundredths(draw, -oh / 2, oh / 2)
    x = min(max(ox + dx, margin + ow / 2), width - margin - ow / 2)
    y = min(max(oy + dy, margin + oh / 2), height - margin - oh / 2)
    return EntitySpec(
        name=name,
        role="occluder",
        appearance=Appearance(
            shape=draw(st.sampled_from(("rect", "ellipse"))),
            size=(ow, oh),
            colors=(draw(st.sampled_from(_OCCLUDER_COLORS)),),
        ),
        position=(x, y),
        appear=draw(st.integers(0, n_frames - 1)),
    )


def _draw_distractor(
    draw: Any,
    name: str,
    targets: list[EntitySpec],
    n_frames: int,
    max_speed: float,
    max_sigma: float,
    margin: float,
    exits: bool,
) -> EntitySpec:
    model = draw(st.sampled_from(targets))
    mw, mh = model.appearance.size
    boundaries = BOUNDARIES if exits else BOUNDARIES[:2]
    return EntitySpec(
        name=name,
        role="distractor",
        mimic=model.name,
        mimic_offset=(_hundredths(draw, -mw, mw), _hundredths(draw, -mh, mh)),
        color_jitter=_hundredths(draw, 0, 10),
        motion=Motion(
            x=_draw_ar2(draw, boundaries, max_sigma, margin),
            y=_draw_ar2(draw, boundaries, max_sigma, margin),
            velocity=(
                _hundredths(draw, -max_speed, max_speed),
                _hundredths(draw, -max_speed, max_speed),
            ),
        ),
        appear=draw(st.integers(0, n_frames - 1)),
    )


def _draw_background(draw: Any, noise: bool) -> Background:
    kind = draw(st.sampled_from(("uniform", "noise", "texture"))) if noise else "uniform"
    color = draw(st.sampled_from(_BACKGROUND_COLORS))
    if kind == "uniform":
        return Background(kind="uniform", color=color)
    low = draw(st.integers(0, 255))
    high = draw(st.integers(low, 255))
    if kind == "noise":  # neither tinted nor smoothed: a colour would be refused
        return Background(kind="noise", low=low, high=high)
    scale = _hundredths(draw, 0.5, 8)
    return Background(kind=kind, color=color, low=low, high=high, scale=scale)


def _draw_clutter(draw: Any, width: int, height: int, min_size: int, margin: float) -> ClutterSpec:
    side = max(min_size, min(width, height) // 4)
    size = draw(st.integers(min_size, side))
    region = None
    if margin > 0:
        region = (margin, margin, width - 2 * margin, height - 2 * margin)
    return ClutterSpec(
        count=draw(st.integers(1, _MAX_CLUTTER)),
        appearance=Appearance(
            shape=draw(st.sampled_from(_SHAPES)),
            size=(size, size),
            pattern=draw(st.sampled_from(_PATTERNS)),
        ),
        palette=_COLORS,
        n_colors=draw(st.integers(1, 3)),
        min_size=min_size,
        placement=draw(st.sampled_from(("uniform", "grid"))),
        region=region,
    )


def _draw_scene(
    draw: Any,
    widths: tuple[int, int],
    heights: tuple[int, int],
    frames: tuple[int, int],
    entities: tuple[int, int],
    sizes: tuple[int, int],
    max_speed: float,
    max_sigma: float,
    margin: float,
    switches: dict[str, bool],
) -> SceneConfig:
    width = draw(st.integers(*widths))
    height = draw(st.integers(*heights))
    n_frames = draw(st.integers(*frames))
    n_entities = draw(st.integers(*entities))
    roles = ["target"]
    if switches["distractors"]:
        roles.append("distractor")
    if switches["occlusion"]:
        roles.append("occluder")
    role_list = ["target"] + [draw(st.sampled_from(roles)) for _ in range(n_entities - 1)]
    exits, noise = switches["exits"], switches["noise"]
    targets: list[EntitySpec] = []
    others: list[EntitySpec] = []
    counts = dict.fromkeys(ROLES, 0)
    for i, role in enumerate(role_list):
        counts[role] += 1
        name = f"{role}{counts[role]}"
        if role == "target":
            spec = _draw_entity(
                draw, width, height, n_frames, name, ("target",), sizes[0], sizes[1],
                max_speed, max_sigma, margin, noise, exits, i > 0,
            )  # fmt: skip
            if i == 0:
                # Trackers start from it: present at frame 0 whatever the noise draws.
                spec = replace(spec, appear=0, disappear=None, position_noise=0.0)
            targets.append(spec)
        elif role == "distractor":
            others.append(
                _draw_distractor(draw, name, targets, n_frames, max_speed, max_sigma, margin, exits)
            )
        else:
            over = draw(st.sampled_from(targets))
            others.append(_draw_occluder(draw, name, over, (width, height, n_frames), margin))
    # Distinct depths: occluders in front, the rest in a drawn order (shrinks to id order).
    front = [e for e in others if e.role == "occluder"]
    rest = targets + [e for e in others if e.role != "occluder"]
    order = draw(st.permutations(range(len(rest))))
    ents = [replace(e, depth=((0, d),)) for d, e in enumerate(front)]
    ents += [replace(rest[j], depth=((0, len(front) + d),)) for d, j in enumerate(order)]
    # Id order: targets first, then distractors and occluders as drawn.
    by_name = {e.name: e for e in ents}
    ordered = tuple(by_name[e.name] for e in targets + others)
    clutter = ()
    if switches["clutter"] and draw(st.booleans()):
        clutter = (_draw_clutter(draw, width, height, sizes[0], margin),)
    sensor_noise = _hundredths(draw, 0, _MAX_SENSOR_NOISE) if noise else 0.0
    background = _draw_background(draw, noise)
    camera = photo = None
    if switches["realistic"] and draw(st.booleans()):
        ordered = _realistic_entities(draw, ordered)
        if clutter:
            clutter = tuple(_realistic_clutter(draw, c) for c in clutter)
        background = _draw_real_background(draw)
        camera = _draw_camera(draw, n_frames)
        photo = _draw_photometric(draw)
    config = SceneConfig(
        width=width,
        height=height,
        n_frames=n_frames,
        background=background,
        entities=ordered,
        clutter=clutter,
        sensor_noise=sensor_noise,
        camera=camera,
        photometric=photo,
    )
    _note_config(config, None)
    return config


# Plain functions wrapped, not decorated: the draws can be called with another ``draw``.
_scene_configs = st.composite(_draw_scene)


def _textured(draw: Any, app: Appearance) -> Appearance:
    """``app`` with an image or Perlin-texture pattern (or unchanged)."""
    kind = draw(st.sampled_from(("keep", "image", "perlin")))
    if kind == "keep":
        return app
    # The fields the new pattern does not use go back to their defaults (else refused).
    plain = Appearance()
    if kind == "perlin":
        return replace(
            app, pattern="perlin", noise_scale=_hundredths(draw, 1, 16),
            texture_sigma=plain.texture_sigma, stripe_width=plain.stripe_width,
        )  # fmt: skip
    tint = draw(st.sampled_from((None, *_COLORS)))
    return replace(
        app,
        colors=plain.colors,
        texture_sigma=plain.texture_sigma,
        stripe_width=plain.stripe_width,
        pattern="image",
        source=draw(st.sampled_from(_IMAGE_SOURCES)),
        fit=draw(st.sampled_from(_FITS)),
        tint=tint,
    )


def _realistic_entities(draw: Any, ents: tuple[EntitySpec, ...]) -> tuple[EntitySpec, ...]:
    """``ents`` with textured appearances; a mimic of an image keeps no colour jitter
    (an image has no colours: it would be refused)."""
    out = [e if e.mimic is not None else replace(e, appearance=_textured(draw, e.appearance))
           for e in ents]  # fmt: skip
    images = {e.name for e in out if e.appearance.pattern == "image"}
    return tuple(replace(e, color_jitter=0.0) if e.mimic in images else e for e in out)


def _realistic_clutter(draw: Any, c: ClutterSpec) -> ClutterSpec:
    """``c`` with a textured appearance; image items keep the default palette and
    ``n_colors`` (they take no colours: others would be refused)."""
    app = _textured(draw, c.appearance)
    if app.pattern != "image":
        return replace(c, appearance=app)
    plain = ClutterSpec(count=0)
    return replace(c, appearance=app, palette=plain.palette, n_colors=plain.n_colors)


def _draw_real_background(draw: Any) -> Background:
    kind = draw(st.sampled_from(("image", "perlin")))
    if kind == "perlin":
        return Background(kind="perlin", scale=_hundredths(draw, 1, 32), low=40, high=220)
    return Background(
        kind="image", source=draw(st.sampled_from(_IMAGE_SOURCES)), fit=draw(st.sampled_from(_FITS))
    )


def _draw_camera(draw: Any, n_frames: int) -> Camera | None:
    kind = draw(st.sampled_from(("none", "ar2", "scripted")))
    if kind == "none":
        return None
    extent = (draw(st.integers(0, 24)), draw(st.integers(0, 24)))
    if kind == "scripted":
        dx, dy = extent[0], extent[1]
        end = max(n_frames - 1, 1)
        return Camera(extent=extent, keyframes=((0, -dx, -dy), (end, dx, dy)))
    return Camera(
        extent=extent,
        x=AR2(boundary=draw(st.sampled_from(BOUNDARIES[:2])), sigma=_hundredths(draw, 0, 3)),
        y=AR2(boundary=draw(st.sampled_from(BOUNDARIES[:2])), sigma=_hundredths(draw, 0, 3)),
        velocity=(_hundredths(draw, -3, 3), _hundredths(draw, -3, 3)),
        zoom=draw(
            st.sampled_from(
                (None, AR2(boundary="reflect", a1=1.0, a2=0.0, sigma=0.05, margin=0.4))
            )
        ),
    )


def _draw_photometric(draw: Any) -> Photometric | None:
    if not draw(st.booleans()):
        return None
    gain = AR2(boundary="reflect", a1=1.0, a2=0.0, sigma=_hundredths(draw, 0, 0.1), margin=0.5)
    return Photometric(
        gain=gain,
        offset=AR2(boundary="reflect", a1=1.0, a2=0.0, sigma=_hundredths(draw, 0, 5), margin=40),
        motion_blur=_hundredths(draw, 0, 2),
        jpeg_quality=draw(st.one_of(st.none(), st.integers(20, 95))),
    )


# --------------------------------------------------------------------------------------
# notes on failing examples


def example_file(config: SceneConfig) -> tuple[str, Path]:
    """``config`` as YAML and the file it is saved in (``<tmp>/scenegen-examples/``, named
    by the SHA-256 of the text, written once).

    Parameters
    ----------
    config : SceneConfig
        The config of a failing example.

    Returns
    -------
    text : str
        The config as YAML (:func:`scenegen.config.dump_yaml`).
    path : Path
        ``<tmp>/scenegen-examples/scene-<first 12 hex characters of the digest>.yaml``.
    """
    import hashlib
    import tempfile

    from scenegen.config import dump_yaml, to_dict
    from scenegen.io.atomic import write_text

    text = dump_yaml(to_dict(config))
    digest = hashlib.sha256(text.encode()).hexdigest()[:12]
    path = Path(tempfile.gettempdir()) / "scenegen-examples" / f"scene-{digest}.yaml"
    if not path.exists():
        write_text(path, text, parents=True)
    return text, path


def _is_final() -> bool:
    # Notes are printed only for the final (shrunk) failing example: only then is the
    # YAML file worth writing.
    from hypothesis.control import current_build_context

    try:
        return bool(current_build_context().is_final)
    except InvalidArgument:
        return False


def _note_config(config: SceneConfig, seed: int | None) -> None:
    """On the final example: the YAML (a drawn config, ``seed`` None) or the command that
    regenerates the scene (a drawn sequence; its config's YAML is in the file)."""
    if not _is_final():
        return
    text, path = example_file(config)
    if seed is None:
        note(f"scene config (YAML, saved as {path}):\n{text}")
    else:
        note(f"regenerate: scenegen generate --config {path} --seed {seed} -o scene.h5")


# --------------------------------------------------------------------------------------
# sequences


def sequences(
    configs: SearchStrategy[SceneConfig] | None = None,
    *,
    seeds: SearchStrategy[int] | None = None,
) -> SearchStrategy[Sequence]:
    """Rendered sequences: a config from ``configs`` and a seed from ``seeds``.

    Parameters
    ----------
    configs : SearchStrategy of SceneConfig, optional
        Default ``scene_configs()``.
    seeds : SearchStrategy of int, optional
        Non-negative seeds; default ``integers(0, 2**32 - 1)`` (shrinks to 0).

    Returns
    -------
    SearchStrategy of Sequence
        In memory: ``frames`` (T, H, W, 3) uint8, ``labels`` (T, H, W) uint16, ``gt``.
    """
    cfgs = scene_configs() if configs is None else configs
    _check_strategy("configs", cfgs)
    sds = st.integers(0, MAX_SEED) if seeds is None else seeds
    _check_strategy("seeds", sds)
    return _sequences(cfgs, sds)


@st.composite
def _sequences(
    draw: Any, configs: SearchStrategy[SceneConfig], seeds: SearchStrategy[int]
) -> Sequence:
    from scenegen.render.plan import generate

    config = draw(configs)
    if not isinstance(config, SceneConfig):
        raise InvalidArgument(f"configs drew {config!r}, which is not a SceneConfig")
    seed = draw(seeds)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidArgument(f"seeds drew {seed!r}; seeds must be non-negative integers")
    _note_config(config, int(seed))
    return generate(config, seed=int(seed))


# --------------------------------------------------------------------------------------
# boxes


def boxes(
    *,
    width: int,
    height: int,
    min_size: float = 1.0,
    max_size: float | None = None,
    inside: bool = True,
    integer: bool = False,
) -> SearchStrategy[NDArray[np.float64]]:
    """One box ``[x, y, w, h]`` (ndarray of shape (4,), float64) on a canvas.

    Coordinates lie on a 1/16-pixel grid (exact in binary, so ``x + w <= width`` holds
    exactly), or on whole pixels with ``integer``. Shrinks towards a ``min_size`` box at
    the top-left corner.

    Parameters
    ----------
    width, height : int
        Canvas size in pixels (>= 1).
    min_size, max_size : float
        Bounds on the box's width and height (0 < min_size <= max_size; ``max_size``
        defaults to the canvas side and is capped by it).
    inside : bool
        The whole box lies inside the canvas; else it only overlaps it.
    integer : bool
        Whole-pixel coordinates and sizes (then ``min_size`` is rounded up).

    Returns
    -------
    SearchStrategy of ndarray of shape (4,)
    """
    w = _check_int("width", width, min_value=1)
    h = _check_int("height", height, min_value=1)
    lo = _check_float("min_size", min_size)
    if lo <= 0:
        raise InvalidArgument(f"min_size={min_size!r} must be > 0")
    hi = float(max(w, h)) if max_size is None else _check_float("max_size", max_size)
    _check_range("min_size", lo, "max_size", hi)
    ins = _check_bool("inside", inside)
    whole = _check_bool("integer", integer)
    step = 1 if whole else 16
    lo_i = math.ceil(lo * step)
    if lo_i > min(w, h) * step:
        raise InvalidArgument(f"min_size={min_size!r} does not fit the canvas {w}x{h}")
    if math.floor(hi * step) < lo_i:
        raise InvalidArgument(
            f"no {'whole-pixel ' if whole else ''}size lies in [min_size={min_size!r}, "
            f"max_size={max_size!r}]"
        )
    return _boxes(w * step, h * step, lo_i, math.floor(hi * step), ins, step)


def _draw_box(
    draw: Any, width: int, height: int, lo: int, hi: int, inside: bool, step: int
) -> NDArray[np.float64]:
    # All in units of 1/step pixel.
    bw = draw(st.integers(lo, min(hi, width)))
    bh = draw(st.integers(lo, min(hi, height)))
    if inside:
        x = draw(st.integers(0, width - bw))
        y = draw(st.integers(0, height - bh))
    else:
        x = draw(st.integers(1 - bw, width - 1))
        y = draw(st.integers(1 - bh, height - 1))
    return np.array([x, y, bw, bh], dtype=np.float64) / step


_boxes = st.composite(_draw_box)
