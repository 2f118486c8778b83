"""OpenCV's single-object trackers behind the protocol, one cv2 tracker per target.

>>> import trackers.adapters
>>> tracker = trackers.adapters.opencv("MIL", rng=0)   # cv2.TrackerMIL
>>> isinstance(tracker, trackers.Tracker)
True

``opencv(name)`` looks up ``cv2.Tracker<name>`` (then ``cv2.legacy.Tracker<name>``, in
builds that have it). Keyword parameters set the fields of ``cv2.Tracker<name>_Params``
(for MIL: ``samplerSearchWinSize``, ``featureSetNumFeatures``, ...). In
opencv-python-headless 5.0 only MIL constructs without model files (DaSiamRPN, Nano and
Vit need ONNX models, passed through their Params fields); KCF, CSRT and the others ship in
opencv-contrib.

OpenCV boxes are integers: an initial box is rounded outward to whole pixels and clipped
to the frame, and grown about its centre to at least :data:`MIN_SIDE` pixels a side
(``cv2.TrackerMIL`` never returns from ``update`` on a box under 5 px, measured with
cv2 5.0); a grown box is reported with its initial size, centred where OpenCV puts it.
A cv2 error at construction or ``init`` is a ``ValueError`` naming the parameters given.
MIL's parameters are checked at construction for an ``init`` that would fail depending
on the seed (:func:`check_mil`: its negative samples are a random draw, and a draw of
none failed ``init`` for 17 seeds in 30 with ``samplerInitMaxNegNum=1``).
When a cv2 tracker reports failure its target's box is NaN for that frame
(``extras["ok"]`` says which succeeded); it keeps updating and may find the target again.
OpenCV's trackers draw from OpenCV's global random state: ``rng`` becomes a C ``int``
seed (:func:`cv2_seed`) passed to ``cv2.setRNGSeed`` at ``init``, but MIL is not
reproducible across runs even so, hence ``deterministic = False``.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np
from numpy.typing import NDArray

from trackers.base import Estimate, check_boxes, check_frame

__all__ = ["MIN_MIL_NEGATIVES", "OpenCVTracker", "check_mil", "cv2_seed", "opencv",
           "opencv_names"]

# Trackers that construct without model files in opencv-python-headless (checked in the
# suite: tests/trackers/test_adapters.py).
MIN_SIDE = 5
_NO_MODEL_FILES = ("MIL", "KCF", "CSRT", "Boosting", "MedianFlow", "TLD", "MOSSE")


def _lookup(name: str) -> tuple[Any, Any]:
    """(tracker class, Params class or None) of ``cv2.Tracker<name>``."""
    import cv2

    for ns in (cv2, getattr(cv2, "legacy", None)):
        if ns is None:
            continue
        cls = getattr(ns, f"Tracker{name}", None)
        if cls is not None and hasattr(cls, "create"):
            return cls, getattr(ns, f"Tracker{name}_Params", None)
    raise ValueError(
        f"unknown OpenCV tracker {name!r} in cv2 {cv2.__version__}; "
        f"available without model files: {', '.join(opencv_names()) or 'none'}"
    )


def opencv_names() -> list[str]:
    """OpenCV tracker names this cv2 build offers that need no model files.

    Returns
    -------
    list of str
        The names among MIL, KCF, CSRT, Boosting, MedianFlow, TLD and MOSSE (in that
        order) found as ``cv2.Tracker<name>`` or ``cv2.legacy.Tracker<name>``.
    """
    import cv2

    out = []
    for name in _NO_MODEL_FILES:
        for ns in (cv2, getattr(cv2, "legacy", None)):
            if ns is not None and hasattr(getattr(ns, f"Tracker{name}", None), "create"):
                out.append(name)
                break
    return out


class OpenCVTracker:
    """``K`` OpenCV single-object trackers of one kind, one per target.

    Parameters
    ----------
    name : str
        ``cv2.Tracker<name>``, e.g. ``"MIL"``.
    rng : numpy.random.Generator, int or None, optional
        Seed of OpenCV's global random state, set at ``init`` (:func:`cv2_seed`); None
        (the default) leaves that state alone.
    **params : Any
        Fields of ``cv2.Tracker<name>_Params``. A numeric field must be finite; one whose
        default is positive must lie in (0, ``MAX_PARAM_FACTOR`` x default], and an int
        field takes integral values only. MIL's are checked by :func:`check_mil`.

    Raises
    ------
    ValueError
        For an unknown tracker, an unknown parameter (naming the valid ones) or a value
        OpenCV rejects.
    """

    deterministic = False
    handles_occlusion = False

    def __init__(self, name: str, *, rng: np.random.Generator | int | None = None,
                 **params: Any) -> None:  # fmt: skip
        self.name = name
        self.rng = cv2_seed(rng)
        self.params = dict(params)
        self._cls, self._params_cls = _lookup(name)
        self._make()  # fail at construction on bad parameters or missing model files
        self._trackers: list[Any] = []
        self._sizes: list[tuple[float, float] | None] = []
        self._shape: tuple[int, ...] | None = None

    def _make(self) -> Any:
        import cv2

        if not self.params:
            try:
                return self._cls.create()
            except cv2.error as err:
                raise ValueError(f"cv2.Tracker{self.name}: {_cv2_message(err)}") from None
        if self._params_cls is None:
            raise ValueError(f"cv2.Tracker{self.name} takes no parameters, got {self.params}")
        p = self._params_cls()
        valid = [a for a in dir(p) if not a.startswith("_")]
        for key, value in self.params.items():
            if key not in valid:
                raise ValueError(
                    f"unknown parameter {key!r} for cv2.Tracker{self.name}; valid: "
                    f"{', '.join(valid)}"
                )
            value = _check_value(self.name, key, value, getattr(p, key))
            try:
                setattr(p, key, value)
            except (TypeError, cv2.error) as err:
                raise ValueError(
                    f"cv2.Tracker{self.name} parameter {key}={value!r}: {err}"
                ) from None
        if self.name == "MIL":
            check_mil(p)
        try:
            return self._cls.create(p)
        except cv2.error as err:
            raise ValueError(
                f"cv2.Tracker{self.name}{self._given()}: {_cv2_message(err)}"
            ) from None

    def _given(self) -> str:
        """`` with params a=1, b=2`` naming the parameters given ("" if none): OpenCV's
        own message does not say which one it could not work with."""
        if not self.params:
            return ""
        return " with params " + ", ".join(f"{k}={v!r}" for k, v in self.params.items())

    def init(self, frame: Any, boxes: Any) -> None:
        """Start one cv2 tracker per box on ``frame`` (H, W, 3) RGB; ``boxes`` (K, 4).

        Seeds OpenCV's global random state first when ``rng`` was given. Each box is
        rounded outward to whole pixels, clipped to the frame and grown to at least
        ``MIN_SIDE`` px a side before it goes to OpenCV.

        Parameters
        ----------
        frame : array_like of uint8, shape (H, W, 3)
            The first frame, RGB (converted to BGR for OpenCV).
        boxes : array_like of float, shape (K, 4) or (4,)
            Initial box [x, y, w, h] per target, in px, K >= 1.

        Raises
        ------
        ValueError
            For a bad frame or bad boxes (``trackers.base.check_frame``,
            ``trackers.base.check_boxes``), or a box a cv2 tracker refuses to start on.
            The tracker is then left uninitialised: ``step`` refuses to run.
        """
        import cv2

        # Unset until every box has started: a box refused had left step tracking only
        # the boxes before it (fewer rows than init's boxes), and a box outside the frame
        # the previous init's trackers.
        self._shape = None
        self._trackers, self._sizes = [], []
        rgb = check_frame(frame)
        boxes = check_boxes(boxes, rgb.shape)
        if self.rng is not None:
            cv2.setRNGSeed(int(self.rng))
        bgr = np.ascontiguousarray(rgb[:, :, ::-1])
        for box in boxes:
            t = self._make()
            px = _pixel_box(box, rgb.shape)
            try:
                t.init(bgr, px)
            except cv2.error as err:
                raise ValueError(
                    f"cv2.Tracker{self.name}{self._given()} could not start on box {px}: "
                    f"{_cv2_message(err)}"
                ) from None
            self._trackers.append(t)
            grown = px[2] > np.ceil(box[2]) or px[3] > np.ceil(box[3])
            self._sizes.append((float(box[2]), float(box[3])) if grown else None)
        self._shape = rgb.shape

    def step(self, frame: Any) -> Estimate:
        """Update every cv2 tracker on ``frame``; NaN boxes where one reports failure.

        Parameters
        ----------
        frame : array_like of uint8, shape (H, W, 3)
            The next frame, RGB, of the shape of the ``init`` frame.

        Returns
        -------
        Estimate
            ``boxes`` of shape (K, 4), [x, y, w, h] in px as OpenCV reports them (whole
            pixels; a box grown at ``init`` keeps its initial size about OpenCV's
            centre), NaN rows for the targets whose tracker failed; ``extras["ok"]``,
            bool of shape (K,), True where it succeeded.

        Raises
        ------
        ValueError
            If ``init`` has not succeeded yet, or for a bad frame or one whose shape
            differs from the ``init`` frame's.
        """
        if self._shape is None:
            raise ValueError(f"cv2.Tracker{self.name}: call init() before step()")
        rgb = check_frame(frame, self._shape)
        bgr = np.ascontiguousarray(rgb[:, :, ::-1])
        out = np.full((len(self._trackers), 4), np.nan)
        ok = np.zeros(len(self._trackers), dtype=bool)
        for k, t in enumerate(self._trackers):
            found, box = t.update(bgr)
            if found:
                out[k] = box
                ok[k] = True
                size = self._sizes[k]
                if size is not None:
                    cx, cy = box[0] + box[2] / 2, box[1] + box[3] / 2
                    out[k] = (cx - size[0] / 2, cy - size[1] / 2, size[0], size[1])
        return Estimate(boxes=out, extras={"ok": ok})

    def __repr__(self) -> str:
        extra = "".join(f", {k}={v!r}" for k, v in self.params.items())
        return f"opencv({self.name!r}, rng={self.rng!r}{extra})"


def _cv2_message(err: Exception) -> str:
    """The last line of a ``cv2.error``, without its ``OpenCV(5.0.0) path/file.cpp:81:
    error:`` prefix (which would push the reason off a one-line message)."""
    lines = [s.strip() for s in str(err).strip().splitlines() if s.strip()]
    if not lines:
        return type(err).__name__
    return re.sub(r"^OpenCV\([^)]*\)\s+\S*:\s*error:\s*", "", lines[-1]) or lines[-1]


def _pixel_box(box: NDArray[np.float64], shape: tuple[int, ...]) -> tuple[int, int, int, int]:
    """``box`` [x, y, w, h] rounded outward to whole pixels, clipped to the frame, at
    least ``MIN_SIDE`` a side (where the frame allows)."""
    x, bw = _span(box[0], box[2], shape[1])
    y, bh = _span(box[1], box[3], shape[0])
    return x, y, bw, bh


def _span(start: float, size: float, limit: int) -> tuple[int, int]:
    """(start, length) in whole pixels of [start, start + size) within [0, limit)."""
    lo = int(np.clip(np.floor(start), 0, limit - 1))
    hi = int(np.clip(np.ceil(start + size), lo + 1, limit))
    side = min(MIN_SIDE, limit)
    if hi - lo < side:
        centre = (lo + hi) / 2
        lo = int(np.clip(np.floor(centre - side / 2), 0, limit - side))
        hi = lo + side
    return lo, hi - lo


def cv2_seed(rng: np.random.Generator | int | None) -> int | None:
    """The C ``int`` seed given to ``cv2.setRNGSeed`` for ``rng``.

    An int that fits a C ``int`` is used as it is (``rng=3`` seeds OpenCV with 3); a larger
    non-negative int (a derived 63-bit seed, as ``scenegen benchmark`` and the experiments
    give) is mapped to 31 bits through ``numpy.random.SeedSequence``; a Generator draws
    one; None leaves OpenCV's state alone.

    Parameters
    ----------
    rng : numpy.random.Generator, int or None
        The tracker's ``rng`` argument.

    Returns
    -------
    int or None
        A seed in [-2**31, 2**31) (in [0, 2**31) when drawn or mapped), or None for
        ``rng=None``.

    Raises
    ------
    ValueError
        For a negative int below -2**31, or anything else than an int, a Generator or None
        (a bool included).

    Examples
    --------
    >>> cv2_seed(3), cv2_seed(None), 0 <= cv2_seed(2**62 + 5) < 2**31
    (3, None, True)
    """
    if rng is None:
        return None
    if isinstance(rng, np.random.Generator):
        return int(rng.integers(2**31))
    if isinstance(rng, bool) or not isinstance(rng, (int, np.integer)):
        # A SeedSequence's repr took three lines: name the type of what is not a number.
        what = repr(rng) if isinstance(rng, (bool, float, str)) else type(rng).__name__
        raise ValueError(f"rng of an OpenCV tracker must be a Generator, an int seed or None, "
                         f"not {what}")  # fmt: skip
    seed = int(rng)
    if -(2**31) <= seed < 2**31:
        return seed
    if seed < 0:
        raise ValueError(f"rng of an OpenCV tracker must be >= -2**31, got {seed}")
    return int(np.random.SeedSequence(seed).generate_state(1, np.uint32)[0] >> 1)


def opencv(name: str, **kw: Any) -> OpenCVTracker:
    """An OpenCV tracker behind the protocol: ``opencv("MIL", rng=0, **params)``.

    See :class:`OpenCVTracker`.

    Parameters
    ----------
    name : str
        ``cv2.Tracker<name>``, e.g. ``"MIL"`` (:func:`opencv_names`).
    **kw : Any
        ``rng`` and the fields of ``cv2.Tracker<name>_Params``.

    Returns
    -------
    OpenCVTracker
        A new tracker, not yet initialised.

    Raises
    ------
    ValueError
        As :class:`OpenCVTracker`.
    """
    return OpenCVTracker(name, **kw)


#: A numeric parameter whose default is positive may be at most this many times its
#: default: OpenCV does not check them (MIL's ``featureSetNumFeatures=0`` crashed the
#: process, -3 asked for 2^64 bytes).
MAX_PARAM_FACTOR = 100


def _check_value(name: str, key: str, value: Any, default: Any) -> Any:
    """Refuse a numeric parameter OpenCV would take and then crash on: not finite, or, where
    the default is positive, not in (0, MAX_PARAM_FACTOR x default]. Returns the value to
    set: an integral float (``65.0``, as ``--param`` may give it) for an int parameter is
    an int, as for the other trackers' integer parameters.

    Raises
    ------
    ValueError
        Naming the tracker, the parameter and the value.
    """
    numeric = (int, float, np.integer, np.floating)
    if isinstance(default, bool) or not isinstance(default, numeric):
        return value
    if isinstance(value, bool) or not isinstance(value, numeric) or not np.isfinite(value):
        raise ValueError(f"cv2.Tracker{name} parameter {key} must be a finite number, "
                         f"got {value!r}")
    if default > 0 and not 0 < value <= MAX_PARAM_FACTOR * default:
        raise ValueError(f"cv2.Tracker{name} parameter {key} must be in "
                         f"(0, {MAX_PARAM_FACTOR * default:g}] ({MAX_PARAM_FACTOR}x its "
                         f"default {default:g}), got {value!r}")
    if isinstance(default, (int, np.integer)):
        if int(value) != value:
            raise ValueError(f"cv2.Tracker{name} parameter {key} must be an integer, "
                             f"got {value!r}")
        return int(value)
    return value


MIN_MIL_NEGATIVES = 20.0
"""Fewest negative samples :func:`check_mil` lets MIL's ``init`` expect: the count is a
sum of independent draws, so it is 0 with probability at most exp(−20) ≈ 2e-9."""


def check_mil(p: Any) -> None:
    """Refuse ``cv2.TrackerMIL_Params`` with which ``init`` may fail depending on the seed.

    MIL's ``init`` takes as negative samples the window positions at distance d from the
    box, 1.5 ``samplerInitInRadius`` <= d < 2 ``samplerSearchWinSize`` (an annulus, in a
    square window of side 2 ⌊2 ``samplerSearchWinSize``⌋ + 1), each with probability
    ``samplerInitMaxNegNum`` / (window positions); with none it fails. The expected count
    over a window that the frame does not clip must be at least :data:`MIN_MIL_NEGATIVES`
    (the defaults, 25, 3 and 65, give 49.7). A box too large for its frame can still
    leave no room for samples: that fails at ``init``, naming the box.

    Parameters
    ----------
    p : cv2.TrackerMIL_Params
        The parameters (read: ``samplerSearchWinSize``, ``samplerInitInRadius``,
        ``samplerInitMaxNegNum``).

    Raises
    ------
    ValueError
        One line naming ``samplerInitMaxNegNum`` (or the radii, when the annulus is
        empty), the values and the least count that works.
    """
    inrad = np.float32(2.0 * p.samplerSearchWinSize)
    outrad = np.float32(1.5 * p.samplerInitInRadius)
    r = int(inrad)
    # Offsets (dr, dc) with outrad² <= dr² + dc² < inrad², counted row by row (the window
    # is up to 10001 x 10001).
    sq = np.arange(r + 1, dtype=np.float64) ** 2
    squares = np.sort(np.concatenate([sq, sq[1:]]))
    hi, lo = float(inrad * inrad), float(outrad * outrad)
    rows = (np.searchsorted(squares, hi - squares, side="left")
            - np.searchsorted(squares, lo - squares, side="left"))
    ring = int(np.sum(np.maximum(rows, 0)))
    if ring == 0:
        raise ValueError(
            f"cv2.TrackerMIL parameters samplerSearchWinSize={p.samplerSearchWinSize:g}, "
            f"samplerInitInRadius={p.samplerInitInRadius:g} leave init no negative samples "
            f"(those lie between 1.5 x samplerInitInRadius and 2 x samplerSearchWinSize px "
            f"from the box): raise samplerSearchWinSize or lower samplerInitInRadius"
        )
    window = (2 * r + 1) ** 2
    expected = ring * min(p.samplerInitMaxNegNum / window, 1.0)
    if expected < MIN_MIL_NEGATIVES and p.samplerInitMaxNegNum < window:
        least = int(np.ceil(MIN_MIL_NEGATIVES * window / ring))
        if least >= window:
            least = window
        raise ValueError(
            f"cv2.TrackerMIL parameter samplerInitMaxNegNum={p.samplerInitMaxNegNum} gives "
            f"init {expected:.3g} negative samples on average (with samplerSearchWinSize="
            f"{p.samplerSearchWinSize:g}, samplerInitInRadius={p.samplerInitInRadius:g}), "
            f"so init fails for some seeds: it must be >= {least}"
        )
