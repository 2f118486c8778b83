"""Export to the MOTChallenge layout: ``gt/gt.txt``, ``seqinfo.ini`` and ``img1/`` frames.

``gt.txt`` rows: ``frame, id, left, top, width, height, conf, class, visibility`` with
1-based frames and ids (our entity ids are already >= 1). Boxes are amodal. ``conf`` is 1
for targets that are at least partly visible, 0 otherwise (MOT's "ignore"). Classes follow
MOT17: 1 target (pedestrian), 8 distractor, 9 occluder. Clutter is not exported. Frames
are written as lossless PNG so that pixels stay exact.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from pathlib import Path

import cv2
import numpy as np

from scenegen.errors import ConfigError
from scenegen.sequence import Sequence

__all__ = ["export_mot"]

_MOT_CLASS = {"target": 1, "distractor": 8, "occluder": 9}


def _gt_lines(seq: Sequence) -> list[str]:
    lines = []
    gt = seq.gt
    roles = seq.entities.role
    for t in range(seq.n_frames):
        for k in range(len(seq.entities)):
            role = str(roles[k])
            if role not in _MOT_CLASS or not gt.present[t, k]:
                continue
            x, y, w, h = (float(v) for v in gt.box[t, k])
            vis = float(gt.visibility[t, k])
            conf = 1 if role == "target" and vis > 0 else 0
            eid = int(seq.entities.id[k])
            lines.append(
                f"{t + 1},{eid},{x:g},{y:g},{w:g},{h:g},{conf},{_MOT_CLASS[role]},{vis:.6f}"
            )
    return lines


def export_mot(seq: Sequence, out_dir: str | Path, *, frame_rate: int = 25) -> None:
    """Write ``seq`` as a MOTChallenge sequence folder ``out_dir`` (replaced atomically)."""
    out = Path(out_dir)
    parent = out.parent if str(out.parent) else Path(".")
    if not parent.is_dir():
        raise ConfigError(f"{out}: folder {parent} does not exist")
    if out.exists() and not out.is_dir():
        raise ConfigError(f"{out}: exists and is not a folder")
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.tmp-", dir=parent))
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o777 & ~umask)  # mkdtemp makes the folder private
    try:
        (tmp / "gt").mkdir()
        (tmp / "img1").mkdir()
        (tmp / "gt" / "gt.txt").write_text("\n".join(_gt_lines(seq)) + "\n")
        (tmp / "seqinfo.ini").write_text(
            "[Sequence]\n"
            f"name={seq.name}\nimDir=img1\nframeRate={frame_rate}\nseqLength={seq.n_frames}\n"
            f"imWidth={seq.width}\nimHeight={seq.height}\nimExt=.png\n"
        )
        for t in range(seq.n_frames):
            ok, data = cv2.imencode(
                ".png", cv2.cvtColor(np.asarray(seq.frames[t]), cv2.COLOR_RGB2BGR)
            )
            if not ok:
                raise ConfigError(f"{out}: could not encode frame {t}")
            (tmp / "img1" / f"{t + 1:06d}.png").write_bytes(data.tobytes())
        old = None
        if out.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{out.name}.old-", dir=parent))
            old.rmdir()
            out.rename(old)
        tmp.rename(out)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
    except BaseException:
        with contextlib.suppress(OSError):
            shutil.rmtree(tmp)
        raise
