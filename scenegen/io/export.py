"""Export to the MOTChallenge layout: ``gt/gt.txt``, ``seqinfo.ini`` and ``img1/`` frames.

``gt.txt`` rows: ``frame, id, left, top, width, height, conf, class, visibility`` with
1-based frames and ids (our entity ids are already >= 1). Boxes are amodal. ``conf`` is 1
for targets that are at least partly visible, 0 otherwise (MOT's "ignore"). Classes follow
MOT17: 1 target (pedestrian), 8 distractor, 9 occluder. Clutter is not exported. Frames
are written as lossless PNG so that pixels stay exact.

The folder is written atomically: everything goes to a temporary folder beside the target
(``.NAME.tmp-PID@HOST-RANDOM``, see :mod:`scenegen.io.atomic`), which then replaces the target
in one step (Linux ``renameat2(RENAME_EXCHANGE)``; elsewhere two renames in quick
succession). A process killed while exporting leaves the earlier folder untouched and its
temporary folder behind, which the next export to the same target removes. Frames are read
and written one at a time, so memory stays bounded whatever the sequence length.
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import os
import shutil
import tempfile
from pathlib import Path

import cv2
import numpy as np

from scenegen.errors import ConfigError
from scenegen.io.atomic import clean_temp_files, temp_prefix
from scenegen.sequence import Sequence

__all__ = ["export_mot"]

_MOT_CLASS = {"target": 1, "distractor": 8, "occluder": 9}
_RENAME_EXCHANGE = 2  # linux/fs.h
_AT_FDCWD = -100


def _gt_rows(seq: Sequence, t: int) -> list[str]:
    """The ``gt.txt`` rows of frame ``t`` (0-based)."""
    gt = seq.gt
    roles = seq.entities.role
    rows = []
    for k in range(len(seq.entities)):
        role = str(roles[k])
        if role not in _MOT_CLASS or not gt.present[t, k]:
            continue
        x, y, w, h = (float(v) for v in gt.box[t, k])
        vis = float(gt.visibility[t, k])
        conf = 1 if role == "target" and vis > 0 else 0
        eid = int(seq.entities.id[k])
        rows.append(f"{t + 1},{eid},{x:g},{y:g},{w:g},{h:g},{conf},{_MOT_CLASS[role]},{vis:.6f}")
    return rows


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


def export_mot(seq: Sequence, out_dir: str | Path, *, frame_rate: int = 25) -> None:
    """Write ``seq`` as a MOTChallenge sequence folder ``out_dir`` (replaced atomically).

    Parameters
    ----------
    seq : Sequence
        In memory or lazily read (frames are read one at a time).
    out_dir : str or Path
        The sequence folder; its parent must exist. An existing folder is replaced.
    frame_rate : int
        Written to ``seqinfo.ini``.

    Raises
    ------
    ConfigError
        If the parent folder does not exist or ``out_dir`` is a file.
    DataError
        If a frame of ``seq`` cannot be read (damaged file).
    """
    out = Path(out_dir)
    parent = out.parent if str(out.parent) else Path(".")
    if not parent.is_dir():
        raise ConfigError(f"{out}: folder {parent} does not exist")
    if out.exists() and not out.is_dir():
        raise ConfigError(f"{out}: exists and is not a folder")
    clean_temp_files(parent, out.name)
    tmp = Path(tempfile.mkdtemp(prefix=temp_prefix(out.name), dir=parent))
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o777 & ~umask)  # mkdtemp makes the folder private
    try:
        (tmp / "gt").mkdir()
        (tmp / "img1").mkdir()
        (tmp / "seqinfo.ini").write_text(
            "[Sequence]\n"
            f"name={seq.name}\nimDir=img1\nframeRate={frame_rate}\nseqLength={seq.n_frames}\n"
            f"imWidth={seq.width}\nimHeight={seq.height}\nimExt=.png\n"
        )
        with open(tmp / "gt" / "gt.txt", "w") as gt_file:
            for t in range(seq.n_frames):
                for row in _gt_rows(seq, t):
                    gt_file.write(row + "\n")
                ok, data = cv2.imencode(
                    ".png", cv2.cvtColor(np.asarray(seq.frames[t]), cv2.COLOR_RGB2BGR)
                )
                if not ok:
                    raise ConfigError(f"{out}: could not encode frame {t}")
                (tmp / "img1" / f"{t + 1:06d}.png").write_bytes(data.tobytes())
        _replace_dir(tmp, out)
    except BaseException:
        with contextlib.suppress(OSError):
            shutil.rmtree(tmp)
        raise
