"""Committed regression fixtures: small HDF5 scenes, their digests and every tracker's output.

The fixtures are defined here (:func:`definitions`): a down-sized version of each preset
(half the canvas, 8 frames, the clutter density kept up to 60 items) and edge cases — an
object entering and leaving the frame, total occlusion, a distractor on the target, a
1-pixel object and a single frame. ``scenegen fixtures regen`` writes them into a folder
(default: the repository's ``fixtures/``)::

    fixtures/<name>.h5                    the sequence (gzip)
    fixtures/expected/<name>/<tracker>.npy  float32 (T, M, 4): the tracker's boxes
    fixtures/registry.json                config, seed, SHA-256 digests, tracker runs

and ``scenegen fixtures verify`` checks that regenerating each fixture gives the same
contents, that the files still hold them, and that every tracker still gives its expected
boxes within ``|actual - expected| <= EXPECTED_ATOL`` pixels (float32 storage, and room
for last-bit differences of compiled code across machines). Trackers run with few
particles (:func:`tracker_params`) so that verifying everything stays fast.

The tracker outputs are what ``scenegen track FILE --tracker NAME --seed 0 --param ...``
writes: the targets present at frame 0, initialised with their ground-truth boxes.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Iterable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from scenegen.config import (
    AR2,
    Appearance,
    Background,
    Camera,
    ClutterSpec,
    EntitySpec,
    Motion,
    SceneConfig,
)
from scenegen.errors import ConfigError, DataError
from scenegen.testing.compare import difference

__all__ = [
    "EXPECTED_ATOL",
    "SCHEMA",
    "FixtureDef",
    "compare_boxes",
    "default_dir",
    "definitions",
    "digests",
    "load_registry",
    "select_names",
    "downsized",
]

SCHEMA = "scenegen-fixtures/1"
EXPECTED_ATOL = 0.01  # pixels
TRACKER_SEED = 0
FAST_PARTICLES = 32


@dataclass(frozen=True)
class FixtureDef:
    """One regression fixture: a config and a seed, with what it exercises.

    Attributes
    ----------
    name : str
        The fixture's name (also its config's ``name``).
    description : str
        What it exercises, one line.
    config : SceneConfig
        The scene.
    seed : int
        The scene seed.
    preset : str
        The preset it was made from ("" for an edge case).
    """

    name: str
    description: str
    config: SceneConfig
    seed: int
    preset: str = ""


# --------------------------------------------------------------------------------------
# Definitions


def _scale_ar2(a: AR2 | None, f: float, *, log_scale: bool = False) -> AR2 | None:
    if a is None:
        return None
    if log_scale:  # log-scale motion is scale-free
        return a
    return replace(
        a,
        sigma=a.sigma * f,
        margin=a.margin * f,
        mean=None if a.mean is None else a.mean * f,
    )


def _scale_appearance(app: Appearance, f: float) -> Appearance:
    return replace(
        app,
        size=(max(1, round(app.size[0] * f)), max(1, round(app.size[1] * f))),
        stripe_width=max(1, round(app.stripe_width * f)),
    )


def _scale_entity(e: EntitySpec, f: float) -> EntitySpec:
    motion = e.motion
    if motion is not None:
        motion = Motion(
            x=_scale_ar2(motion.x, f),
            y=_scale_ar2(motion.y, f),
            scale=_scale_ar2(motion.scale, f, log_scale=True),
            velocity=(motion.velocity[0] * f, motion.velocity[1] * f),
        )
    return replace(
        e,
        appearance=_scale_appearance(e.appearance, f),
        position=None if e.position is None else (e.position[0] * f, e.position[1] * f),
        motion=motion,
        position_noise=e.position_noise * f,
        mimic_offset=(e.mimic_offset[0] * f, e.mimic_offset[1] * f),
    )


def _scale_camera(cam: Camera | None, f: float) -> Camera | None:
    if cam is None:
        return None
    ex, ey = round(cam.extent[0] * f), round(cam.extent[1] * f)
    # An offset scaled with its extent stays within it but for the extent's rounding
    # (less than half a pixel; the offset is a whole number of pixels anyway).
    keyframes = tuple(
        (t, min(max(dx * f, -ex), ex), min(max(dy * f, -ey), ey)) for t, dx, dy in cam.keyframes
    )
    return replace(
        cam,
        extent=(ex, ey),
        x=_scale_ar2(cam.x, f),
        y=_scale_ar2(cam.y, f),
        zoom=_scale_ar2(cam.zoom, f, log_scale=True),
        velocity=(cam.velocity[0] * f, cam.velocity[1] * f),
        keyframes=keyframes,
    )


def _scale_clutter(c: ClutterSpec, f: float, max_count: int | None) -> ClutterSpec:
    app = _scale_appearance(c.appearance, f)
    count = round(c.count * f * f)  # same density on the smaller canvas
    if max_count is not None:
        count = min(count, max_count)
    return replace(
        c,
        count=count,
        appearance=app,
        min_size=min(round(c.min_size * f), min(app.size)),
        region=None if c.region is None else tuple(v * f for v in c.region),
    )


def downsized(
    config: SceneConfig, *, factor: float, n_frames: int, max_clutter: int | None = None
) -> SceneConfig:
    """``config`` on a canvas scaled by ``factor``, with ``n_frames`` frames.

    Positions, sizes, speeds, noise stds, margins and texture scales are scaled by
    ``factor``, the camera's too (its extent, offset motion, velocity and keyframe
    offsets; not its log zoom); clutter counts by ``factor**2`` (same density), capped at
    ``max_clutter``. Frame-indexed fields (appear, disappear, depth keyframes, the frames
    of camera keyframes) are kept, and so are the photometric settings, the sensor noise
    and an appearance's ``noise_scale``.

    Parameters
    ----------
    config : SceneConfig
        The scene.
    factor : float
        Scale of the canvas, in (0, 1]; sizes are rounded and at least 1 px.
    n_frames : int
        Frames of the result, >= 1.
    max_clutter : int, optional
        Most items per clutter group (None: no cap).

    Returns
    -------
    SceneConfig
        The downsized config (validated again on construction).

    Raises
    ------
    ConfigError
        If ``factor`` is not in (0, 1] or ``n_frames`` < 1.
    """
    if not 0 < factor <= 1:
        raise ConfigError(f"factor must be in (0, 1], got {factor}")
    if n_frames < 1:
        raise ConfigError(f"n_frames must be >= 1, got {n_frames}")
    bg = config.background
    return replace(
        config,
        width=max(1, round(config.width * factor)),
        height=max(1, round(config.height * factor)),
        n_frames=n_frames,
        background=replace(bg, scale=bg.scale * factor),
        entities=tuple(_scale_entity(e, factor) for e in config.entities),
        clutter=tuple(_scale_clutter(c, factor, max_clutter) for c in config.clutter),
        sensor_noise=config.sensor_noise,
        camera=_scale_camera(config.camera, factor),
    )


_STILL = AR2(boundary="free", sigma=0.0)  # motion by the initial velocity only
_WHITE = Background(kind="uniform", color=(255, 255, 255))
_DISC = Appearance(
    shape="ellipse",
    size=(12, 12),
    pattern="sectors",
    colors=((230, 30, 30), (30, 170, 30), (30, 60, 230), (240, 210, 0)),
)


def _enter_leave() -> FixtureDef:
    cfg = SceneConfig(
        name="enter-leave",
        width=80,
        height=60,
        n_frames=12,
        background=_WHITE,
        entities=(
            EntitySpec(
                name="leaving",
                role="target",
                appearance=_DISC,
                position=(60.0, 20.0),
                motion=Motion(x=_STILL, y=_STILL, velocity=(3.0, 0.0)),
                depth=((0, 0),),
            ),
            EntitySpec(
                name="entering",
                role="target",
                appearance=replace(_DISC, shape="rect", pattern="checker", stripe_width=3),
                position=(-8.0, 40.0),
                motion=Motion(x=_STILL, y=_STILL, velocity=(9.0, 0.0)),
                depth=((0, 1),),
            ),
        ),
    )
    what = "a tracked target leaves the frame; another object enters and leaves it"
    return FixtureDef(cfg.name, what, cfg, seed=1)


def _full_occlusion() -> FixtureDef:
    cfg = SceneConfig(
        name="full-occlusion",
        width=96,
        height=64,
        n_frames=14,
        background=Background(kind="texture", color=(200, 200, 180), low=60, high=200, scale=3),
        entities=(
            EntitySpec(
                name="walker",
                role="target",
                appearance=replace(_DISC, pattern="bands"),
                position=(16.0, 32.0),
                motion=Motion(x=_STILL, y=_STILL, velocity=(5.0, 0.0)),
                depth=((0, 1),),
            ),
            EntitySpec(
                name="wall",
                role="occluder",
                appearance=Appearance(shape="rect", size=(24, 30), colors=((90, 90, 90),)),
                position=(48.0, 32.0),
                depth=((0, 0),),
            ),
        ),
    )
    what = "a target passes behind a larger static occluder, totally hidden at frames 6-7"
    return FixtureDef(cfg.name, what, cfg, seed=1)


def _distractor_on_target() -> FixtureDef:
    cfg = SceneConfig(
        name="distractor-on-target",
        width=80,
        height=60,
        n_frames=12,
        background=Background(kind="noise", low=0, high=255),
        entities=(
            EntitySpec(
                name="target",
                role="target",
                appearance=_DISC,
                position=(30.0, 30.0),
                motion=Motion(
                    x=AR2(boundary="reflect", a1=1.5, a2=-0.5, sigma=1.0, margin=2),
                    y=AR2(boundary="reflect", a1=1.5, a2=-0.5, sigma=1.0, margin=2),
                ),
                depth=((0, 1),),
            ),
            EntitySpec(
                name="copy",
                role="distractor",
                mimic="target",
                color_jitter=5.0,
                motion=Motion(
                    x=AR2(boundary="reflect", sigma=0.3, margin=2),
                    y=AR2(boundary="reflect", sigma=0.3, margin=2),
                    velocity=(3.0, 1.5),
                ),
                appear=2,
                disappear=9,
                depth=((0, 0),),
            ),
        ),
    )
    what = "a recoloured copy appears on the target at frame 2, drifts off, goes at 9"
    return FixtureDef(cfg.name, what, cfg, seed=1)


def _one_pixel() -> FixtureDef:
    cfg = SceneConfig(
        name="one-pixel",
        width=64,
        height=48,
        n_frames=8,
        background=_WHITE,
        entities=(
            EntitySpec(
                name="dot",
                role="target",
                appearance=Appearance(shape="rect", size=(1, 1), colors=((200, 0, 0),)),
                position=(20.5, 20.5),
                motion=Motion(
                    x=AR2(boundary="reflect", a1=1.5, a2=-0.5, sigma=0.5, margin=2),
                    y=AR2(boundary="reflect", a1=1.5, a2=-0.5, sigma=0.5, margin=2),
                    velocity=(1.0, 0.5),
                ),
            ),
        ),
    )
    return FixtureDef(cfg.name, "a 1x1-pixel target on white", cfg, seed=1)


def _single_frame() -> FixtureDef:
    cfg = SceneConfig(
        name="single-frame",
        width=64,
        height=48,
        n_frames=1,
        background=_WHITE,
        entities=(
            EntitySpec(name="target", role="target", appearance=_DISC, position=(32.0, 24.0)),
        ),
        clutter=(ClutterSpec(count=12, appearance=_DISC, n_colors=3, min_size=6),),
    )
    return FixtureDef(cfg.name, "one frame: a target among clutter", cfg, seed=1)


def _edge_cases() -> list[FixtureDef]:
    """The hand-made fixtures, in registry order."""
    return [
        _enter_leave(),
        _full_occlusion(),
        _distractor_on_target(),
        _one_pixel(),
        _single_frame(),
    ]


def definitions() -> dict[str, FixtureDef]:
    """Every fixture by name: one per preset (``<preset>-small``), then the edge cases.

    Returns
    -------
    dict of str to FixtureDef
        The definitions: each preset of :func:`scenegen.presets.names` at half size,
        8 frames, at most 60 clutter items per group, seed 1; then the edge cases.
    """
    from scenegen import presets

    out: dict[str, FixtureDef] = {}
    for name in presets.names():
        cfg = downsized(presets.get(name), factor=0.5, n_frames=8, max_clutter=60)
        fname = f"{name}-small"
        out[fname] = FixtureDef(
            fname,
            f"preset {name} at half size, 8 frames, clutter density kept (at most 60 items)",
            replace(cfg, name=fname),
            seed=1,
            preset=name,
        )
    for d in _edge_cases():
        out[d.name] = d
    return out


# --------------------------------------------------------------------------------------
# Digests and tracker runs


def digest_array(arr: Any) -> str:
    a = np.ascontiguousarray(np.asarray(arr))
    h = hashlib.sha256(f"{a.dtype.str}{a.shape}".encode())
    if a.dtype.kind == "U":
        h.update("\n".join(a.ravel().tolist()).encode("utf-8"))
    else:
        h.update(a.tobytes())
    return h.hexdigest()


def digests(seq: Any) -> dict[str, str]:
    """SHA-256 (hex) of the contents of every array of ``seq``, keyed by HDF5 path.

    Each digest covers the dtype, the shape and the bytes; the templates share one digest
    (``templates``, over all of them in id order).

    Parameters
    ----------
    seq : Sequence
        The sequence (in memory or read from a file).

    Returns
    -------
    dict of str to str
        ``frames``, ``labels``, ``entities/id``, ``entities/role``, ``entities/name``,
        every ``gt/<field>`` and ``templates``, each to a 64-character hex digest.
    """
    out = {
        "frames": digest_array(seq.frames),
        "labels": digest_array(seq.labels),
        "entities/id": digest_array(np.asarray(seq.entities.id, dtype=np.int32)),
        "entities/role": digest_array(np.asarray(seq.entities.role, dtype=str)),
        "entities/name": digest_array(np.asarray(seq.entities.name, dtype=str)),
    }
    for key, arr in seq.gt.as_dict().items():
        out[f"gt/{key}"] = digest_array(arr)
    h = hashlib.sha256()
    for eid in sorted(seq.templates):
        h.update(str(eid).encode())
        h.update(digest_array(seq.templates[eid]).encode())
    out["templates"] = h.hexdigest()
    return out


def compare_boxes(actual: NDArray[Any], expected: NDArray[Any]) -> str | None:
    """None if equal within :data:`EXPECTED_ATOL` pixels (NaN matching NaN), else what
    differs (:func:`scenegen.testing.compare.difference`; the index is (frame, target,
    coordinate)).

    Parameters
    ----------
    actual, expected : ndarray of float, shape (T, M, 4)
        Boxes [x, y, w, h] (px) per frame and target.

    Returns
    -------
    str or None
        One line saying what differs (shape, NaN placement or the largest difference),
        or None.
    """
    return difference(actual, expected, atol=EXPECTED_ATOL)


# --------------------------------------------------------------------------------------
# Registry


def default_dir() -> Path:
    """The repository's ``fixtures/`` folder in a source checkout, else ``./fixtures``.

    Returns
    -------
    Path
        The checkout's folder (absolute) when it holds ``registry.json``, else the
        relative ``fixtures``.
    """
    repo = Path(__file__).resolve().parents[2] / "fixtures"
    return repo if (repo / "registry.json").exists() else Path("fixtures")


def load_registry(folder: Path, *, missing_ok: bool) -> dict[str, Any]:
    """The fixture registry ``folder/registry.json``.

    Parameters
    ----------
    folder : Path
        The fixtures folder.
    missing_ok : bool
        Give an empty registry when the file is missing, instead of raising.

    Returns
    -------
    dict
        The registry: ``schema`` and ``fixtures`` (name -> entry).

    Raises
    ------
    DataError
        The file is missing (unless ``missing_ok``), unreadable, not JSON, or of another
        schema.
    """
    path = folder / "registry.json"
    if not path.exists():
        if missing_ok:
            return {"schema": SCHEMA, "fixtures": {}}
        raise DataError(f"{path}: no such file (write the fixtures with `scenegen fixtures regen`)")
    from scenegen.io.atomic import read_regular_text

    try:  # a FIFO there is refused at once (SpecialFile, a DataError line)
        reg = json.loads(read_regular_text(path))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as err:
        raise DataError(f"{path}: not a readable JSON registry: {err}") from None
    if not isinstance(reg, dict) or reg.get("schema") != SCHEMA:
        raise DataError(f"{path}: schema is not {SCHEMA!r}")
    return reg


def select_names(names: Iterable[str] | None, what: str, valid: Iterable[str]) -> list[str]:
    """The names asked for, checked against the valid ones.

    Parameters
    ----------
    names : iterable of str or None
        The names asked for; None: every valid name.
    what : str
        What they name, for the message ("fixture").
    valid : iterable of str
        The valid names.

    Returns
    -------
    list of str
        ``names`` in the order given, or every valid name in its order.

    Raises
    ------
    ConfigError
        ``unknown WHAT 'NAME'; valid: ...`` for the first unknown name.
    """
    valid = list(valid)
    if names is None:
        return valid
    out = list(names)
    for n in out:
        if n not in valid:
            raise ConfigError(f"unknown {what} {n!r}; valid: {', '.join(valid)}")
    return out
