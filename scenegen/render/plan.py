"""Scenario planning and rendering: config + seed -> frames, labels and ground truth.

Data flows one way: :func:`plan` turns a config and a seed into a
:class:`Scenario` (trajectories, depths, templates: everything but pixels), and
:meth:`Scenario.render` draws any frame range of it in one compiled call. The static
layer (background, clutter and entities that never move and lie behind all others) is
drawn once.

Randomness: each entity draws from its own stream, keyed by the scenario seed and the
entity's *name*, so adding, removing or reordering other entities never changes its
trajectory or appearance. Per-frame sensor noise is keyed by the frame index, so rendering
in chunks gives the same bytes as rendering at once.

Position noise is added to the planned motion path per frame; the path itself (before the
noise) is kept as :attr:`Scenario.path_x`, :attr:`Scenario.path_y` and recorded as
``gt/path_center``.
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from scenegen.config import Background, EntitySpec, SceneConfig
from scenegen.config.messages import _short
from scenegen.errors import ConfigError
from scenegen.render import compose as kernels
from scenegen.render import photometric, textures
from scenegen.render.camera import camera_offsets, camera_zoom
from scenegen.render.draw import draw_template, jitter_colors, paint_template, transform_template
from scenegen.render.motion import ar2_path
from scenegen.sequence import Entities, GroundTruth, Sequence

__all__ = ["Chunk", "Scenario", "entity_rng", "generate", "plan", "resolve_seed"]

_SCALE_LIMITS = (0.05, 20.0)


def _key(name: str) -> int:
    return int.from_bytes(hashlib.sha256(name.encode("utf-8")).digest()[:8], "little")


def entity_rng(seed: int, name: str, *extra: int) -> np.random.Generator:
    """The random stream of component ``name`` (an entity name, ``background``, ...).

    Parameters
    ----------
    seed : int
        The scene seed.
    name : str
        The component's name; hashed (SHA-256) into the spawn key, so each component's
        stream depends on its name only, not on the other components.
    *extra : int
        Further spawn-key entries (a frame index, say): independent sub-streams.

    Returns
    -------
    numpy.random.Generator
        A new generator, the same for the same arguments.
    """
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(_key(name), *extra)))


MAX_SEED = 2**64 - 1
"""Largest scene seed: a file stores it as a 64-bit unsigned integer."""


def resolve_seed(seed: int | np.integer | None) -> int:
    """An int seed in [0, :data:`MAX_SEED`]; ``None`` draws a fresh one from the OS.

    Parameters
    ----------
    seed : int, numpy.integer or None
        The seed (not a bool).

    Returns
    -------
    int
        ``seed`` as an int; a fresh one (below 2**63) for None.

    Raises
    ------
    ConfigError
        ``"seed must be an integer in [0, 2**64 - 1], got <seed>"``.
    """
    if seed is None:
        return int(np.random.SeedSequence().generate_state(1, dtype=np.uint64)[0] >> 1)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not (
            0 <= seed <= MAX_SEED):  # fmt: skip
        raise ConfigError(f"seed must be an integer in [0, 2**64 - 1], got {_short(seed)}")
    return int(seed)


def _background(bg: Background, h: int, w: int, rng: np.random.Generator) -> NDArray[np.uint8]:
    if bg.kind == "uniform":
        out = np.empty((h, w, 3), dtype=np.uint8)
        out[:] = bg.color
        return out
    if bg.kind == "image":
        assert bg.source is not None  # validated by Background
        img = textures.load_source(bg.source, "background.source")
        tint = None if bg.color == (255, 255, 255) else bg.color
        return textures.tinted(textures.fit_image(img, w, h, bg.fit), tint)
    if bg.kind == "perlin":
        v = textures.value_noise(w, h, bg.scale, rng)
        tint = np.asarray(bg.color, dtype=np.float32) / 255.0
        out = bg.low + v[..., None] * (bg.high - bg.low) * tint
        return np.clip(np.rint(out), 0, 255).astype(np.uint8)
    noise = rng.integers(bg.low, bg.high + 1, size=(h, w, 3), dtype=np.uint8)
    if bg.kind == "noise":
        return noise
    smooth = cv2.GaussianBlur(noise.astype(np.float32), (0, 0), bg.scale)
    # Stretch the smoothed noise back to [low, high] and tint it with the colour.
    lo, hi = float(smooth.min()), float(smooth.max())
    smooth = (smooth - lo) / max(hi - lo, 1e-6)
    tint = np.asarray(bg.color, dtype=np.float32) / 255.0
    out = bg.low + smooth * (bg.high - bg.low) * tint
    return np.clip(np.rint(out), 0, 255).astype(np.uint8)


@dataclass
class Chunk:
    """Frames ``start:stop`` of a scenario with their ground truth (shapes as in
    :class:`~scenegen.sequence.GroundTruth`, with F = stop - start frames).

    Attributes
    ----------
    start : int
        Index of the first frame.
    frames : ndarray of shape (F, H, W, 3), uint8
        RGB frames.
    labels : ndarray of shape (F, H, W), uint16
        Entity id of the visible surface; 0 is the background.
    gt : dict of str to ndarray
        The :class:`~scenegen.sequence.GroundTruth` arrays by field name (``box``,
        ``visible_box``, ``center``, ``visibility``, ``present``, ``depth``,
        ``path_center``), each with F frames.
    """

    start: int
    frames: NDArray[np.uint8]
    labels: NDArray[np.uint16]
    gt: dict[str, NDArray[Any]]


@dataclass
class Scenario:
    """Everything about a sequence but its pixels.

    Attributes
    ----------
    config : SceneConfig
    seed : int
    preset : str
    names, roles : list of str (K)
    templates : list of ndarray (h, w, 4)
        Base template of each entity.
    cx, cy : ndarray of shape (T, K)
        Drawn centre (motion plus position noise) before rounding to pixels.
    path_x, path_y : ndarray of shape (T, K)
        Centre of the noise-free motion path (``cx``, ``cy`` before the position noise).
    scale, angle, shade : ndarray of shape (T, K)
        Per-frame appearance transform.
    alive : ndarray of shape (T, K), bool
    depth_value : ndarray of shape (T, K), int64
        Configured depth (smaller is nearer), clutter behind everything.
    depth_rank : ndarray of shape (T, K), int16
    in_static : ndarray of shape (K,), bool
        Entities drawn once into the static layer.
    background : ndarray of shape (H + 2 ey, W + 2 ex, 3), uint8
        The static background; (ex, ey) is the camera's extent, (0, 0) without a camera.
    cam_x, cam_y : ndarray of shape (T,), int64
        Camera offset per frame: scene point (x, y) is drawn at (x - cam_x, y - cam_y).
        ``cx``, ``cy``, ``path_x``, ``path_y`` are scene coordinates; every ground-truth
        field is in frame coordinates. With a zoom they are already frame coordinates
        (the zoom is folded into them and into ``scale``) and ``cam_x = cam_y = 0``.
    view_x, view_y : ndarray of shape (T,), int64
        The camera offset applied to the background (equal to ``cam_x``, ``cam_y``
        without a zoom).
    zoom : ndarray of shape (T,)
        Camera zoom per frame (ones without a zoom).
    gain, offset : ndarray of shape (T,)
        Global illumination per frame (``gain * pixel + offset``).
    _static_cache : tuple of ndarray or None
        The static layer, drawn on the first :meth:`render` and kept (private: leave it
        None).
    """

    config: SceneConfig
    seed: int
    preset: str
    names: list[str]
    roles: list[str]
    templates: list[NDArray[np.uint8]]
    cx: NDArray[np.float64]
    cy: NDArray[np.float64]
    path_x: NDArray[np.float64]
    path_y: NDArray[np.float64]
    scale: NDArray[np.float64]
    angle: NDArray[np.float64]
    shade: NDArray[np.float64]
    alive: NDArray[np.bool_]
    depth_value: NDArray[np.int64]
    depth_rank: NDArray[np.int16]
    in_static: NDArray[np.bool_]
    background: NDArray[np.uint8]
    cam_x: NDArray[np.int64]
    cam_y: NDArray[np.int64]
    view_x: NDArray[np.int64]
    view_y: NDArray[np.int64]
    zoom: NDArray[np.float64]
    gain: NDArray[np.float64]
    offset: NDArray[np.float64]
    _static_cache: tuple[NDArray[Any], ...] | None = field(default=None, repr=False)

    @property
    def n_frames(self) -> int:
        """Number of frames T, an int (``config.n_frames``)."""
        return self.config.n_frames

    @property
    def n_entities(self) -> int:
        """Number of entities K, an int (clutter items included)."""
        return len(self.names)

    def entities(self) -> Entities:
        """The K entities, with ids 1..K in ``names`` order.

        Returns
        -------
        Entities
            ``id`` (K,) int32 ``1..K``; ``role`` and ``name`` (K,) str arrays of
            :attr:`roles` and :attr:`names`.
        """
        k = self.n_entities
        return Entities(
            id=np.arange(1, k + 1, dtype=np.int32),
            role=np.array(self.roles, dtype=str),
            name=np.array(self.names, dtype=str),
        )

    # -- rendering ---------------------------------------------------------------------

    def _varies(self) -> NDArray[np.bool_]:
        return (
            np.any(self.scale != 1.0, axis=0)
            | np.any(self.angle != 0.0, axis=0)
            | np.any(self.shade != 1.0, axis=0)
        )

    @property
    def pad(self) -> tuple[int, int]:
        """(ex, ey): how far the background extends beyond the frame on each side."""
        bh, bw = self.background.shape[:2]
        return (bw - self.config.width) // 2, (bh - self.config.height) // 2

    @property
    def moving_camera(self) -> bool:
        """Whether the background moves under the frame, a bool (``view_x`` or
        ``view_y`` nonzero at some frame)."""
        return bool(np.any(self.view_x != 0) or np.any(self.view_y != 0))

    @property
    def zoomed(self) -> bool:
        """Whether the camera zooms, a bool (``zoom`` differs from 1 at some frame)."""
        return bool(np.any(self.zoom != 1.0))

    def background_frame(self, t: int) -> NDArray[np.uint8]:
        """The background as seen in frame ``t`` (H, W, 3): the window at the camera
        offset, resampled about the frame centre when the camera zooms.

        Parameters
        ----------
        t : int
            Frame index, ``0 <= t < T`` (negative counts from the end).

        Returns
        -------
        ndarray of shape (H, W, 3), uint8
            A new array (a copy of the window; bilinear resampling, borders reflected,
            when ``zoom[t] != 1``), without entities, illumination or noise.
        """
        h, w = self.config.height, self.config.width
        px, py = self.pad
        xs, ys = px + int(self.view_x[t]), py + int(self.view_y[t])
        z = float(self.zoom[t])
        if z == 1.0:
            return self.background[ys : ys + h, xs : xs + w].copy()
        # Frame pixel u (centre u + 1/2) shows scene point c + (u + 1/2 - c) / z.
        cx, cy = w / 2, h / 2
        m = np.array(
            [
                [1 / z, 0.0, (0.5 - cx) / z + cx + xs - 0.5],
                [0.0, 1 / z, (0.5 - cy) / z + cy + ys - 0.5],
            ]
        )
        flags = cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP
        return cv2.warpAffine(
            self.background, m, (w, h), flags=flags, borderMode=cv2.BORDER_REFLECT_101
        )

    def _static_layer(self) -> tuple[NDArray[Any], ...]:
        if self._static_cache is not None:
            return self._static_cache
        h, w = self.background.shape[:2]
        px, py = self.pad
        rgb = self.background.copy()
        lab = np.zeros((h, w), dtype=np.uint16)
        k_n = self.n_entities
        tidx = np.full(k_n, -1, dtype=np.int64)
        x0 = np.zeros(k_n, dtype=np.int64)
        y0 = np.zeros(k_n, dtype=np.int64)
        static = np.flatnonzero(self.in_static)
        tbuf, toff, th, tw = _pack([self.templates[k] for k in static])
        for k in static[np.argsort(-self.depth_value[0, static], kind="stable")]:
            i = int(np.searchsorted(static, k))
            tidx[k] = i
            x0[k], y0[k] = _top_left(self.cx[0, k], self.cy[0, k], tw[i], th[i])
            x0[k] += px
            y0[k] += py
            kernels.paint(rgb, lab, tbuf, toff[i], th[i], tw[i], x0[k], y0[k], k + 1)
        box = np.zeros((k_n, 4), dtype=np.int64)
        count = np.zeros(k_n, dtype=np.int64)
        kernels.scan_static(lab, tidx, x0, y0, th, tw, box, count)
        self._static_cache = (rgb, lab, box, count)
        return self._static_cache

    def render(self, start: int = 0, stop: int | None = None) -> Chunk:
        """Render frames ``start:stop`` with their ground truth.

        The first call draws the static layer and keeps it; any split of the frames into
        ranges gives the same bytes as one call.

        Parameters
        ----------
        start : int, default 0
            First frame (``0 <= start < stop``).
        stop : int, optional
            End frame, exclusive (``<= T``); None: T.

        Returns
        -------
        Chunk
            The F = stop - start frames (F, H, W, 3) uint8, labels (F, H, W) uint16 and
            ground-truth arrays (F, K, ...) of the range.

        Raises
        ------
        ValueError
            If the range is empty or outside ``0:T``.
        """
        t_n = self.n_frames
        stop = t_n if stop is None else stop
        if not 0 <= start < stop <= t_n:
            raise ValueError(f"frame range {start}:{stop} is outside 0:{t_n}")
        f_n, k_n = stop - start, self.n_entities
        h, w = self.config.height, self.config.width
        s_rgb, s_lab, s_box, s_count = self._static_layer()
        varies = self._varies()

        templates: list[NDArray[np.uint8]] = list(self.templates)
        tidx = np.full((f_n, k_n), -1, dtype=np.int64)
        base_idx = np.arange(k_n, dtype=np.int64)
        for f in range(f_n):
            t = start + f
            tidx[f] = np.where(self.alive[t], base_idx, -1)
            for k in np.flatnonzero(varies & self.alive[t]):
                templates.append(
                    transform_template(
                        self.templates[k],
                        scale=float(self.scale[t, k]),
                        angle=float(self.angle[t, k]),
                        shade=float(self.shade[t, k]),
                    )
                )
                tidx[f, k] = len(templates) - 1
        tbuf, toff, th, tw = _pack(templates)
        safe = np.maximum(tidx, 0)
        x0 = np.floor(self.cx[start:stop] - tw[safe] / 2 + 0.5).astype(np.int64)
        y0 = np.floor(self.cy[start:stop] - th[safe] / 2 + 0.5).astype(np.int64)
        moving = self.config.camera is not None
        if moving:
            x0 -= self.cam_x[start:stop, None]
            y0 -= self.cam_y[start:stop, None]
        # Alive and overlapping the frame.
        inside = (x0 < w) & (y0 < h) & (x0 + tw[safe] > 0) & (y0 + th[safe] > 0)
        present = (tidx >= 0) & inside
        _drop_shapes_outside(present, templates, tidx, x0, y0, h, w)
        tidx = np.where(present, tidx, -1)

        dyn = np.flatnonzero(~self.in_static)
        order = np.full((f_n, max(len(dyn), 1)), -1, dtype=np.int64)
        if len(dyn):
            dv = self.depth_value[start:stop][:, dyn]
            order[:, : len(dyn)] = dyn[np.argsort(-dv, axis=1, kind="stable")]

        out_rgb = np.empty((f_n, h, w, 3), dtype=np.uint8)
        out_lab = np.empty((f_n, h, w), dtype=np.uint16)
        is_static = self.in_static
        if moving:
            # The static layer moves under the frame: crop it per frame and rescan the
            # static entities' visible statistics in the cropped labels.
            px, py = self.pad
            for f in range(f_n):
                if self.zoomed:  # nothing is static: the background alone, resampled
                    out_rgb[f] = self.background_frame(start + f)
                    out_lab[f] = 0
                    continue
                ys, xs = py + self.view_y[start + f], px + self.view_x[start + f]
                out_rgb[f] = s_rgb[ys : ys + h, xs : xs + w]
                out_lab[f] = s_lab[ys : ys + h, xs : xs + w]
            is_static = np.zeros_like(self.in_static)
        else:
            out_rgb[:] = s_rgb
            out_lab[:] = s_lab
        out_box = np.zeros((f_n, k_n, 4), dtype=np.int64)
        out_count = np.zeros((f_n, k_n), dtype=np.int64)
        kernels.render_chunk(
            tbuf, toff, th, tw, order, tidx, x0, y0,
            is_static, s_box, s_count, out_rgb, out_lab, out_box, out_count,
        )  # fmt: skip
        self._photometric(start, out_rgb, out_lab, tidx, out_box, out_count)
        if self.config.sensor_noise > 0:
            for f in range(f_n):
                rng = entity_rng(self.seed, "sensor", start + f)
                # frame + N(0, 1) * sigma, rounded and clipped (in place: same bytes).
                noisy = rng.standard_normal((h, w, 3))
                noisy *= self.config.sensor_noise
                noisy += out_rgb[f]
                np.rint(noisy, out=noisy)
                np.clip(noisy, 0, 255, out=noisy)
                out_rgb[f] = noisy
        p = self.config.photometric
        if p is not None and p.jpeg_quality is not None:
            for f in range(f_n):
                out_rgb[f] = photometric.jpeg(out_rgb[f], p.jpeg_quality)

        gt = _ground_truth(tidx, x0, y0, th, tw, toff, tbuf, out_box, out_count)
        gt["depth"] = self.depth_rank[start:stop].copy()
        path = np.stack([self.path_x[start:stop], self.path_y[start:stop]], axis=-1)
        if moving:
            path -= np.stack([self.cam_x[start:stop], self.cam_y[start:stop]], axis=-1)[:, None]
        path[~gt["present"]] = np.nan
        gt["path_center"] = path.astype(np.float32)
        return Chunk(start=start, frames=out_rgb, labels=out_lab, gt=gt)

    def _photometric(self, start, rgb, lab, tidx, vbox, vcount) -> None:
        """Motion blur of the moving entities, then the illumination, in place on frames
        ``start:start+F``; labels and visible statistics (of the sharp silhouettes) are
        read, never changed."""
        p = self.config.photometric
        if p is None:
            return
        f_n = rgb.shape[0]
        if p.motion_blur > 0:
            vx, vy = self.image_velocity()
            for f in range(f_n):
                t = start + f
                for k in np.flatnonzero((tidx[f] >= 0) & (vcount[f] > 0) & ~self.in_static):
                    box = (
                        int(vbox[f, k, 0]), int(vbox[f, k, 1]),
                        int(vbox[f, k, 2]), int(vbox[f, k, 3]),
                    )  # fmt: skip
                    photometric.motion_blur(
                        rgb[f], lab[f], k + 1, box, (vx[t, k], vy[t, k]), p.motion_blur
                    )
        for f in range(f_n):
            g, o = float(self.gain[start + f]), float(self.offset[start + f])
            if g != 1.0 or o != 0.0:
                rgb[f] = photometric.illuminate(rgb[f], g, o)

    def image_velocity(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Velocity (T, K) of every entity in frame coordinates, pixels per frame (the
        backward difference; frame 0 takes frame 1's).

        Computed from the drawn centres ``cx``, ``cy`` (position noise included) minus
        the camera offset.

        Returns
        -------
        vx, vy : ndarray of shape (T, K), float64
            Horizontal and vertical velocity (px/frame); zeros when T = 1.
        """
        x = self.cx - self.cam_x[:, None]
        y = self.cy - self.cam_y[:, None]
        vx, vy = np.zeros_like(x), np.zeros_like(y)
        if x.shape[0] > 1:
            vx[1:], vy[1:] = np.diff(x, axis=0), np.diff(y, axis=0)
            vx[0], vy[0] = vx[1], vy[1]
        return vx, vy

    def chunks(self, size: int = 64) -> Iterator[Chunk]:
        """Render the whole scenario in chunks of ``size`` frames (bounded memory).

        Parameters
        ----------
        size : int, default 64
            Frames per chunk, >= 1 (the last chunk may be shorter).

        Returns
        -------
        iterator of Chunk
            ``render(start, min(start + size, T))`` for ``start = 0, size, 2 size, ...``,
            each rendered when the iterator reaches it.

        Raises
        ------
        ValueError
            If ``size`` is not an integer >= 1 (at the call, not at the first chunk).
        """
        if isinstance(size, bool) or not isinstance(size, (int, np.integer)) or size < 1:
            raise ValueError(f"size must be an integer >= 1, got {size!r}")
        step = int(size)
        return (self.render(start, min(start + step, self.n_frames))
                for start in range(0, self.n_frames, step))

    def template_images(self) -> dict[int, NDArray[np.uint8]]:
        """Each entity's base template (RGBA), keyed by id.

        Returns
        -------
        dict of int to ndarray of shape (h, w, 4), uint8
            :attr:`templates` (not copies) keyed by ids 1..K.
        """
        return {k + 1: tpl for k, tpl in enumerate(self.templates)}


def _top_left(cx: float, cy: float, tw: int, th: int) -> tuple[int, int]:
    return int(np.floor(cx - tw / 2 + 0.5)), int(np.floor(cy - th / 2 + 0.5))


def _drop_shapes_outside(present: NDArray[np.bool_], templates: list[NDArray[np.uint8]],
                         tidx: NDArray[np.int64], x0: NDArray[np.int64],
                         y0: NDArray[np.int64], h: int, w: int) -> None:
    """Clear ``present`` (F, K) where only the transparent part of a template (its
    rectangle's corners around an ellipse, say) overlaps the frame: an entity is present
    when one of its shape's pixels (alpha > 0) is inside the frame. ``templates`` (RGBA),
    ``tidx``, ``x0``, ``y0`` (F, K) as in :meth:`Plan.render`."""
    th = np.array([t.shape[0] for t in templates], dtype=np.int64)
    tw = np.array([t.shape[1] for t in templates], dtype=np.int64)
    safe = np.maximum(tidx, 0)
    partial = present & ((x0 < 0) | (y0 < 0) | (x0 + tw[safe] > w) | (y0 + th[safe] > h))
    for f, k in zip(*np.nonzero(partial), strict=True):
        i, x, y = int(tidx[f, k]), int(x0[f, k]), int(y0[f, k])
        alpha = templates[i][max(0, -y) : min(int(th[i]), h - y),
                             max(0, -x) : min(int(tw[i]), w - x), 3]  # fmt: skip
        if not alpha.any():
            present[f, k] = False


def _pack(
    templates: list[NDArray[np.uint8]],
) -> tuple[NDArray[np.uint8], NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    th = np.array([t.shape[0] for t in templates], dtype=np.int64)
    tw = np.array([t.shape[1] for t in templates], dtype=np.int64)
    sizes = th * tw * 4
    toff = np.zeros(len(templates), dtype=np.int64)
    if len(templates) > 1:
        toff[1:] = np.cumsum(sizes)[:-1]
    tbuf = (
        np.concatenate([np.ascontiguousarray(t).ravel() for t in templates])
        if templates
        else np.zeros(0, dtype=np.uint8)
    )
    return tbuf, toff, th, tw


def _ground_truth(tidx, x0, y0, th, tw, toff, tbuf, vbox, vcount) -> dict[str, NDArray[Any]]:
    present = tidx >= 0
    safe = np.maximum(tidx, 0)
    w = tw[safe].astype(np.float32)
    h = th[safe].astype(np.float32)
    box = np.stack([x0.astype(np.float32), y0.astype(np.float32), w, h], axis=-1)
    box[~present] = np.nan
    center = np.stack([box[..., 0] + w / 2, box[..., 1] + h / 2], axis=-1)
    alpha_count = np.array(
        [
            np.count_nonzero(tbuf[o + 3 : o + 4 * hh * ww : 4])
            for o, hh, ww in zip(toff, th, tw, strict=True)
        ],
        dtype=np.float64,
    )
    amodal = np.where(present, alpha_count[safe], 1.0)
    visibility = np.where(present, vcount / amodal, 0.0).astype(np.float32)
    vb = np.stack(
        [
            vbox[..., 0],
            vbox[..., 1],
            vbox[..., 2] + 1 - vbox[..., 0],
            vbox[..., 3] + 1 - vbox[..., 1],
        ],
        axis=-1,
    ).astype(np.float32)
    vb[vcount == 0] = np.nan
    return {
        "box": box,
        "visible_box": vb,
        "center": center.astype(np.float32),
        "visibility": visibility,
        "present": present,
    }


# ---------------------------------------------------------------------------------------
# Planning


def _entity_plan(
    e: EntitySpec,
    cfg: SceneConfig,
    seed: int,
    tpl: NDArray[np.uint8],
    start: tuple[float, float],
    where: str = "entity",
) -> tuple[NDArray[np.float64], ...]:
    """Trajectory (T,) x, y, scale, angle, shade, path x, path y of one entity from its own
    stream; x, y include the position noise, path x, path y do not. ``where`` names the
    entity in errors (``entities[0]``): a runaway AR2 path is a ConfigError naming its
    field (:func:`~scenegen.render.motion.ar2_path`)."""
    t_n = cfg.n_frames
    rng = entity_rng(seed, e.name, 1)
    th, tw = tpl.shape[:2]
    if e.motion is None:
        x = np.full(t_n, start[0])
        y = np.full(t_n, start[1])
        s = np.zeros(t_n)
    else:
        m = e.motion
        x = ar2_path(
            m.x, start[0], m.velocity[0], t_n, rng=rng,
            lo=m.x.margin + tw / 2, hi=cfg.width - m.x.margin - tw / 2,
            field=f"{where}.motion.x",
        )  # fmt: skip
        y = ar2_path(
            m.y, start[1], m.velocity[1], t_n, rng=rng,
            lo=m.y.margin + th / 2, hi=cfg.height - m.y.margin - th / 2,
            field=f"{where}.motion.y",
        )  # fmt: skip
        if m.scale is not None:
            lim = m.scale.margin if m.scale.margin > 0 else np.inf
            s = ar2_path(
                m.scale, 0.0, 0.0, t_n, rng=rng, lo=-lim, hi=lim, field=f"{where}.motion.scale"
            )
        else:
            s = np.zeros(t_n)
    path_x, path_y = x, y
    if e.position_noise > 0:
        noise = rng.standard_normal((t_n, 2)) * e.position_noise
        x = x + noise[:, 0]
        y = y + noise[:, 1]
    t = np.arange(t_n, dtype=np.float64)
    if e.variation is not None:
        v = e.variation
        phase = np.sin(2 * np.pi * t / v.period + v.phase)
        angle = v.rotation * phase
        shade = 1.0 + v.shading * phase
    else:
        angle = np.zeros(t_n)
        shade = np.ones(t_n)
    # exp of a log scale beyond +-50 would overflow; the limits clip it anyway.
    scale = np.clip(np.exp(np.clip(s, -50.0, 50.0)), *_SCALE_LIMITS)
    return x, y, scale, angle, shade, path_x, path_y


def _clutter(cfg: SceneConfig, seed: int) -> list[tuple[str, NDArray[np.uint8], float, float]]:
    items = []
    for i, spec in enumerate(cfg.clutter):
        rng = entity_rng(seed, f"clutter:{spec.name}")
        n = spec.count
        if spec.region is None:
            rx, ry, rw, rh = 0.0, 0.0, float(cfg.width), float(cfg.height)
        else:
            rx, ry, rw, rh = spec.region
        bw, bh = spec.appearance.size
        lo = spec.min_size if spec.min_size > 0 else min(bw, bh)
        frac = rng.uniform(lo / min(bw, bh), 1.0, size=n)
        pal = np.asarray(spec.palette, dtype=np.uint8)
        cols = rng.integers(0, len(pal), size=(n, spec.n_colors))
        if spec.placement == "grid":
            g = int(np.ceil(np.sqrt(n))) if n else 1
            gx, gy = np.meshgrid(np.arange(g), np.arange(g))
            cell_w, cell_h = rw / g, rh / g
            cx = rx + (gx.ravel()[:n] + rng.uniform(0.2, 0.8, n)) * cell_w
            cy = ry + (gy.ravel()[:n] + rng.uniform(0.2, 0.8, n)) * cell_h
        else:
            cx = rx + rng.uniform(0, rw, n)
            cy = ry + rng.uniform(0, rh, n)
        app = spec.appearance
        textured = app.pattern in ("image", "perlin")
        for j in range(n):
            size = (max(1, int(round(bw * frac[j]))), max(1, int(round(bh * frac[j]))))
            if textured:
                item = app
                if app.pattern == "perlin":  # an image has no colours
                    colors = tuple(tuple(int(v) for v in c) for c in pal[cols[j]])
                    item = replace(app, colors=colors)
                tpl = draw_template(
                    item, rng=rng, size=size,
                    field=f"clutter[{i}].appearance",
                )  # fmt: skip
                items.append((f"{spec.name}-{j}", tpl, float(cx[j]), float(cy[j])))
                continue
            tpl = paint_template(
                app.shape, app.pattern, size[0], size[1], pal[cols[j]],
                stripe_width=app.stripe_width, texture_sigma=app.texture_sigma, rng=rng,
            )  # fmt: skip
            items.append((f"{spec.name}-{j}", tpl, float(cx[j]), float(cy[j])))
    return items


_Path = tuple[NDArray[np.float64], ...]  # (T,) x, y, scale, angle, shade, path x, path y


def _entity_paths(
    cfg: SceneConfig, seed: int
) -> tuple[dict[str, NDArray[np.uint8]], dict[str, _Path]]:
    """Template and trajectory of every configured entity, by name.

    Targets (and anything not mimicking) come first: a mimic starts where its model is at
    the mimic's appear frame, and its own motion starts there.
    """
    t_n = cfg.n_frames
    by_name = {e.name: e for e in cfg.entities}
    templates: dict[str, NDArray[np.uint8]] = {}
    paths: dict[str, _Path] = {}
    index = {e.name: i for i, e in enumerate(cfg.entities)}
    for e in sorted(cfg.entities, key=lambda e: e.mimic is not None):
        app_rng = entity_rng(seed, e.name, 0)
        app = e.appearance
        where = f"entities[{index[e.name]}].appearance"
        if e.mimic is not None:
            app = jitter_colors(by_name[e.mimic].appearance, e.color_jitter, rng=app_rng)
            where = f"entities[{index[e.mimic]}].appearance"
        tpl = draw_template(app, rng=app_rng, field=where)
        templates[e.name] = tpl
        if e.position is not None:
            start = (float(e.position[0]), float(e.position[1]))
        else:
            mx, my = paths[e.mimic][0], paths[e.mimic][1]
            t0 = min(e.appear, t_n - 1)
            start = (mx[t0] + e.mimic_offset[0], my[t0] + e.mimic_offset[1])
        path = _entity_plan(e, cfg, seed, tpl, start, f"entities[{index[e.name]}]")
        if e.position is None and e.appear > 0:
            path = tuple(_delayed(arr, e.appear) for arr in path)
        paths[e.name] = path
    return templates, paths


def _delayed(arr: NDArray[np.float64], appear: int) -> NDArray[np.float64]:
    """``arr`` starting at frame ``appear`` (held at its first value before)."""
    out = np.empty_like(arr)
    shift = min(appear, arr.shape[0])  # at or past the end: held at its first value
    out[shift:] = arr[: arr.shape[0] - shift]
    out[:shift] = arr[0]
    return out


def _depth_values(cfg: SceneConfig, n_clutter: int) -> NDArray[np.int64]:
    """Configured depth (T, K) of every entity, then clutter behind every entity (later
    clutter items drawn over earlier ones)."""
    t_n, k_user = cfg.n_frames, len(cfg.entities)
    depth_value = np.empty((t_n, k_user + n_clutter), dtype=np.int64)
    for k, e in enumerate(cfg.entities):
        for f, d in e.depth:
            depth_value[min(f, t_n) :, k] = d
    base = (max((d for e in cfg.entities for _, d in e.depth), default=-1)) + 1
    depth_value[:, k_user:] = base + (n_clutter - 1 - np.arange(n_clutter))
    return depth_value


def _static_entities(cfg: SceneConfig, depth_value: NDArray[np.int64]) -> NDArray[np.bool_]:
    """Entities drawn once into the static layer (K,): those that never move, change or
    come and go (clutter included), and lie behind every entity that does."""
    k_user = len(cfg.entities)
    static = np.zeros(depth_value.shape[1], dtype=bool)
    for k, e in enumerate(cfg.entities):
        static[k] = (
            e.motion is None
            and e.position_noise == 0
            and e.variation is None
            and e.appear == 0
            and e.disappear is None
            and len(e.depth) == 1
        )
    static[k_user:] = True
    dyn_depth = depth_value[:, ~static]
    max_dyn = int(dyn_depth.max()) if dyn_depth.size else -1
    return static & (depth_value.min(axis=0) > max_dyn)


def _per_frame(
    cfg: SceneConfig, paths: dict[str, _Path], clutter: list[tuple[str, Any, float, float]]
) -> tuple[NDArray[Any], ...]:
    """Per-frame arrays (T, K) of the entities then the clutter items: x, y, scale,
    angle, shade, path x, path y and alive (clutter stays put, always alive)."""
    t_n, k_user = cfg.n_frames, len(cfg.entities)
    k_n = k_user + len(clutter)
    cx = np.empty((t_n, k_n))
    cy = np.empty((t_n, k_n))
    path_x = np.empty((t_n, k_n))
    path_y = np.empty((t_n, k_n))
    scale = np.ones((t_n, k_n))
    angle = np.zeros((t_n, k_n))
    shade = np.ones((t_n, k_n))
    alive = np.zeros((t_n, k_n), dtype=bool)
    for k, e in enumerate(cfg.entities):
        cx[:, k], cy[:, k], scale[:, k], angle[:, k], shade[:, k], path_x[:, k], path_y[:, k] = (
            paths[e.name]
        )
        stop = t_n if e.disappear is None else min(e.disappear, t_n)
        alive[e.appear : stop, k] = True
    for j, c in enumerate(clutter):
        cx[:, k_user + j] = path_x[:, k_user + j] = c[2]
        cy[:, k_user + j] = path_y[:, k_user + j] = c[3]
        alive[:, k_user + j] = True
    return cx, cy, scale, angle, shade, path_x, path_y, alive


def plan(config: SceneConfig, seed: int | None = None, *, preset: str = "") -> Scenario:
    """Plan a scenario: trajectories, depths, presence and templates of every entity.

    Parameters
    ----------
    config : SceneConfig
    seed : int or None
        ``None`` draws a fresh seed (recorded in the result).
    preset : str
        The preset name to record ("" if none).

    Returns
    -------
    Scenario
        Everything but the pixels; :meth:`Scenario.render` draws them.

    Raises
    ------
    ConfigError
        A seed out of [0, :data:`MAX_SEED`], an image file that is missing or unreadable,
        or an AR2 path beyond :data:`~scenegen.config.MAX_PATH` (naming the field and the
        frame).
    """
    seed = resolve_seed(seed)
    cfg = config
    templates, paths = _entity_paths(cfg, seed)
    clutter = _clutter(cfg, seed)
    names = [e.name for e in cfg.entities] + [c[0] for c in clutter]
    roles = [e.role for e in cfg.entities] + ["clutter"] * len(clutter)
    tpls = [templates[e.name] for e in cfg.entities] + [c[1] for c in clutter]
    cx, cy, scale, angle, shade, path_x, path_y, alive = _per_frame(cfg, paths, clutter)
    depth_value = _depth_values(cfg, len(clutter))
    cam_x, cam_y = camera_offsets(cfg.camera, cfg.n_frames, entity_rng(seed, "camera"))
    view_x, view_y = cam_x, cam_y
    zoom = camera_zoom(cfg.camera, cfg.n_frames, entity_rng(seed, "camera-zoom"))
    in_static = _static_entities(cfg, depth_value)
    if np.any(zoom != 1.0):
        # Fold the view into the entities: frame coordinates, scale times zoom, and
        # everything drawn per frame.
        z = zoom[:, None]
        c_x, c_y = cfg.width / 2, cfg.height / 2
        cx = c_x + z * (cx - cam_x[:, None] - c_x)
        cy = c_y + z * (cy - cam_y[:, None] - c_y)
        path_x = c_x + z * (path_x - cam_x[:, None] - c_x)
        path_y = c_y + z * (path_y - cam_y[:, None] - c_y)
        scale = scale * z
        in_static = np.zeros_like(in_static)
        cam_x, cam_y = np.zeros_like(cam_x), np.zeros_like(cam_y)
    gain, offset = photometric.illumination(
        cfg.photometric, cfg.n_frames, entity_rng(seed, "illumination")
    )
    ex, ey = cfg.camera.extent if cfg.camera is not None else (0, 0)
    return Scenario(
        config=cfg,
        seed=seed,
        preset=preset,
        names=names,
        roles=roles,
        templates=tpls,
        cx=cx,
        cy=cy,
        path_x=path_x,
        path_y=path_y,
        scale=scale,
        angle=angle,
        shade=shade,
        alive=alive,
        depth_value=depth_value,
        depth_rank=_ranks(depth_value),
        in_static=in_static,
        background=_background(
            cfg.background, cfg.height + 2 * ey, cfg.width + 2 * ex, entity_rng(seed, "background")
        ),
        cam_x=cam_x,
        cam_y=cam_y,
        view_x=view_x,
        view_y=view_y,
        zoom=zoom,
        gain=gain,
        offset=offset,
    )


def _ranks(depth_value: NDArray[np.int64]) -> NDArray[np.int16]:
    """Rank of each entity per frame (0 = nearest), computed once per distinct row."""
    t_n, k_n = depth_value.shape
    out = np.empty((t_n, k_n), dtype=np.int16)
    if t_n == 0:
        return out
    change = np.ones(t_n, dtype=bool)
    change[1:] = np.any(depth_value[1:] != depth_value[:-1], axis=1)
    starts = np.flatnonzero(change)
    for i, s in enumerate(starts):
        e = starts[i + 1] if i + 1 < len(starts) else t_n
        rank = np.empty(k_n, dtype=np.int16)
        rank[np.argsort(depth_value[s], kind="stable")] = np.arange(k_n, dtype=np.int16)
        out[s:e] = rank
    return out


def _resolve(config: SceneConfig | str | dict[str, Any]) -> tuple[SceneConfig, str]:
    from scenegen import presets
    from scenegen.config import from_dict

    if isinstance(config, SceneConfig):
        return config, ""
    if isinstance(config, str):
        return presets.get(config), config
    if isinstance(config, dict):
        return from_dict(config), ""
    raise ConfigError(
        f"expected a SceneConfig, a preset name or a dict, got {type(config).__name__}"
    )


def generate(
    config: SceneConfig | str | dict[str, Any],
    *,
    seed: int | None = None,
    frames: int | None = None,
) -> Sequence:
    """Generate a whole sequence in memory.

    Parameters
    ----------
    config : SceneConfig, str or dict
        A config, a preset name (``scenegen.presets.names()``) or plain config data.
    seed : int or None
        Same config and seed give identical bytes; ``None`` draws a fresh seed.
    frames : int, optional
        Override the number of frames.

    Returns
    -------
    Sequence
        ``frames`` (T, H, W, 3) uint8, ``labels`` (T, H, W) uint16, ``gt`` and templates.

    Raises
    ------
    ConfigError
        An unknown preset, an invalid config, ``frames`` not an integer >= 1, or a scene
        that cannot be planned (:func:`plan`).

    Examples
    --------
    >>> seq = generate("kams-a", seed=1)
    >>> seq.frames.shape
    (140, 240, 320, 3)
    """
    cfg, preset = _resolve(config)
    if frames is not None:
        if isinstance(frames, bool) or not isinstance(frames, (int, np.integer)) or frames < 1:
            raise ConfigError(f"frames must be an integer >= 1, got {_short(frames)}")
        cfg = replace(cfg, n_frames=int(frames))
    scn = plan(cfg, seed, preset=preset)
    chunk = scn.render()
    return Sequence(
        name=cfg.name,
        seed=scn.seed,
        config=cfg,
        preset=preset,
        frames=chunk.frames,
        labels=chunk.labels,
        entities=scn.entities(),
        gt=GroundTruth(**chunk.gt),
        templates=scn.template_images(),
    )
