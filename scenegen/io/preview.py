"""Previews: a PNG contact sheet, a GIF or an MP4 with ground truth drawn on the frames.

Each entity's amodal box is drawn thin and its visible box thick, labelled with
``id:depth``; tracker estimates (``--result``) are drawn in white with a black outline.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from scenegen.errors import ConfigError
from scenegen.io import atomic_path
from scenegen.sequence import Sequence

__all__ = ["annotate", "contact_sheet", "write_preview"]

#: Frame sides (px) an MP4 preview can have: what the MPEG-4 Part 2 encoder accepts.
MP4_SIDES = (2, 8191)

_ROLE_COLORS = {
    "target": (0, 200, 0),
    "distractor": (230, 0, 0),
    "occluder": (0, 90, 255),
    "clutter": (160, 160, 160),
}


def annotate(
    seq: Sequence, t: int, *, boxes: NDArray[Any] | None = None, clutter: bool = False
) -> NDArray[np.uint8]:
    """Frame ``t`` (H, W, 3) with ground truth (and optional estimates (M, 4)) drawn.

    Each entity present at ``t`` gets its amodal box (1 px) and visible box (2 px) in its
    role's colour (targets green, distractors red, occluders blue, clutter grey), labelled
    ``id:depth``; the frame index ``t=…`` is written top left.

    Parameters
    ----------
    seq : Sequence
        The sequence.
    t : int
        Frame index, 0-based.
    boxes : ndarray of shape (M, 4), optional
        Tracker estimates ``[x, y, w, h]`` of frame ``t``, pixels, drawn white with a
        black outline; rows with a NaN are skipped.
    clutter : bool
        Whether to draw clutter entities too.

    Returns
    -------
    ndarray of uint8, shape (H, W, 3)
        The annotated RGB frame (a copy; ``seq`` is unchanged).
    """
    img = np.ascontiguousarray(np.asarray(seq.frames[t]).copy())
    gt = seq.gt
    for k in range(len(seq.entities)):
        role = str(seq.entities.role[k])
        if (role == "clutter" and not clutter) or not gt.present[t, k]:
            continue
        color = _ROLE_COLORS.get(role, (255, 255, 0))
        box = gt.box[t, k]
        p0, p1 = _corners(box, img.shape)
        cv2.rectangle(img, p0, p1, color, 1)
        vb = gt.visible_box[t, k]
        if np.all(np.isfinite(vb)):
            cv2.rectangle(img, *_corners(vb, img.shape), color, 2)
        label = f"{int(seq.entities.id[k])}:{int(gt.depth[t, k])}"
        lx, ly = (int(np.clip(v, -_LABEL_REACH, _LABEL_REACH)) for v in box[:2])
        cv2.putText(img, label, (lx, max(ly - 3, 8)), cv2.FONT_HERSHEY_SIMPLEX, 0.35,
                    color, 1, cv2.LINE_AA)  # fmt: skip
    if boxes is not None:
        for box in np.asarray(boxes, dtype=np.float64):
            if not np.all(np.isfinite(box)):
                continue
            p0, p1 = _corners(box, img.shape)
            cv2.rectangle(img, p0, p1, (0, 0, 0), 3)
            cv2.rectangle(img, p0, p1, (255, 255, 255), 1)
    cv2.putText(img, f"t={t}", (4, 12), cv2.FONT_HERSHEY_SIMPLEX, 0.4, (0, 0, 0), 3, cv2.LINE_AA)
    cv2.putText(img, f"t={t}", (4, 12), cv2.FONT_HERSHEY_SIMPLEX, 0.4, (255, 255, 0), 1,
                cv2.LINE_AA)  # fmt: skip
    return img


#: Pixels a corner may lie outside the image after clipping: more than half the thickest
#: line, so that an edge off the image stays off it.
_CLIP_MARGIN = 8
#: Where a label's origin is clipped to, pixels: far beyond any image a label could reach.
_LABEL_REACH = 1 << 20


def _corners(box: NDArray[Any], shape: tuple[int, ...]) -> tuple[tuple[int, int], tuple[int, int]]:
    """The corners ``(x0, y0), (x1, y1)`` (inclusive) of a finite ``box`` [x, y, w, h] for
    ``cv2.rectangle``, clipped to ``_CLIP_MARGIN`` pixels around an image of ``shape``:
    OpenCV takes C ``int`` points, so a box far off the image (1e30) is drawn as the same
    clipped rectangle rather than failing."""
    x, y, w, h = (float(v) for v in box)
    with np.errstate(over="ignore"):  # x + w may overflow to inf, clipped all the same
        corners = np.trunc([[x, y], [x + w, y + h]]) - [[0, 0], [1, 1]]
    hi = [shape[1] + _CLIP_MARGIN, shape[0] + _CLIP_MARGIN]
    c = np.clip(corners, -_CLIP_MARGIN, hi).astype(int)
    return (int(c[0, 0]), int(c[0, 1])), (int(c[1, 0]), int(c[1, 1]))


def contact_sheet(
    seq: Sequence, *, n: int = 12, cols: int = 4, boxes: NDArray[Any] | None = None
) -> NDArray[np.uint8]:
    """``n`` evenly spaced annotated frames tiled ``cols`` wide, shape (rows*H, cols*W, 3).

    Parameters
    ----------
    seq : Sequence
        The sequence.
    n : int
        Frames to show, first and last included (all T frames if T < n).
    cols : int
        Tiles per row (fewer if there are fewer frames).
    boxes : ndarray of shape (T, M, 4), optional
        Tracker estimates per frame, pixels (see :func:`annotate`).

    Returns
    -------
    ndarray of uint8, shape (rows*H, cols*W, 3)
        RGB sheet of :func:`annotate` tiles, row by row; the unused tiles of the last row
        are white.
    """
    t_n = seq.n_frames
    idx = np.unique(np.linspace(0, t_n - 1, min(n, t_n)).round().astype(int))
    tiles = [annotate(seq, int(t), boxes=None if boxes is None else boxes[t]) for t in idx]
    h, w = tiles[0].shape[:2]
    cols = min(cols, len(tiles))
    rows = -(-len(tiles) // cols)
    sheet = np.full((rows * h, cols * w, 3), 255, dtype=np.uint8)
    for i, tile in enumerate(tiles):
        r, c = divmod(i, cols)
        sheet[r * h : (r + 1) * h, c * w : (c + 1) * w] = tile
    return sheet


def write_preview(
    seq: Sequence, out: str | Path, *, boxes: NDArray[Any] | None = None, max_frames: int = 200
) -> None:
    """Write a preview of ``seq`` to ``out`` (.png contact sheet, .gif or .mp4 animation).

    ``boxes`` (T, M, 4): tracker estimates to draw. Animations show at most
    ``max_frames`` evenly spaced frames.

    Parameters
    ----------
    seq : Sequence
        The sequence.
    out : str or Path
        Output file, written atomically; its suffix (``.png``, ``.gif`` or ``.mp4``, any
        case) picks the kind. A PNG is :func:`contact_sheet` with its defaults; a GIF
        shows 80 ms per frame, an MP4 12.5 frames per second.
    boxes : ndarray of shape (T, M, 4), optional
        Tracker estimates per frame, pixels (see :func:`annotate`).
    max_frames : int
        Most frames of an animation (ignored for a PNG).

    Raises
    ------
    ConfigError
        For another suffix, a PNG that cannot be encoded, an MP4 whose frames are not
        2..8191 px a side (:data:`MP4_SIDES`), or an OpenCV build that cannot write MP4.
    """
    out = Path(out)
    ext = out.suffix.lower()
    if ext not in (".png", ".gif", ".mp4"):
        raise ConfigError(f"{out}: preview must be .png, .gif or .mp4, got {ext or 'no suffix'!r}")
    if ext == ".png":
        sheet = contact_sheet(seq, boxes=boxes)
        ok, data = cv2.imencode(".png", cv2.cvtColor(sheet, cv2.COLOR_RGB2BGR))
        if not ok:
            raise ConfigError(f"{out}: could not encode PNG")
        with atomic_path(out) as tmp:
            tmp.write_bytes(data.tobytes())
        return
    t_n = seq.n_frames
    idx = np.unique(np.linspace(0, t_n - 1, min(max_frames, t_n)).round().astype(int))
    frames = [annotate(seq, int(t), boxes=None if boxes is None else boxes[t]) for t in idx]
    with atomic_path(out, ext) as tmp:  # the suffix lets OpenCV pick the container
        if ext == ".gif":
            from PIL import Image

            # Fast octree quantisation without dithering: the default median cut takes
            # seconds per frame on noisy backgrounds.
            imgs = [
                Image.fromarray(f).quantize(256, method=Image.Quantize.FASTOCTREE, dither=0)
                for f in frames
            ]
            imgs[0].save(
                tmp, format="GIF", save_all=True, append_images=imgs[1:], duration=80, loop=0
            )
        else:
            h, w = frames[0].shape[:2]
            # MPEG-4 Part 2 takes sides of 2..8191 px; checked first, since the encoder
            # would print its own lines before refusing.
            if not (MP4_SIDES[0] <= w <= MP4_SIDES[1] and MP4_SIDES[0] <= h <= MP4_SIDES[1]):
                raise ConfigError(
                    f"{out}: MP4 frames must be {MP4_SIDES[0]}..{MP4_SIDES[1]} px a side, "
                    f"these are {w}x{h}; write a .gif or .png preview instead"
                )
            writer = cv2.VideoWriter(str(tmp), cv2.VideoWriter_fourcc(*"mp4v"), 12.5, (w, h))
            if not writer.isOpened():
                raise ConfigError(f"{out}: this OpenCV build cannot write MP4")
            for f in frames:
                writer.write(cv2.cvtColor(f, cv2.COLOR_RGB2BGR))
            writer.release()
