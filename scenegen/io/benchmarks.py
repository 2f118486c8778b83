"""Export to single-object benchmark layouts: OTB, GOT-10k and VOT.

Single-object toolkits know one target per sequence, so every target becomes its own
sequence folder ``DIR/<sequence>_<target name>/`` holding all frames and that target's
annotation (frames are hard links to one copy where the file system allows). DIR also
gets ``list.txt`` naming the sequence folders, one a line (as GOT-10k and VOT have).
Boxes are amodal ``x, y, w, h``, one comma-separated line per frame. Conventions:

OTB (Wu et al. 2015, the MATLAB toolkit)
    ``img/0001.jpg …`` and ``groundtruth_rect.txt``. Pixel coordinates are 1-based
    (MATLAB): ``x + 1, y + 1, w, h``. OTB has no absence label: a frame where the target
    is out of the scene is written ``0,0,0,0``, which the toolkit's
    ``calcSeqErrRobust`` treats as unlabelled (any value <= 0: overlap and centre error
    -1, still counted in the frame total). Occluded frames keep their amodal box, as OTB
    annotates occluded targets.
GOT-10k (Huang et al. 2019, the ``got10k`` Python toolkit)
    ``00000001.jpg …``, ``groundtruth.txt`` (0-based pixels, the toolkit reads them as
    they are), ``absence.label`` (1 where the target is out of the scene, box
    ``0,0,0,0``), ``cover.label`` (visible ratio in GOT-10k's levels 0–8: 0 fully
    occluded or absent, 1 (0, 15 %), 2 [15, 30 %), … 7 [90, 100 %), 8 fully visible),
    ``cut_by_image.label`` (1 where the amodal box reaches past the image border) and
    ``meta_info.ini``. The toolkit scores only frames with cover > 0, so fully occluded
    and absent frames do not count there. It opens ``ROOT/<subset>/list.txt``: export
    into ``ROOT/val`` for ``got10k.datasets.GOT10k(ROOT, subset="val")``.
VOT (Kristan et al., the ``vot`` toolkit; short-term rectangle format)
    ``color/00000001.jpg …``, ``groundtruth.txt`` (0-based pixels, as the Python toolkit
    reads regions), absent frames ``nan,nan,nan,nan`` (VOT long-term's "target not
    visible"), per-frame tags ``occlusion.tag`` (1 where less than the whole target is
    visible, absent frames included) and ``sequence`` metadata (``channels.color``,
    ``fps``, ``format``, ``name``).

A single-object tracker's result in the OTB or GOT-10k convention (one ``x,y,w,h`` line
per frame, what OpenCV, pysot and got10k trackers write) is read by
:func:`read_benchmark_result`, the inverse of the annotation export: the export's
``groundtruth_rect.txt`` (or ``groundtruth.txt``) read as a result gives back the
amodal boxes, with no box where the target is out of the scene.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Callable
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from scenegen.errors import ConfigError, DataError
from scenegen.io.atomic import describe_special_file
from scenegen.io.export import encode_frame, write_folder
from scenegen.io.mot import check_number_text, read_result_text
from scenegen.sequence import Sequence

__all__ = [
    "BENCHMARKS",
    "RESULT_KINDS",
    "cover_level",
    "export_benchmark",
    "first_box_values",
    "read_benchmark_result",
]

BENCHMARKS = ("otb", "got10k", "vot")
_DEFAULT_IMAGE = {"otb": "jpg", "got10k": "jpg", "vot": "png"}
#: Pixel coordinate of the top-left pixel in each layout's boxes (OTB's toolkit is MATLAB).
_ORIGIN = {"otb": 1.0, "got10k": 0.0, "vot": 0.0}
_LABEL = {"otb": "OTB", "got10k": "GOT-10k", "vot": "VOT"}

RESULT_KINDS = ("otb", "got10k")
"""Single-object result files :func:`read_benchmark_result` reads (VOT's result files
mark initialisations and failures with codes, a different format)."""


#: Lower edges of GOT-10k's cover levels 2..7 (level 1 is (0, 15 %), 8 is fully visible),
#: in float32 like the visibility they are compared with (exactly 90 % is level 7).
_COVER_EDGES = np.array([0.15, 0.30, 0.45, 0.60, 0.75, 0.90], dtype=np.float32)


def cover_level(visibility: float, present: bool) -> int:
    """GOT-10k's cover level 0–8 of a visible fraction (0 when absent or fully occluded).

    Parameters
    ----------
    visibility : float
        Visible fraction of the target, in [0, 1] (compared in float32).
    present : bool
        Whether the target is in the scene.

    Returns
    -------
    int
        0 absent or fully occluded, 1 (0, 15 %), 2 [15, 30 %), … 7 [90, 100 %), 8 fully
        visible.

    Examples
    --------
    >>> cover_level(0.5, True), cover_level(1.0, True), cover_level(0.5, False)
    (4, 8, 0)
    """
    v = np.float32(visibility)
    if not present or v <= 0.0:
        return 0
    if v >= 1.0:
        return 8
    return 1 + int(np.count_nonzero(v >= _COVER_EDGES))


def _num(v: float) -> str:
    r = repr(float(v))
    return r[:-2] if r.endswith(".0") else r


def _frame_name(kind: str, t: int, ext: str) -> str:
    if kind == "otb":
        return f"img/{t + 1:04d}.{ext}"
    if kind == "vot":
        return f"color/{t + 1:08d}.{ext}"
    return f"{t + 1:08d}.{ext}"


def _annotations(kind: str, seq: Sequence, k: int, fps: int, ext: str) -> dict[str, str]:
    """File name -> content of target ``k``'s annotation files."""
    box = np.asarray(seq.gt.box[:, k], dtype=np.float64)
    present = np.asarray(seq.gt.present[:, k], dtype=bool)
    vis = np.asarray(seq.gt.visibility[:, k], dtype=np.float64)
    off = _ORIGIN[kind]
    lines = []
    for t in range(seq.n_frames):
        x, y, w, h = box[t]
        if not present[t]:
            lines.append("nan,nan,nan,nan" if kind == "vot" else "0,0,0,0")
        elif off:
            lines.append(f"{_num(x + off)},{_num(y + off)},{_num(w)},{_num(h)}")
        else:
            lines.append(f"{_num(x)},{_num(y)},{_num(w)},{_num(h)}")
    name = "groundtruth_rect.txt" if kind == "otb" else "groundtruth.txt"
    files = {name: "\n".join(lines) + "\n"}
    if kind == "got10k":
        files["absence.label"] = "".join(f"{int(not p)}\n" for p in present)
        files["cover.label"] = "".join(
            f"{cover_level(float(v), bool(p))}\n" for v, p in zip(vis, present, strict=True)
        )
        right, bottom = box[:, 0] + box[:, 2], box[:, 1] + box[:, 3]
        with np.errstate(invalid="ignore"):
            cut = present & (
                (box[:, 0] < 0) | (box[:, 1] < 0) | (right > seq.width) | (bottom > seq.height)
            )
        files["cut_by_image.label"] = "".join(f"{int(c)}\n" for c in cut)
        files["meta_info.ini"] = (
            "[METAINFO]\n"
            f"object_class: {seq.entities.name[k]}\n"
            f"resolution: ({seq.width}, {seq.height})\n"
            "source: scenegen\n"
        )
    if kind == "vot":
        files["occlusion.tag"] = "".join(
            f"{int(not p or v < 1.0)}\n" for v, p in zip(vis, present, strict=True)
        )
        files["sequence"] = (
            f"channels.color=color/%08d.{ext}\nformat=default\nfps={fps}\n"
            f"name={seq.name}_{seq.entities.name[k]}\n"
        )
    return files


def _folder_name(seq: Sequence, k: int) -> str:
    raw = f"{seq.name}_{seq.entities.name[k]}"
    return re.sub(r"[^A-Za-z0-9._-]+", "-", raw)


def _folder_names(seq: Sequence, idx: list[int]) -> list[str]:
    """One folder per target; targets whose names map to one folder ("box a", "box-a")
    each get their entity id appended (``..._box-a-id3``)."""
    names = [_folder_name(seq, k) for k in idx]
    clash = {n for n in names if names.count(n) > 1}
    return [
        f"{n}-id{int(seq.entities.id[k])}" if n in clash else n
        for n, k in zip(names, idx, strict=True)
    ]


def export_benchmark(
    seq: Sequence,
    out_dir: str | Path,
    kind: str,
    *,
    image_format: str | None = None,
    fps: int = 25,
    progress: Callable[[int], None] | None = None,
) -> list[str]:
    """Write ``seq`` in the OTB, GOT-10k or VOT layout, one sequence folder per target.

    Parameters
    ----------
    seq : Sequence
        In memory or lazily read (frames are read one at a time).
    out_dir : str or Path
        Output folder, replaced atomically; its parent must exist.
    kind : {"otb", "got10k", "vot"}
    image_format : {"png", "jpg"}, optional
        Frame files; default jpg for OTB and GOT-10k (their loaders list ``*.jpg``), png
        (lossless) for VOT.
    fps : int
        VOT's ``sequence`` file.
    progress : callable, optional
        Called with the number of frames written so far.

    Returns
    -------
    list of str
        The sequence folders written (one per target in the scene at some frame).

    Raises
    ------
    ConfigError
        For an unknown ``kind`` or image format, or an output that cannot be written.
    """
    if kind not in BENCHMARKS:
        raise ConfigError(f"benchmark must be one of {', '.join(BENCHMARKS)}; got {kind!r}")
    ext = image_format or _DEFAULT_IMAGE[kind]
    out = Path(out_dir)
    encode_frame(np.zeros((1, 1, 3), np.uint8), ext, out)
    idx = np.asarray(seq.target_indices())
    idx = [int(k) for k in idx if np.asarray(seq.gt.present[:, k]).any()]
    names = _folder_names(seq, idx)

    def fill(tmp: Path) -> None:
        for k, name in zip(idx, names, strict=True):
            folder = tmp / name
            (folder / ("img" if kind == "otb" else "color" if kind == "vot" else "")).mkdir(
                parents=True, exist_ok=True
            )
            for fname, text in _annotations(kind, seq, k, fps, ext).items():
                (folder / fname).write_text(text)
        (tmp / "list.txt").write_text("".join(n + "\n" for n in names))
        for t in range(seq.n_frames):
            data = encode_frame(seq.frames[t], ext, out)
            first: Path | None = None
            for name in names:
                path = tmp / name / _frame_name(kind, t, ext)
                if first is None:
                    path.write_bytes(data)
                    first = path
                    continue
                try:
                    os.link(first, path)
                except OSError:
                    path.write_bytes(data)
            if progress is not None:
                progress(t + 1)

    write_folder(out, fill)
    return names


#: One value separator: a comma (spaces around it allowed), or a run of tabs and spaces.
_SEPARATOR = re.compile(r"[ \t]*,[ \t]*|[ \t]+")


def _box_line(line: str) -> tuple[float, float, float, float] | None:
    """The box ``x, y, w, h`` of one result line, None for no box (``0,0,0,0`` or four
    NaN); ValueError saying what is wrong otherwise."""
    cells = _SEPARATOR.split(line.strip())
    if len(cells) != 4:
        raise ValueError(
            f"{len(cells)} values; a line is x, y, w, h separated by commas, tabs or spaces"
        )
    for c in cells:  # as MOT files: ASCII digits, sign, point and exponent only
        check_number_text(c)
    x, y, w, h = (float(c) for c in cells)
    if all(math.isnan(v) for v in (x, y, w, h)):
        return None
    if not all(math.isfinite(v) for v in (x, y, w, h)):
        raise ValueError("a box value is not a finite number (four NaN: no box)")
    if not (math.isfinite(x + w) and math.isfinite(y + h)):
        raise ValueError("the box's right or bottom edge overflows to infinity")
    if w < 0 or h < 0:
        raise ValueError("width and height must not be negative")
    if x == y == w == h == 0:
        return None
    return x, y, w, h


def first_box_values(path: str | Path) -> int | None:
    """How many values the first line of a text file holds, split as
    :func:`read_benchmark_result` splits a line (4 for an OTB or GOT-10k result); None
    if the file cannot be read as text. Reads at most the first 4 kB.

    Parameters
    ----------
    path : str or Path
        The file.

    Returns
    -------
    int or None
        Values on the first line; None also for a FIFO or a device (not opened), an
        empty file or a blank first line.
    """
    if describe_special_file(path) is not None:  # a FIFO would wait for a writer
        return None
    try:
        with open(path, encoding="utf-8-sig", errors="strict") as f:
            first = f.read(4096).splitlines()
    except (OSError, UnicodeDecodeError, ValueError):
        return None
    return len(_SEPARATOR.split(first[0].strip())) if first and first[0].strip() else None


def read_benchmark_result(
    path: str | Path, n_frames: int, kind: str = "otb"
) -> NDArray[np.float64]:
    """Read a single-object tracker's result file in the OTB or GOT-10k convention.

    The inverse of the annotation files :func:`export_benchmark` writes: one line per
    frame of the sequence, the first for frame 0 (the initial box), each ``x, y, w, h``
    with its values separated by commas, tabs or spaces. OTB boxes are 1-based (``x + 1,
    y + 1``; the result of a tracker started on ``groundtruth_rect.txt``), GOT-10k boxes
    0-based. A line ``0,0,0,0`` (what the export writes where the target is out of the
    scene) or ``nan,nan,nan,nan`` (what got10k's ``np.savetxt`` writes for a missing box)
    is no box: it is scored as a lost target (IoU 0, centre error infinite), not as a
    box at the corner. Blank lines at the end are ignored; a byte-order mark and any line
    ending are allowed.

    Parameters
    ----------
    path : str or Path
    n_frames : int
        Frames of the sequence the result was made on: the file must have this many lines.
    kind : {"otb", "got10k"}
        The convention (:data:`RESULT_KINDS`).

    Returns
    -------
    ndarray of shape (n_frames, 4)
        Boxes ``[x, y, w, h]`` in scenegen's 0-based pixels, NaN rows where there is no box.

    Raises
    ------
    DataError
        Naming the file and line of a malformed line (not 4 values, a value that is not
        a number in ASCII (:func:`scenegen.io.mot.check_number_text`), a NaN or infinite
        value in a box, an edge that
        overflows, a negative width or height, an empty line before the last box); naming
        the file and both counts if it has not ``n_frames`` lines; a file that is not
        UTF-8 text or not a regular file.
    ConfigError
        For a ``kind`` not in :data:`RESULT_KINDS`.

    Examples
    --------
    >>> boxes = read_benchmark_result("out/crossing_target/groundtruth_rect.txt",
    ...                               seq.n_frames)  # doctest: +SKIP
    """
    if kind not in RESULT_KINDS:
        raise ConfigError(f"result kind must be one of {', '.join(RESULT_KINDS)}; got {kind!r}")
    label = _LABEL[kind]
    p = Path(path)
    text = read_result_text(p, "result file", f"{label} results")
    lines = text.splitlines()
    while lines and not lines[-1].strip():
        lines.pop()
    off = _ORIGIN[kind]
    boxes = np.full((len(lines), 4), np.nan)
    for n, line in enumerate(lines, 1):
        try:
            if not line.strip():  # skipping it would shift every later frame by one
                raise ValueError("an empty line; a frame without a box is 0,0,0,0")
            box = _box_line(line)
        except ValueError as err:
            raise DataError(
                f"{p}:{n}: not a box line of {label} results ({err}): {line[:80]!r}"
            ) from None
        if box is not None:
            x, y, w, h = box
            boxes[n - 1] = (x - off, y - off, w, h)
    if len(lines) != n_frames:
        raise DataError(
            f"{p}: {len(lines)} lines, but the sequence has {n_frames} frames ({label} "
            "results have one line per frame, the first for frame 0)"
        )
    return boxes
