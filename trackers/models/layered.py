"""Layered hypothesized measurements (SHM paper §3.1): template matching per depth ordering.

For ``M`` objects there are ``L = M!`` depth orderings. Under ordering ``j`` the objects
are measured front to back: the front object by template matching (the smallest mean
squared intensity difference to its reference over a search window), then its pixels are
masked and the next object is matched ignoring masked pixels, and so on. This yields the
hypothesized measurements ``y^j`` (one centre per object) and their squared-difference
means ``e^{j,m}``. Objects that do not come close give the same measurement under every
ordering and are matched once (see ``trackers.kernels.template``).

Templates and supports (**open** in the paper, chosen here): the reference of object
``m`` is the frame-0 image inside its initial box (rounded to whole pixels). Its *support*
— the pixels that are compared, and that mask the objects behind once matched — is set by
``support``:

- ``"box"``: every pixel of the box;
- ``"ellipse"``: the ellipse inscribed in the box (tested at pixel centres), which drops
  the background corners of round objects.

Pre-smoothing (**open**): the frame (and so the templates) can be blurred with a Gaussian
of std ``blur`` pixels before matching. A small blur makes the squared difference tolerant
of the small rotations and of fine periodic textures (checkers, stripes) that otherwise
give several near-equal minima.

Cost: each search compares ``(2 r + 1)²`` candidates (about ``((2 r) / step + 1)²`` plus
``(2 step − 1)²`` with the coarse-to-fine search) of ``|support|`` pixels; the number of
searches per frame is ``M`` when no objects are close and at most ``M · M!`` (96 for
``M = 4``), which is why exhaustive orderings stop at ``MAX_OBJECTS = 4``.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from trackers.kernels.template import layered_match

__all__ = [
    "MAX_OBJECTS",
    "SUPPORTS",
    "LayeredMatcher",
    "LayeredMeasurement",
    "check_matcher_params",
    "orderings",
]

MAX_OBJECTS = 4
SUPPORTS = ("box", "ellipse")


def orderings(n_objects: int) -> NDArray[np.int16]:
    """All depth orderings of ``n_objects`` objects, shape (n!, n), int16.

    Row ``j`` lists object indices nearest first; rows are in lexicographic order, so
    row 0 is the identity (object 0 in front).

    Parameters
    ----------
    n_objects : int
        Number of objects n, in [1, ``MAX_OBJECTS``].

    Returns
    -------
    ndarray of int16, shape (n!, n)
        One ordering per row.

    Raises
    ------
    ValueError
        If ``n_objects`` is below 1 or above ``MAX_OBJECTS``.

    Examples
    --------
    >>> orderings(3).tolist()
    [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]]
    """
    if n_objects < 1:
        raise ValueError(f"need at least 1 object for depth orderings, got {n_objects}")
    if n_objects > MAX_OBJECTS:
        raise ValueError(
            f"{n_objects} objects give {math.factorial(n_objects)} depth orderings; exhaustive "
            f"orderings support at most {MAX_OBJECTS} objects: split the targets into groups "
            f"of at most {MAX_OBJECTS} and run one tracker per group"
        )
    return np.array(list(itertools.permutations(range(n_objects))), dtype=np.int16)


@dataclass
class LayeredMeasurement:
    """The hypothesized measurements of one frame.

    Attributes
    ----------
    centres : ndarray of shape (L, M, 2)
        Measured centre (x, y) of object m under ordering l; NaN for a missed measurement.
    mse : ndarray of shape (L, M)
        Mean squared difference per channel (intensity², 0..255²) of each match; NaN if
        missed.
    counts : ndarray of shape (L, M)
        Pixels compared by each match (unmasked, inside the frame); 0 if missed.
    n_searches : int
        Template searches run (orderings that cannot differ share their searches).
    """

    centres: NDArray[np.float64]
    mse: NDArray[np.float64]
    counts: NDArray[np.int64]
    n_searches: int


class LayeredMatcher:
    """Masked mean-squared-difference template matcher for ``M`` objects.

    Parameters
    ----------
    frame : ndarray of shape (H, W, 3), uint8
        The frame the templates are cut from.
    boxes : ndarray of shape (M, 4)
        One box [x, y, w, h] per object; rounded to whole pixels.
    search_radius : int
        Half-size of the search window in pixels: candidates lie within ±``search_radius``
        of the predicted position in x and in y.
    step : int
        Coarse-to-fine stride (1 = exhaustive search).
    min_visible : float
        In (0, 1]: smallest fraction of a template's support that a candidate must compare
        (inside the frame and unmasked); fewer is a missed measurement.
    support : {"box", "ellipse"}
        Template support, see the module docstring.
    blur : float
        Std in pixels of the Gaussian pre-smoothing of frames and templates (0 = none).

    Attributes
    ----------
    templates : ndarray of shape (M, TH, TW, 3), uint8
        Reference images (blurred if ``blur`` > 0), padded to the largest box.
    support : ndarray of shape (M, TH, TW), bool
        Support of each template (False in the padding).
    sizes : ndarray of shape (M, 2), int64
        Template (height, width): the box's part inside frame 0.

    Examples
    --------
    >>> import numpy as np
    >>> frame = np.random.default_rng(0).integers(0, 256, (60, 80, 3), dtype=np.uint8)
    >>> matcher = LayeredMatcher(frame, [[10, 10, 16, 16], [40, 20, 16, 16]], step=1)
    >>> meas = matcher.measure(frame, [[18, 18], [48, 28]], orderings(2))
    >>> meas.centres[0].tolist(), meas.n_searches
    ([[18.0, 18.0], [48.0, 28.0]], 2)
    """

    def __init__(
        self,
        frame: NDArray[np.uint8],
        boxes: ArrayLike,
        *,
        search_radius: int = 10,
        step: int = 2,
        min_visible: float = 0.25,
        support: str = "box",
        blur: float = 0.0,
    ) -> None:
        check_matcher_params(search_radius, step, min_visible, support, blur)
        self.blur = float(blur)
        frame = self._smooth(frame)
        b = np.asarray(boxes, dtype=np.float64).reshape(-1, 4)
        m = b.shape[0]
        h, w = frame.shape[:2]
        tl = np.round(b[:, :2]).astype(np.int64)
        size = np.maximum(np.round(b[:, 2:]).astype(np.int64), 1)  # (w, h)
        # A box that overlaps the frame by less than a pixel can round to a template wholly
        # outside it; moving the rounded corner by under a pixel keeps one row/column in,
        # so every template has at least one pixel inside the frame.
        tl[:, 0] = np.clip(tl[:, 0], 1 - size[:, 0], w - 1)
        tl[:, 1] = np.clip(tl[:, 1], 1 - size[:, 1], h - 1)
        # Template pixels outside frame 0 have no reference and are never in the support,
        # so each template is cut to its part inside frame 0 (the box's rows r0:r1 and
        # columns c0:c1): the same matches, and memory bounded by the frame's size
        # whatever the box's.
        r0 = np.maximum(0, -tl[:, 1])
        r1 = np.minimum(size[:, 1], h - tl[:, 1])
        c0 = np.maximum(0, -tl[:, 0])
        c1 = np.minimum(size[:, 0], w - tl[:, 0])
        cut = np.stack([r1 - r0, c1 - c0], axis=1).astype(np.int64)  # (h, w)
        th_max, tw_max = int(cut[:, 0].max()), int(cut[:, 1].max())
        self.templates = np.zeros((m, th_max, tw_max, 3), dtype=np.uint8)
        self.support = np.zeros((m, th_max, tw_max), dtype=bool)
        self.sizes = cut
        for k in range(m):
            th, tw = int(cut[k, 0]), int(cut[k, 1])
            x0, y0 = int(tl[k, 0] + c0[k]), int(tl[k, 1] + r0[k])
            sup = _support_mask(support, int(size[k, 1]), int(size[k, 0]),
                                (int(r0[k]), int(r1[k])), (int(c0[k]), int(c1[k])))
            # A sliver box whose shape support misses the frame falls back to its box pixels.
            self.templates[k, :th, :tw] = frame[y0:y0 + th, x0:x0 + tw]
            self.support[k, :th, :tw] = sup if sup.any() else True
        tl += np.stack([c0, r0], axis=1)
        self._n_support = self.support.sum(axis=(1, 2))
        # Measured centre = initial box centre + displacement of the matched top-left.
        self._tl0 = tl
        self._centre0 = b[:, :2] + b[:, 2:] / 2
        self.n_objects = m
        self.search_radius = int(search_radius)
        self.step = int(step)
        self.min_visible = float(min_visible)
        self._frame_hw = (h, w)
        self._buffer: NDArray[np.uint8] | None = None

    def measure(
        self,
        frame: NDArray[np.uint8],
        centres: ArrayLike,
        order: NDArray[np.integer],
        *,
        masking: bool = True,
    ) -> LayeredMeasurement:
        """Match every object under every ordering of ``order`` in one kernel call.

        An object predicted to have less than ``min_visible`` of its support inside the
        frame is not searched (it has left): its measurement is missed under every
        ordering, so a window at the border cannot lock onto the background there.

        Parameters
        ----------
        frame : ndarray of shape (H, W, 3), uint8
            The current frame, of the shape of the one the templates were cut from
            (blurred here if ``blur`` > 0).
        centres : array_like of shape (M, 2)
            Predicted centre (x, y) of each object: the middle of its search window, in px
            (rounded to whole pixels; a NaN centre searches around the object's position
            in the template frame).
        order : ndarray of shape (L, M)
            Orderings, nearest first (``orderings(M)``, or one row for plain matching).
        masking : bool, default True
            Mask the pixels of the objects matched in front (False: every object is
            matched on the unmasked frame).

        Returns
        -------
        LayeredMeasurement
            ``centres`` (L, M, 2) in px, ``mse`` (L, M), ``counts`` (L, M) and
            ``n_searches``: one row per row of ``order``.
        """
        c = np.asarray(centres, dtype=np.float64).reshape(self.n_objects, 2)
        h, w = self._frame_hw
        shift = np.round(c - self._centre0)
        # A prediction that ran far outside the frame keeps its window at the border, where
        # the object would re-enter.
        shift = np.nan_to_num(shift, nan=0.0)
        origin = self._tl0 + shift.astype(np.int64)
        lim = self.search_radius + 1
        origin[:, 0] = np.clip(origin[:, 0], -self.sizes[:, 1] - lim, w + lim)
        origin[:, 1] = np.clip(origin[:, 1], -self.sizes[:, 0] - lim, h + lim)
        active = self._inside_fraction(origin) >= self.min_visible
        frame = self._smooth_windows(frame, origin, active)
        rows = np.ascontiguousarray(order, dtype=np.int64)
        n_order = rows.shape[0]
        pos = np.zeros((n_order, self.n_objects, 2), dtype=np.int64)
        mse = np.empty((n_order, self.n_objects), dtype=np.float64)
        counts = np.zeros((n_order, self.n_objects), dtype=np.int64)
        n = layered_match(
            frame, self.templates, self.support, self.sizes, origin, active,
            self.search_radius, self.step, rows, masking, self.min_visible, pos, mse, counts,
        )
        out = self._centre0[None] + (pos - self._tl0[None]).astype(np.float64)
        out[np.isnan(mse)] = np.nan
        return LayeredMeasurement(centres=out, mse=mse, counts=counts, n_searches=int(n))

    def _inside_fraction(self, origin: NDArray[np.int64]) -> NDArray[np.float64]:
        """Fraction of each support inside the frame with its top-left at ``origin``."""
        h, w = self._frame_hw
        out = np.zeros(self.n_objects)
        for k in range(self.n_objects):
            x, y = int(origin[k, 0]), int(origin[k, 1])
            th, tw = int(self.sizes[k, 0]), int(self.sizes[k, 1])
            r0, r1 = max(0, -y), max(0, min(th, h - y))
            c0, c1 = max(0, -x), max(0, min(tw, w - x))
            out[k] = self.support[k, r0:r1, c0:c1].sum() / self._n_support[k]
        return out

    def _smooth(self, frame: NDArray[np.uint8]) -> NDArray[np.uint8]:
        if self.blur <= 0:
            return frame
        return cv2.GaussianBlur(frame, (0, 0), self.blur, borderType=cv2.BORDER_REPLICATE)

    def _smooth_windows(
        self, frame: NDArray[np.uint8], origin: NDArray[np.int64], active: NDArray[np.bool_]
    ) -> NDArray[np.uint8]:
        """The frame blurred inside the search windows of the active objects.

        Only the windows are read by the kernel, so only they are blurred: each window is
        cut with a margin wider than the Gaussian's support (so its inside equals the
        whole-frame blur, which replicates the frame's own border the same way) and
        written into a buffer; pixels outside every window are left stale.
        """
        if self.blur <= 0:
            return frame
        h, w = self._frame_hw
        if self._buffer is None:
            self._buffer = np.zeros((h, w, 3), dtype=np.uint8)
        out = self._buffer
        r = self.search_radius
        pad = int(np.ceil(4 * self.blur)) + 1
        for k in np.flatnonzero(active):
            x0, y0 = int(origin[k, 0]) - r, int(origin[k, 1]) - r
            x1, y1 = x0 + int(self.sizes[k, 1]) + 2 * r, y0 + int(self.sizes[k, 0]) + 2 * r
            cx0, cy0 = max(x0 - pad, 0), max(y0 - pad, 0)
            cx1, cy1 = min(x1 + pad, w), min(y1 + pad, h)
            if cx0 >= cx1 or cy0 >= cy1:
                continue
            crop = cv2.GaussianBlur(
                frame[cy0:cy1, cx0:cx1], (0, 0), self.blur, borderType=cv2.BORDER_REPLICATE
            )
            wx0, wy0 = max(x0, 0), max(y0, 0)
            wx1, wy1 = min(x1, w), min(y1, h)
            if wx0 < wx1 and wy0 < wy1:
                out[wy0:wy1, wx0:wx1] = crop[wy0 - cy0 : wy1 - cy0, wx0 - cx0 : wx1 - cx0]
        return out


def check_matcher_params(
    search_radius: int, step: int, min_visible: float, support: str, blur: float
) -> None:
    """Validate the matcher's parameters (shared by the trackers' constructors).

    Parameters
    ----------
    search_radius : int
        Half-size of the search window, in [1, 200] px.
    step : int
        Coarse-to-fine stride, in [1, 8].
    min_visible : float
        Smallest visible fraction of a support, in (0, 1].
    support : {"box", "ellipse"}
        Template support.
    blur : float
        Std of the Gaussian pre-smoothing, in [0, 20] px.

    Raises
    ------
    ValueError
        Naming the first bad value (``search_radius`` and ``step`` must be ints, not
        integral floats; booleans and non-finite numbers are refused).
    """
    if not _is_int(search_radius) or not 1 <= search_radius <= 200:
        raise ValueError(f"search_radius must be an int in [1, 200], got {search_radius!r}")
    if not _is_int(step) or not 1 <= step <= 8:
        raise ValueError(f"step must be an int in [1, 8], got {step!r}")
    if not 0 < _real(min_visible) <= 1:
        raise ValueError(f"min_visible must be in (0, 1], got {min_visible!r}")
    if not isinstance(support, str) or support not in SUPPORTS:
        raise ValueError(f"unknown support {support!r}; valid: {', '.join(SUPPORTS)}")
    if not 0 <= _real(blur) <= 20:
        raise ValueError(f"blur must be in [0, 20] pixels, got {blur!r}")


def _is_int(value: object) -> bool:
    """Whether ``value`` is an int (numpy's too) and not a bool (True was a radius of 1)."""
    return isinstance(value, (int, np.integer)) and not isinstance(value, bool)


def _real(value: object) -> float:
    """``value`` as a finite float, or NaN (which fails every bound) for anything else: a
    string, a list, a bool, inf."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(
        value, (int, float, np.integer, np.floating)
    ):
        return float("nan")
    x = float(value)
    return x if np.isfinite(x) else float("nan")


def _support_mask(kind: str, th: int, tw: int, rows: tuple[int, int],
                  cols: tuple[int, int]) -> NDArray[np.bool_]:
    """Rows ``rows`` and columns ``cols`` ([start, stop)) of a (th, tw) box's support."""
    (r0, r1), (c0, c1) = rows, cols
    if kind == "box":
        return np.ones((r1 - r0, c1 - c0), dtype=bool)
    yy, xx = np.mgrid[r0:r1, c0:c1]
    u = (xx + 0.5) / tw * 2 - 1
    v = (yy + 0.5) / th * 2 - 1
    m = u * u + v * v <= 1.0
    if r0 <= th // 2 < r1 and c0 <= tw // 2 < c1:
        m[th // 2 - r0, tw // 2 - c0] = True
    return m
