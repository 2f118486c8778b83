"""MOTChallenge text files: ground-truth rows and tracker files, written and read.

MOTChallenge conventions (Milan et al., "MOT16", §3.3 and the devkit): one row per box,
``frame, id, bb_left, bb_top, bb_width, bb_height, conf, ...``, frames and ids counted
from 1, and pixel coordinates counted from 1 (the devkit is MATLAB: the top-left pixel
is (1, 1)). scenegen counts pixels from 0, so ``bb_left = x + 1`` and ``bb_top = y + 1``;
reading subtracts 1 again. Numbers are written with Python's shortest round-trip repr,
so a file read back gives the boxes written (up to the float64 rounding of ``± 1``).

Tracker files have 10 columns: ``frame, id, bb_left, bb_top, bb_width, bb_height, conf,
-1, -1, -1`` (``conf`` 1; the last three are MOTChallenge's unused world coordinates).

Ground-truth modes (``gt_mode``) say which ground-truth boxes count:

``amodal`` (scenegen's default)
    Every frame where a target is in the scene counts, with its amodal box, occluded or
    not. Tracker boxes are all scored. The ground-truth file holds the target rows only,
    all with ``conf`` 1.
``visible`` (MOTChallenge's convention)
    A target counts only in frames where its visible fraction is above
    ``visibility_threshold`` (default 0: fully occluded frames are ignored); other rows
    get ``conf`` 0, which MOTChallenge and TrackEval ignore. Distractors are written as
    class 8 and occluders as class 9; a tracker box matched to a distractor is dropped
    (neither a true nor a false positive), as TrackEval's MOTChallenge preprocessing does.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from scenegen.errors import ConfigError, DataError
from scenegen.io.atomic import atomic_path, describe_special_file
from scenegen.sequence import Sequence

__all__ = [
    "GT_MODES",
    "MOT_CLASS",
    "check_number_text",
    "read_result_text",
    "gt_keep",
    "gt_rows",
    "read_mot_tracker",
    "read_mot_tracker_rows",
    "write_mot_tracker",
]

GT_MODES = ("amodal", "visible")
"""Ground-truth conventions of the MOT export and of ``evaluate`` (see the module doc)."""

MOT_CLASS = {"target": 1, "distractor": 8, "occluder": 9}
"""MOT17 classes: pedestrian, distractor, occluder."""

MAX_TRACKER_FILE_BYTES = 512 * 1024 * 1024
#: Track ids of a tracker file are integers of magnitude below this (they are stored as int64).
MAX_TRACK_ID = 2**63


def _num(v: float) -> str:
    r = repr(float(v))
    return r[:-2] if r.endswith(".0") else r


def check_gt_mode(gt_mode: str, visibility_threshold: float) -> None:
    """Raise ConfigError for an unknown mode, a threshold outside [0, 1), or a threshold
    other than 0 in ``amodal`` mode (which counts every frame a target is in the scene,
    so it would be recorded in the report and ignored)."""
    if gt_mode not in GT_MODES:
        raise ConfigError(f"gt_mode must be one of {', '.join(GT_MODES)}; got {gt_mode!r}")
    if not 0.0 <= visibility_threshold < 1.0:
        raise ConfigError(f"visibility_threshold must be in [0, 1), got {visibility_threshold}")
    if gt_mode == "amodal" and visibility_threshold != 0.0:
        raise ConfigError(
            f"visibility_threshold ({visibility_threshold}) applies to gt_mode 'visible' "
            "only: amodal counts every frame a target is in the scene"
        )


def visible_enough(visibility: ArrayLike, threshold: float) -> NDArray[np.bool_]:
    """Where a visible fraction exceeds ``threshold``, compared in float32, the precision
    visibility is stored in (so an 80 % visible target is not above a threshold of 0.8)."""
    return np.asarray(visibility, dtype=np.float32) > np.float32(threshold)


def gt_keep(
    seq: Sequence, gt_mode: str = "amodal", visibility_threshold: float = 0.0
) -> NDArray[np.bool_]:
    """Ground-truth boxes that count, (T, K) bool: present, and visible enough if ``visible``.

    Parameters
    ----------
    seq : Sequence
        The sequence (its ``gt.present`` and ``gt.visibility`` are used).
    gt_mode : {"amodal", "visible"}
        Ground-truth convention (module docstring).
    visibility_threshold : float
        ``visible`` mode: a target counts where its visible fraction exceeds this, in
        [0, 1); must be 0 in ``amodal`` mode.

    Returns
    -------
    ndarray of bool, shape (T, K)
        True where entity k's box counts at frame t (every entity, whatever its role).

    Raises
    ------
    ConfigError
        For an unknown ``gt_mode`` or a bad ``visibility_threshold`` (see
        :func:`check_gt_mode`).
    """
    check_gt_mode(gt_mode, visibility_threshold)
    present = np.asarray(seq.gt.present, dtype=bool)
    if gt_mode == "amodal":
        return present
    return present & visible_enough(seq.gt.visibility, visibility_threshold)


def gt_rows(
    seq: Sequence, t: int, gt_mode: str = "amodal", visibility_threshold: float = 0.0
) -> list[str]:
    """The MOTChallenge ``gt.txt`` rows of frame ``t`` (0-based), entities in file order.

    Columns: ``frame, id, bb_left, bb_top, bb_width, bb_height, conf, class, visibility``.

    Parameters
    ----------
    seq : Sequence
        The sequence.
    t : int
        Frame index, 0-based.
    gt_mode : {"amodal", "visible"}
        Ground-truth convention (module docstring).
    visibility_threshold : float
        ``visible`` mode: a target counts where its visible fraction exceeds this, in
        [0, 1); must be 0 in ``amodal`` mode.

    Returns
    -------
    list of str
        One row per entity present at frame ``t`` (no newline): the targets in ``amodal``
        mode; targets, distractors and occluders (:data:`MOT_CLASS`) in ``visible`` mode,
        ``conf`` 1 only for a target visible enough. Frame and box corner are 1-based.

    Raises
    ------
    ConfigError
        For an unknown ``gt_mode`` or a bad ``visibility_threshold`` (see
        :func:`check_gt_mode`).
    """
    check_gt_mode(gt_mode, visibility_threshold)
    gt = seq.gt
    roles = seq.entities.role
    rows = []
    for k in range(len(seq.entities)):
        role = str(roles[k])
        if role not in MOT_CLASS or not gt.present[t, k]:
            continue
        if gt_mode == "amodal" and role != "target":
            continue
        x, y, w, h = (float(v) for v in gt.box[t, k])
        vis = float(gt.visibility[t, k])
        conf = int(
            role == "target"
            and (gt_mode == "amodal" or bool(visible_enough(vis, visibility_threshold)))
        )
        eid = int(seq.entities.id[k])
        rows.append(
            f"{t + 1},{eid},{_num(x + 1)},{_num(y + 1)},{_num(w)},{_num(h)},{conf},"
            f"{MOT_CLASS[role]},{vis:.6f}"
        )
    return rows


def write_mot_tracker(path: str | Path, boxes: ArrayLike, track_ids: ArrayLike) -> int:
    """Write tracker boxes as a MOTChallenge tracker file (atomically).

    Parameters
    ----------
    path : str or Path
        The ``.txt`` file; its folder must exist.
    boxes : array_like of shape (T, M, 4)
        Boxes ``[x, y, w, h]`` (0-based pixels), NaN where the track has no box.
    track_ids : array_like of int, shape (M,)
        Track ids (≥ 1), e.g. the entity ids of a :class:`scenegen.io.TrackerResult`.

    Returns
    -------
    int
        Rows written.

    Raises
    ------
    ConfigError
        If the file cannot be written (naming ``path``), ``boxes`` is not of shape
        (T, M, 4) for the M ids, or an id is < 1.
    """
    b = np.asarray(boxes, dtype=np.float64)
    ids = np.asarray(track_ids).astype(np.int64).reshape(-1)
    if b.ndim != 3 or b.shape[1:] != (ids.shape[0], 4):
        raise ConfigError(f"boxes {b.shape} do not fit {ids.shape[0]} track ids")
    if ids.size and ids.min() < 1:
        raise ConfigError(f"MOTChallenge track ids start at 1, got {int(ids.min())}")
    lines = []
    for t in range(b.shape[0]):
        for m in range(b.shape[1]):
            x, y, w, h = b[t, m]
            if not all(math.isfinite(v) for v in (x, y, w, h)):
                continue
            box = f"{_num(x + 1)},{_num(y + 1)},{_num(w)},{_num(h)}"
            lines.append(f"{t + 1},{int(ids[m])},{box},1,-1,-1,-1\n")
    target = Path(path)
    with writable(target), atomic_path(target) as tmp:
        tmp.write_text("".join(lines))
    return len(lines)


def read_mot_tracker(
    path: str | Path, n_frames: int
) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Read a MOTChallenge tracker file: (track ids (M,), boxes (n_frames, M, 4)).

    :func:`read_mot_tracker_rows` without the row order; see it for the parameters,
    returns and errors.

    Parameters
    ----------
    path : str or Path
        The tracker file.
    n_frames : int
        Frames of the sequence it was made on; frame numbers must be in 1..n_frames.

    Returns
    -------
    track_ids : ndarray of int, shape (M,)
        The ids in the file, sorted.
    boxes : ndarray of shape (n_frames, M, 4)
        Boxes in scenegen's 0-based pixels, NaN where a track has no row.

    Raises
    ------
    DataError
        As :func:`read_mot_tracker_rows`.
    """
    ids, boxes, _ = read_mot_tracker_rows(path, n_frames)
    return ids, boxes


_NUMBER = re.compile(
    r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|[+-]?(?:nan|inf|infinity)",
    re.IGNORECASE,
)


def read_result_text(path: str | Path, kind: str, read_as: str) -> str:
    """The text of a tracker's result file: UTF-8, a byte-order mark allowed (Notepad,
    Excel's "CSV UTF-8", PowerShell write one; it is not part of the first number).

    Parameters
    ----------
    path : str or Path
        The result file.
    kind : str
        What the file should be, for the size message (e.g. ``"tracker file"``).
    read_as : str
        What it is read as, for the read message (e.g. ``"a MOTChallenge tracker file"``).

    Returns
    -------
    str
        The decoded text, without a byte-order mark.

    Raises
    ------
    DataError
        One line naming ``path``: a FIFO or a device (a FIFO waits for a writer,
        /dev/zero never ends), more than :data:`MAX_TRACKER_FILE_BYTES` ("not a
        ``kind``"), unreadable or not UTF-8 ("cannot read as ``read_as``").
    """
    p = Path(path)
    special = describe_special_file(p)
    if special is not None:
        raise DataError(special)
    try:
        if p.stat().st_size > MAX_TRACKER_FILE_BYTES:
            raise DataError(f"{p}: larger than {MAX_TRACKER_FILE_BYTES} bytes; not a {kind}")
        return p.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as err:
        raise DataError(f"{p}: cannot read as {read_as}: {err}") from None


def check_number_text(cell: str) -> None:
    """Raise ValueError unless ``cell`` is a number as text files write one: ASCII digits,
    sign, point and exponent (``nan``/``inf`` pass here, for a later, clearer refusal).
    Python's ``int`` and ``float`` also read ``1_0`` as 10 and any script's digits
    (``１`` fullwidth, ``١`` Arabic-Indic) as numbers, which no tool writes.

    Parameters
    ----------
    cell : str
        One cell of a row, surrounding spaces already stripped.

    Raises
    ------
    ValueError
        If ``cell`` is not such a number; the message says why (``_``, or what is allowed).
    """
    if _NUMBER.fullmatch(cell):
        return
    if "_" in cell:
        raise ValueError("'_' is not part of a number")
    raise ValueError(f"{cell[:20]!r} is not a number (ASCII digits, sign, point, exponent)")


def _integer(cell: str) -> int:
    """A frame or id cell as an exact integer: ``12``, or ``12.0`` below 2**53 (a float
    above that may stand for several integers)."""
    try:
        return int(cell)
    except ValueError:
        pass
    x = float(cell)  # ValueError for text
    if not math.isfinite(x) or x != int(x):
        raise ValueError("frame and id must be integers")
    if abs(x) >= 2**53:
        raise ValueError(f"{cell} is written as a float beyond 2**53, which is not exact; "
                         "write the integer")  # fmt: skip
    return int(x)


def read_mot_tracker_rows(
    path: str | Path, n_frames: int
) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.int64]]:
    """Read a MOTChallenge tracker file, with the order of its rows in each frame.

    Parameters
    ----------
    path : str or Path
    n_frames : int
        Frames of the sequence it was made on; frame numbers must be in 1..n_frames.

    Returns
    -------
    track_ids : ndarray of int, shape (M,)
        The ids in the file, sorted.
    boxes : ndarray of shape (n_frames, M, 4)
        Boxes in scenegen's 0-based pixels (``bb_left - 1``, ``bb_top - 1``), NaN where a
        track has no row.
    rank : ndarray of int, shape (n_frames, M)
        Position of the track's row among the rows of its frame, in file order (0 first),
        −1 where it has none. TrackEval matches a frame's boxes in this order, which
        breaks ties in its matchings (``mot_frames``' ``est_rank``).

    Raises
    ------
    DataError
        Naming the file and line of a malformed row (fewer than 6 comma-separated
        columns, a ``_`` in a number, a frame or id that is not an integer, an id beyond
        ``MAX_TRACK_ID``, a box value that is not a finite number or whose right or bottom
        edge is not, a negative width or height), a frame out of range, or a track id that
        appears twice in a frame; a file that is not UTF-8 text (a byte-order mark is
        allowed); a path that is not a regular file (a FIFO, a device).
    """
    p = Path(path)
    text = read_result_text(p, "tracker file", "a MOTChallenge tracker file")
    rows: list[tuple[int, int, int, float, float, float, float]] = []
    for n, line in enumerate(text.splitlines(), 1):
        if not line.strip():
            continue
        # Spaces around a value are allowed (``1, 1, 2``); within one they are not: "20 1"
        # is two numbers, not 201.
        cells = [c.strip() for c in line.split(",")]
        try:
            if len(cells) < 6:
                raise ValueError("fewer than 6 comma-separated columns")
            for c in cells[:6]:
                check_number_text(c)
            frame, ident = _integer(cells[0]), _integer(cells[1])
            if abs(ident) >= MAX_TRACK_ID:
                raise ValueError(f"id beyond ±{MAX_TRACK_ID - 1}")
            vals = [float(c) for c in cells[2:6]]
            if not all(np.isfinite(vals)):
                raise ValueError("a box value is not a finite number")
            if not (math.isfinite(vals[0] + vals[2]) and math.isfinite(vals[1] + vals[3])):
                raise ValueError("the box's right or bottom edge overflows to infinity")
            if vals[2] < 0 or vals[3] < 0:
                raise ValueError("width and height must not be negative")
        except ValueError as err:
            raise DataError(f"{p}:{n}: not a MOTChallenge row ({err}): {line[:80]!r}") from None
        if not 1 <= frame <= n_frames:
            raise DataError(f"{p}:{n}: frame {frame} is outside 1..{n_frames}")
        rows.append((n, frame, ident, *vals))  # type: ignore[arg-type]
    ids = np.array(sorted({r[2] for r in rows}), dtype=np.int64)
    col = {int(i): c for c, i in enumerate(ids)}
    boxes = np.full((n_frames, ids.shape[0], 4), np.nan)
    rank = np.full((n_frames, ids.shape[0]), -1, dtype=np.int64)
    seen = np.zeros(n_frames, dtype=np.int64)
    for n, frame, ident, x, y, w, h in rows:
        t, c = frame - 1, col[ident]
        if not np.isnan(boxes[t, c, 0]):
            raise DataError(f"{p}:{n}: track id {ident} appears twice in frame {frame}")
        boxes[t, c] = (x - 1.0, y - 1.0, w, h)
        rank[t, c] = seen[t]
        seen[t] += 1
    return ids, boxes, rank


class writable:
    """Context manager: turn an operating-system error while writing into one ConfigError.

    ``with writable(target): ...`` reports ``TARGET: cannot write: REASON`` (exit 2 in the
    CLI: the user must pick another output) instead of an internal error naming a
    temporary file beside the target.
    """

    def __init__(self, target: str | Path) -> None:
        self.target = Path(target)

    def __enter__(self) -> None:
        return None

    def __exit__(self, kind: type | None, err: BaseException | None, tb: object) -> bool:
        code = _write_errno(err)
        if code is not None:
            raise ConfigError(f"{self.target}: cannot write: {os.strerror(code)}") from None
        return False


def _write_errno(err: BaseException | None) -> int | None:
    """The operating-system error number of a failed write, or None if it is not one.

    An :class:`OSError`'s ``errno``; h5py reports a write that fails when a file is
    flushed or closed (a full disk) as a ``RuntimeError`` (or an ``OSError`` without
    ``errno``) whose multi-line HDF5 message holds ``errno = N``.
    """
    if isinstance(err, OSError) and err.errno is not None:
        return int(err.errno)
    if isinstance(err, (OSError, RuntimeError)):
        found = re.search(r"\berrno = (\d+)", str(err))
        return int(found.group(1)) if found else None
    return None
