"""Compiled (numba) hot loops of the generator: layered compositing and visible statistics.

Templates of all entities are packed into one flat RGBA buffer (``tbuf``) with per-template
offsets and sizes, so one call renders a whole chunk of frames for every entity.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["paint", "render_chunk"]


@njit(cache=True, nogil=True)
def paint(rgb, lab, tbuf, off, th, tw, x0, y0, label):  # pragma: no cover - compiled
    """Paint one template at (x0, y0) onto rgb (H, W, 3) and lab (H, W); clips at borders."""
    h, w = lab.shape
    r0 = max(0, -y0)
    r1 = min(th, h - y0)
    c0 = max(0, -x0)
    c1 = min(tw, w - x0)
    for r in range(r0, r1):
        base = off + (r * tw) * 4
        yy = y0 + r
        for c in range(c0, c1):
            p = base + c * 4
            if tbuf[p + 3] != 0:
                xx = x0 + c
                rgb[yy, xx, 0] = tbuf[p]
                rgb[yy, xx, 1] = tbuf[p + 1]
                rgb[yy, xx, 2] = tbuf[p + 2]
                lab[yy, xx] = label


@njit(cache=True, nogil=True)
def _scan_visible(lab, label, x0, y0, tw, th, out_box, out_count):  # pragma: no cover
    """Box (c_min, r_min, c_max, r_max) and count of pixels equal to ``label`` in a region."""
    h, w = lab.shape
    r0 = max(0, y0)
    r1 = min(h, y0 + th)
    c0 = max(0, x0)
    c1 = min(w, x0 + tw)
    cmin, rmin, cmax, rmax, n = w, h, -1, -1, 0
    for r in range(r0, r1):
        for c in range(c0, c1):
            if lab[r, c] == label:
                n += 1
                if c < cmin:
                    cmin = c
                if c > cmax:
                    cmax = c
                if r < rmin:
                    rmin = r
                if r > rmax:
                    rmax = r
    out_box[0] = cmin
    out_box[1] = rmin
    out_box[2] = cmax
    out_box[3] = rmax
    out_count[0] = n


@njit(cache=True, nogil=True)
def scan_static(lab, tidx, x0, y0, toff_h, toff_w, vis_box, vis_count):  # pragma: no cover
    """Visible statistics of every entity on one label image (used for the static layer)."""
    k_n = tidx.shape[0]
    box = np.empty(4, dtype=np.int64)
    cnt = np.empty(1, dtype=np.int64)
    for k in range(k_n):
        ti = tidx[k]
        if ti < 0:
            vis_count[k] = 0
            continue
        _scan_visible(lab, k + 1, x0[k], y0[k], toff_w[ti], toff_h[ti], box, cnt)
        vis_box[k, 0] = box[0]
        vis_box[k, 1] = box[1]
        vis_box[k, 2] = box[2]
        vis_box[k, 3] = box[3]
        vis_count[k] = cnt[0]


@njit(cache=True, nogil=True)
def render_chunk(
    tbuf,
    toff,
    th,
    tw,
    order,
    tidx,
    x0,
    y0,
    is_static,
    static_box,
    static_count,
    out_rgb,
    out_lab,
    out_box,
    out_count,
):  # pragma: no cover - compiled
    """Render F frames: per-frame entities back to front over the static layer, then stats.

    ``out_rgb`` and ``out_lab`` must already hold the static layer (background and
    entities that never move and lie behind every per-frame entity, drawn once), copied
    into every frame by the caller: a broadcast copy in numpy is a plain memcpy, much
    faster than an element loop here.

    Parameters
    ----------
    tbuf : (N,) uint8, toff : (NT,) int64, th, tw : (NT,) int64
        Packed RGBA templates.
    order : (F, D) int64
        Per frame, the indices of the per-frame entities back to front, padded with -1.
    tidx : (F, K) int64
        Template index per frame and entity, -1 where absent.
    x0, y0 : (F, K) int64
        Top-left corner of each entity's template.
    is_static : (K,) bool
        Entities already in the static layer.
    static_box : (K, 4) int64, static_count : (K,) int64
        Their visible statistics on the static layer.
    out_rgb : (F, H, W, 3) uint8, out_lab : (F, H, W) uint16
    out_box : (F, K, 4) int64, out_count : (F, K) int64
        Visible box (c_min, r_min, c_max, r_max) and visible pixel count per entity.
    """
    box = np.empty(4, dtype=np.int64)
    cnt = np.empty(1, dtype=np.int64)
    drawn = np.empty((order.shape[1], 4), dtype=np.int64)
    for f in range(order.shape[0]):
        n_drawn = _draw_frame(
            out_rgb[f], out_lab[f], tbuf, toff, th, tw, order[f], tidx[f], x0[f], y0[f], drawn
        )
        _frame_stats(
            out_lab[f], th, tw, tidx[f], x0[f], y0[f], is_static, static_box, static_count,
            drawn, n_drawn, out_box[f], out_count[f], box, cnt,
        )  # fmt: skip


@njit(cache=True, nogil=True)
def _draw_frame(
    rgb, lab, tbuf, toff, th, tw, order, tidx, x0, y0, drawn
):  # pragma: no cover - compiled
    """Paint one frame's per-frame entities back to front (``order``: (D,), padded with
    -1); record each painted rectangle [x0, y0, x1, y1) in ``drawn`` and return how many."""
    n_drawn = 0
    for j in range(order.shape[0]):
        k = order[j]
        if k < 0:
            break
        ti = tidx[k]
        if ti < 0:
            continue
        paint(rgb, lab, tbuf, toff[ti], th[ti], tw[ti], x0[k], y0[k], k + 1)
        drawn[n_drawn, 0] = x0[k]
        drawn[n_drawn, 1] = y0[k]
        drawn[n_drawn, 2] = x0[k] + tw[ti]
        drawn[n_drawn, 3] = y0[k] + th[ti]
        n_drawn += 1
    return n_drawn


@njit(cache=True, nogil=True)
def _frame_stats(
    lab, th, tw, tidx, x0, y0, is_static, static_box, static_count, drawn, n_drawn,
    out_box, out_count, box, cnt,
):  # pragma: no cover - compiled  # fmt: skip
    """Visible box and pixel count (``out_box`` (K, 4), ``out_count`` (K,)) of every
    entity in one frame's labels. A static entity that no per-frame entity was drawn over
    keeps its statistics on the static layer; the others are scanned."""
    for k in range(tidx.shape[0]):
        ti = tidx[k]
        if ti < 0:
            out_count[k] = 0
            continue
        bx0 = x0[k]
        by0 = y0[k]
        bx1 = bx0 + tw[ti]
        by1 = by0 + th[ti]
        if is_static[k]:
            touched = False
            for d in range(n_drawn):
                if (
                    drawn[d, 0] < bx1
                    and bx0 < drawn[d, 2]
                    and drawn[d, 1] < by1
                    and by0 < drawn[d, 3]
                ):
                    touched = True
                    break
            if not touched:
                for i in range(4):
                    out_box[k, i] = static_box[k, i]
                out_count[k] = static_count[k]
                continue
        _scan_visible(lab, k + 1, bx0, by0, tw[ti], th[ti], box, cnt)
        for i in range(4):
            out_box[k, i] = box[i]
        out_count[k] = cnt[0]
