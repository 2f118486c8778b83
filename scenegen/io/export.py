"""Export to the MOTChallenge layout: ``gt/gt.txt``, ``seqinfo.ini`` and ``img1/`` frames.

``gt.txt`` rows: ``frame, id, bb_left, bb_top, width, height, conf, class, visibility``
with MOTChallenge's 1-based frames, ids (our entity ids are already >= 1) and pixel
coordinates (``bb_left = x + 1``). Boxes are amodal. Which rows count follows
``gt_mode`` (see :mod:`scenegen.io.mot`): ``amodal`` (default) writes every target row
with ``conf`` 1; ``visible`` (MOTChallenge's convention) writes ``conf`` 0 where a target's
visible fraction is at most ``visibility_threshold`` (MOT's "ignore") and adds distractors
(class 8) and occluders (class 9). Clutter is not exported. Frames are written as lossless
PNG by default so that pixels stay exact.

The folder is written atomically: everything goes to a temporary folder beside the target
(``.NAME.tmp-PID@HOST-RANDOM``, see :mod:`scenegen.io.atomic`), which then replaces the target
in one step (Linux ``renameat2(RENAME_EXCHANGE)``; elsewhere two renames in quick
succession). A process killed while exporting leaves the earlier folder untouched and its
temporary folder behind, which the next export to the same target removes. Frames are read
and written one at a time, so memory stays bounded whatever the sequence length. An output
that cannot be written raises :class:`~scenegen.errors.ConfigError` naming the target.
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import os
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np

from scenegen.errors import ConfigError
from scenegen.io.atomic import clean_temp_files, temp_prefix
from scenegen.io.mot import gt_rows, writable
from scenegen.sequence import Sequence

__all__ = ["IMAGE_FORMATS", "encode_frame", "export_mot", "seqinfo_text", "write_folder"]

IMAGE_FORMATS = ("png", "jpg")
"""Frame formats of the exports: lossless PNG, or JPEG (quality 95)."""

Progress = Callable[[int], None] | None
_RENAME_EXCHANGE = 2  # linux/fs.h
_AT_FDCWD = -100


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths atomically; False where the system cannot."""
    try:
        fn = ctypes.CDLL(None, use_errno=True).renameat2
    except (AttributeError, OSError):
        return False
    res = fn(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE)
    if res == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP):
        return False
    raise OSError(err, os.strerror(err), str(b))


def _replace_dir(tmp: Path, out: Path) -> None:
    """Put the folder ``tmp`` at ``out``, replacing any folder there; ``tmp`` is consumed.

    Concurrent exports to the same target each end with a complete folder at ``out`` (the
    last one wins), whichever order their steps interleave in.
    """
    parent = out.parent if str(out.parent) else Path(".")
    for _ in range(100):
        if not out.exists():
            try:
                os.rename(tmp, out)
                return
            except OSError as err:  # another export created ``out`` meanwhile
                if err.errno not in (errno.ENOTEMPTY, errno.EEXIST):
                    raise
                continue
        if not out.is_dir():
            raise ConfigError(f"{out}: exists and is not a folder")
        try:
            swapped = _exchange(tmp, out)
        except FileNotFoundError:  # ``out`` vanished meanwhile: try a plain rename again
            continue
        if swapped:
            shutil.rmtree(tmp, ignore_errors=True)  # now holds the previous folder
            return
        old = Path(tempfile.mkdtemp(prefix=temp_prefix(out.name, "old"), dir=parent))
        try:
            os.rename(out, old / out.name)
        except FileNotFoundError:
            old.rmdir()
            continue
        try:
            os.rename(tmp, out)
        except OSError as err:
            if err.errno not in (errno.ENOTEMPTY, errno.EEXIST):
                with contextlib.suppress(OSError):  # put the previous folder back
                    os.rename(old / out.name, out)
                shutil.rmtree(old, ignore_errors=True)
                raise
            shutil.rmtree(old, ignore_errors=True)
            continue  # another export put a complete folder at ``out`` meanwhile
        shutil.rmtree(old, ignore_errors=True)
        return
    raise OSError(errno.EBUSY, "other processes keep replacing the folder", str(out))


def encode_frame(frame: np.ndarray, image_format: str, where: Path) -> bytes:
    """Encode an RGB frame (H, W, 3) uint8 as PNG or JPEG (quality 95) bytes.

    Parameters
    ----------
    frame : ndarray of uint8, shape (H, W, 3)
        RGB frame.
    image_format : {"png", "jpg"}
        Encoding (:data:`IMAGE_FORMATS`).
    where : Path
        The output the frame is for, named in error messages.

    Returns
    -------
    bytes
        The encoded image file.

    Raises
    ------
    ConfigError
        For an image format not in :data:`IMAGE_FORMATS`, or a frame that cannot be encoded
        (naming ``where``).
    """
    if image_format not in IMAGE_FORMATS:
        raise ConfigError(
            f"image format must be one of {', '.join(IMAGE_FORMATS)}; got {image_format!r}"
        )
    bgr = cv2.cvtColor(np.asarray(frame), cv2.COLOR_RGB2BGR)
    params = [cv2.IMWRITE_JPEG_QUALITY, 95] if image_format == "jpg" else []
    ok, data = cv2.imencode(f".{image_format}", bgr, params)
    if not ok:
        raise ConfigError(f"{where}: could not encode a frame as {image_format}")
    return bytes(data.tobytes())


def write_folder(out_dir: str | Path, fill: Callable[[Path], None]) -> None:
    """Create folder ``out_dir`` atomically: ``fill(tmp)`` writes into a temporary folder.

    The temporary folder then replaces ``out_dir`` (and any folder there) in one step; if
    ``fill`` raises, it is removed and the exception propagates.

    Parameters
    ----------
    out_dir : str or Path
        The folder to create or replace; its parent must exist.
    fill : callable
        ``fill(tmp)`` writes the folder's content into the temporary folder ``tmp``
        (a :class:`~pathlib.Path` beside ``out_dir``).

    Raises
    ------
    ConfigError
        If the parent folder does not exist, ``out_dir`` is a file, or it cannot be
        written (naming ``out_dir``, not the temporary folder).
    """
    out = Path(out_dir)
    parent = out.parent if str(out.parent) else Path(".")
    if not parent.is_dir():
        raise ConfigError(f"{out}: folder {parent} does not exist")
    if out.exists() and not out.is_dir():
        raise ConfigError(f"{out}: exists and is not a folder")
    with writable(out):
        clean_temp_files(parent, out.name)
        tmp = Path(tempfile.mkdtemp(prefix=temp_prefix(out.name), dir=parent))
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o777 & ~umask)  # mkdtemp makes the folder private
        try:
            fill(tmp)
            _replace_dir(tmp, out)
        except BaseException:
            with contextlib.suppress(OSError):
                shutil.rmtree(tmp)
            raise


def seqinfo_text(seq: Sequence, frame_rate: int = 25, image_format: str = "png") -> str:
    """The ``seqinfo.ini`` of ``seq`` in a MOTChallenge sequence folder.

    Parameters
    ----------
    seq : Sequence
        The sequence (its ``name``, ``n_frames``, ``width`` and ``height`` are used).
    frame_rate : int
        Written as ``frameRate``.
    image_format : {"png", "jpg"}
        Written as ``imExt`` (the frames' extension in ``img1/``).

    Returns
    -------
    str
        The ``[Sequence]`` section: ``name``, ``imDir``, ``frameRate``, ``seqLength``,
        ``imWidth``, ``imHeight`` and ``imExt``, one per line.
    """
    return (
        "[Sequence]\n"
        f"name={seq.name}\nimDir=img1\nframeRate={frame_rate}\nseqLength={seq.n_frames}\n"
        f"imWidth={seq.width}\nimHeight={seq.height}\nimExt=.{image_format}\n"
    )


def export_mot(
    seq: Sequence,
    out_dir: str | Path,
    *,
    frame_rate: int = 25,
    gt_mode: str = "amodal",
    visibility_threshold: float = 0.0,
    image_format: str = "png",
    progress: Progress = None,
) -> None:
    """Write ``seq`` as a MOTChallenge sequence folder ``out_dir`` (replaced atomically).

    Parameters
    ----------
    seq : Sequence
        In memory or lazily read (frames are read one at a time).
    out_dir : str or Path
        The sequence folder; its parent must exist. An existing folder is replaced.
    frame_rate : int
        Written to ``seqinfo.ini``.
    gt_mode : {"amodal", "visible"}
        Which ground truth counts (module docstring).
    visibility_threshold : float
        ``visible`` mode: rows with visibility at most this get ``conf`` 0.
    image_format : {"png", "jpg"}
        Frame files ``img1/000001.png`` (default, lossless) or ``.jpg``.
    progress : callable, optional
        Called with the number of frames written so far.

    Raises
    ------
    ConfigError
        If the parent folder does not exist, ``out_dir`` is a file or cannot be written,
        or an option is invalid.
    DataError
        If a frame of ``seq`` cannot be read (damaged file).
    """
    out = Path(out_dir)
    gt_rows(seq, 0, gt_mode, visibility_threshold)  # checks the options before any work
    encode_frame(np.zeros((1, 1, 3), np.uint8), image_format, out)

    def fill(tmp: Path) -> None:
        (tmp / "gt").mkdir()
        (tmp / "img1").mkdir()
        (tmp / "seqinfo.ini").write_text(seqinfo_text(seq, frame_rate, image_format))
        with open(tmp / "gt" / "gt.txt", "w") as gt_file:
            for t in range(seq.n_frames):
                for row in gt_rows(seq, t, gt_mode, visibility_threshold):
                    gt_file.write(row + "\n")
                data = encode_frame(seq.frames[t], image_format, out)
                (tmp / "img1" / f"{t + 1:06d}.{image_format}").write_bytes(data)
                if progress is not None:
                    progress(t + 1)

    write_folder(out, fill)
