"""Score the committed MOT files with the got10k toolkit's OTB evaluation; write ``oracle.json``.

The reference is the GOT-10k team's toolkit (pip ``got10k``, github.com/got-10k/toolkit):
``ExperimentOTB._calc_metrics`` (``got10k.utils.metrics.rect_iou`` and ``center_error``)
and ``ExperimentOTB._calc_curves`` (21 IoU thresholds ``linspace(0, 1, 21)``, success =
IoU > θ; 51 centre-error thresholds 0…50 px, precision = error ≤ θ), the AUC being the
mean of the success curve and P@20 the precision curve at index 20, as
``ExperimentOTB.report`` computes them. A second opinion comes from pysot-toolkit's OPE
benchmark (github.com/StrangerZhang/pysot-toolkit, ``pysot/utils/statistics.py``:
``overlap_ratio``, ``success_overlap``, ``success_error``; its OPE centre is
``x + (w - 1) / 2``); its compiled ``region`` module is not needed, so the three functions
are taken from the file as written (their numba ``@jit`` dropped). The script runs in a
side environment and does not import scenegen::

    python3 -m venv /tmp/otb-venv
    /tmp/otb-venv/bin/pip install got10k==0.1.3 six      # pulls numpy, shapely, matplotlib
    git clone https://github.com/StrangerZhang/pysot-toolkit /tmp/pysot-toolkit
    git -C /tmp/pysot-toolkit checkout 8b5ced3b39129b26b3700c218ffcadba7d8ad278
    /tmp/otb-venv/bin/python tools/otb/make_oracle.py --pysot /tmp/pysot-toolkit \
        [--out tests/data/otb/oracle.json]

(``--pysot-commit SHA`` records the commit when the folder is not a git checkout.) To check
that the committed file still reproduces, without rewriting it::

    OTB_PYTHON=/tmp/otb-venv/bin/python OTB_PYSOT=/tmp/pysot-toolkit \
        .venv/bin/python -m pytest -m slow tests/scenegen/evaluation/test_otb_oracle.py

Made with got10k 0.1.3 (its dependencies as pip resolved them: numpy 2.4.6, shapely 2.2.0;
got10k also imports ``six``, which it does not declare: ``pip install six``), pysot-toolkit
``8b5ced3b39129b26b3700c218ffcadba7d8ad278``, Python 3.11.7.

Inputs: the TrackEval oracle's files, ``tests/data/trackeval/gt/amodal/<seq>/gt/gt.txt``
(scenegen's MOT export of the fixture, amodal ground truth: a row per frame the target is in
the scene) and ``tests/data/trackeval/trackers/<tracker>/<seq>.txt`` (MOTChallenge tracker
files: our 12 trackers, ``scrambled`` and ``tied``; see ``tools/trackeval/make_inputs.py``).
Boxes are taken as written, MOT's 1-based pixels (IoU and centre error do not depend on
the origin). A *case* is (tracker, sequence, target id, track id): every target of the
sequence against every track of the file, and against no track at all (``"none"``: every
estimate missing), because which track scenegen pairs with a target is scenegen's choice.

Per case, ``oracle.json`` holds the reference under several frame conventions:

``scored``
    scenegen's convention, mapped onto the tool: only frames where the target has a
    ground-truth box, the tracker's own box on every frame (frame 0 included), a missing
    box (no row for that frame) NaN, which fails every IoU and error threshold in
    got10k's comparisons. Full curves, AUC and P@20 (got10k), and pysot's AUC and P@20.
``got10k``
    got10k's ``ExperimentOTB.report`` as it runs on ``scenegen export --format otb``:
    every frame of the sequence, the ground-truth rows of absent frames ``0,0,0,0`` (what
    the export writes), and ``boxes[0] = anno[0]`` (frame 0 replaced by the ground truth).
``frame0``
    ``scored`` plus got10k's frame-0 replacement (only when the target is in the scene at
    frame 0).
``absent``
    ``got10k`` without the frame-0 replacement: the effect of counting absent frames.
``pysot_all``
    pysot's OPE on every frame of the sequence with the exported ``0,0,0,0`` rows (it
    masks them: IoU -1, a success failure; centre error -1, a precision success) and the
    tracker's frame 0.

plus, per file, the tool versions (got10k, pysot commit, numpy, python).
"""

from __future__ import annotations

import argparse
import ast
import importlib.metadata
import json
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
from got10k.experiments.otb import ExperimentOTB

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
DATA = ROOT / "tests" / "data" / "trackeval"
PYSOT_FUNCTIONS = ("overlap_ratio", "success_overlap", "success_error")


def _experiment() -> ExperimentOTB:
    """An ``ExperimentOTB`` without its dataset (its constructor would download OTB): only
    the bin counts its ``_calc_metrics`` / ``_calc_curves`` use are set, as its
    ``__init__`` sets them."""
    exp = ExperimentOTB.__new__(ExperimentOTB)
    exp.nbins_iou = 21
    exp.nbins_ce = 51
    return exp


def _load_pysot(folder: Path) -> dict[str, Any]:
    """pysot-toolkit's ``overlap_ratio``, ``success_overlap`` and ``success_error``, from
    ``pysot/utils/statistics.py`` as written, without the numba ``@jit`` decorator."""
    source = (folder / "pysot" / "utils" / "statistics.py").read_text()
    tree = ast.parse(source)
    defs = [n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name in PYSOT_FUNCTIONS]
    for d in defs:
        d.decorator_list = []
    namespace: dict[str, Any] = {"np": np}
    exec(compile(ast.Module(body=defs, type_ignores=[]), str(folder), "exec"), namespace)
    return {name: namespace[name] for name in PYSOT_FUNCTIONS}


def _pysot_centre(b: np.ndarray) -> np.ndarray:
    # pysot's OPEBenchmark.convert_bb_to_center
    return np.array([(b[:, 0] + (b[:, 2] - 1) / 2), (b[:, 1] + (b[:, 3] - 1) / 2)]).T


def _read_rows(path: Path, n_frames: int, keep_class: int | None) -> dict[int, np.ndarray]:
    """Boxes (T, 4) per id from a MOT file (1-based frames and pixels; NaN: no row)."""
    tracks: dict[int, np.ndarray] = {}
    text = path.read_text().split()
    for line in text:
        cells = line.split(",")
        if keep_class is not None and int(float(cells[7])) != keep_class:
            continue
        t, ident = int(float(cells[0])) - 1, int(float(cells[1]))
        box = tracks.setdefault(ident, np.full((n_frames, 4), np.nan))
        box[t] = [float(c) for c in cells[2:6]]
    return tracks


def _n_frames(seq_folder: Path) -> int:
    for line in (seq_folder / "seqinfo.ini").read_text().splitlines():
        if line.startswith("seqLength="):
            return int(line.split("=", 1)[1])
    raise SystemExit(f"{seq_folder}: no seqLength")


def _got10k(exp: ExperimentOTB, est: np.ndarray, gt: np.ndarray) -> dict[str, Any]:
    ious, errors = exp._calc_metrics(est.copy(), gt.copy())
    succ, prec = exp._calc_curves(ious, errors)
    return {
        "success": [float(v) for v in succ],
        "precision": [float(v) for v in prec],
        "auc": float(np.mean(succ)),
        "p20": float(prec[20]),
    }


def _pysot(fns: dict[str, Any], est: np.ndarray, gt: np.ndarray) -> dict[str, float]:
    n = len(gt)
    succ = fns["success_overlap"](gt, est, n)
    prec = fns["success_error"](_pysot_centre(gt), _pysot_centre(est), np.arange(0, 51, 1), n)
    return {"auc": float(np.mean(succ)), "p20": float(prec[20])}


def score_case(
    exp: ExperimentOTB, pysot: dict[str, Any] | None, est: np.ndarray, gt: np.ndarray
) -> dict[str, Any]:
    """All the conventions of one (target, track) case; ``gt`` NaN where absent."""
    scored = np.all(np.isfinite(gt), axis=1)
    exported = np.where(scored[:, None], gt, 0.0)  # scenegen's OTB export: 0,0,0,0
    ref = _got10k(exp, est[scored], gt[scored])
    est0 = est.copy()
    if scored[0]:
        est0[0] = gt[0]
    frame0 = _got10k(exp, est0[scored], gt[scored])
    absent = _got10k(exp, est, exported)
    full = est.copy()
    full[0] = exported[0]  # ExperimentOTB.report: boxes[0] = anno[0]
    got = _got10k(exp, full, exported)
    case: dict[str, Any] = {
        "frames": int(scored.sum()),
        "scored": ref,
        "frame0": {"auc": frame0["auc"], "p20": frame0["p20"]},
        "absent": {"auc": absent["auc"], "p20": absent["p20"]},
        "got10k": {"auc": got["auc"], "p20": got["p20"]},
    }
    if pysot is not None:
        case["scored"]["pysot"] = _pysot(pysot, est[scored], gt[scored])
        case["pysot_all"] = _pysot(pysot, est, exported)
    return case


def _git_commit(path: Path) -> str | None:
    try:
        return subprocess.run(
            ["git", "-C", str(path), "rev-parse", "HEAD"],
            check=True,
            capture_output=True,
            text=True,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None


def main() -> None:
    parser = argparse.ArgumentParser(description="Score the committed MOT files with got10k.")
    parser.add_argument("--pysot", type=Path, help="a checkout of pysot-toolkit (second opinion)")
    parser.add_argument("--pysot-commit", help="pysot-toolkit commit (when not a git checkout)")
    parser.add_argument("--out", type=Path, default=ROOT / "tests" / "data" / "otb" / "oracle.json")
    args = parser.parse_args()
    exp = _experiment()
    pysot = _load_pysot(args.pysot) if args.pysot else None
    oracle: dict[str, Any] = {
        "tool": "got10k ExperimentOTB",
        "got10k": importlib.metadata.version("got10k"),
        "pysot_toolkit": (args.pysot_commit or _git_commit(args.pysot)) if args.pysot else None,
        "numpy": np.__version__,
        "python": sys.version.split()[0],
        "cases": {},
    }
    gt_root = DATA / "gt" / "amodal"
    trackers = sorted(p.name for p in (DATA / "trackers").iterdir() if p.is_dir())
    for seq_folder in sorted(p for p in gt_root.iterdir() if p.is_dir()):
        n = _n_frames(seq_folder)
        targets = _read_rows(seq_folder / "gt" / "gt.txt", n, keep_class=1)
        for tracker in trackers:
            tracks = _read_rows(DATA / "trackers" / tracker / f"{seq_folder.name}.txt", n, None)
            tracks_none = {**{str(k): v for k, v in sorted(tracks.items())},
                           "none": np.full((n, 4), np.nan)}  # fmt: skip
            table = oracle["cases"].setdefault(tracker, {}).setdefault(seq_folder.name, {})
            for target, gt in sorted(targets.items()):
                table[str(target)] = {
                    track: score_case(exp, pysot, est, gt) for track, est in tracks_none.items()
                }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps(oracle, indent=1, sort_keys=True)
    # a curve, or a dict of numbers, on one line: the file stays small and a diff shows the
    # case that changed
    text = re.sub(r"([\[{])\n\s*([^\[\]{}]*?)\n\s*([\]}])",
                  lambda m: m[1] + " ".join(m[2].split()) + m[3], text)  # fmt: skip
    args.out.write_text(text + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
