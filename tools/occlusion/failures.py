"""Where the occluded walker is lost: each failed run's first untracked frame, placed
against the scene's events (the walker passing behind or in front of another person).

Usage (on a folder written by ``scenegen experiment dps-occlusion``)::

    python tools/occlusion/failures.py DIR

For every preset and method in ``DIR/runs/`` it prints the runs that fail (a run
*succeeds* when the walker is tracked in every frame but frame 0, the experiment's
success), the median first untracked frame, and how many of the failures begin at each
event of the scene: an **event** is the span of frames in which the walker's amodal box
overlaps another person's horizontally, named ``behind NAME`` or ``in front of NAME`` by
the ground-truth depth, extended by ``--grace`` frames after the boxes part (a run that
follows the person instead of the walker is lost as they separate). A failure outside
every event is counted as ``elsewhere``. The last two columns are the walker's median
visibility at the frame it is lost (near 0 when it is lost while hidden, near 1 when the
tracker leaves a visible walker for the person it has just crossed) and the median
number of frames since it was last hidden (visibility below 5 %).

The scenes are generated again from the records' seeds (one per preset and scene), so the
folder need not hold the sequences. The analysis in docs/experiments.md ("Where the
walker is lost") used it.
"""

from __future__ import annotations

import argparse
import functools
import glob
from collections import defaultdict
from pathlib import Path

import numpy as np

import scenegen
from scenegen.lab.experiments.definitions import get
from scenegen.lab.experiments.outputs import read_record
from scenegen.lab.experiments.runner import scene_seed

EXPERIMENT = "dps-occlusion"
HIDDEN = 0.05  # visible fraction below which the walker counts as hidden


@functools.lru_cache(maxsize=64)
def _scene(preset: str, base: int, scene: int) -> tuple[tuple[tuple[str, int, int], ...],
                                                         np.ndarray]:  # fmt: skip
    """The scene's crossings (name, first frame, last frame) and the walker's visible
    fraction per frame, shape (T,), from one generation of the scene."""
    seq = scenegen.generate(preset, seed=scene_seed(base, EXPERIMENT, preset, scene))
    gt = seq.gt
    walker = int(seq.initial_targets(0)[0])  # the walker is the first target of both presets
    box = np.asarray(gt.box, dtype=np.float64)
    depth = np.asarray(gt.depth)
    out = []
    for j in range(box.shape[1]):
        if j == walker:
            continue
        lo = np.maximum(box[:, walker, 0], box[:, j, 0])
        hi = np.minimum(box[:, walker, 0] + box[:, walker, 2], box[:, j, 0] + box[:, j, 2])
        frames = np.flatnonzero(hi > lo)
        if frames.size == 0:
            continue
        mid = int(frames[frames.size // 2])
        where = "behind" if depth[mid, walker] > depth[mid, j] else "in front of"
        out.append((f"{where} {seq.entities.name[j]}", int(frames[0]), int(frames[-1])))
    vis = np.asarray(gt.visibility[:, walker], dtype=np.float64)
    return tuple(sorted(out, key=lambda e: e[1])), vis


def events(preset: str, base: int, scene: int, grace: int) -> tuple[tuple[str, int, int], ...]:
    """The scene's events, in time order: (name, first frame, last frame + grace) per
    person whose box the walker's overlaps."""
    return tuple((n, a, b + grace) for n, a, b in _scene(preset, base, scene)[0])


def visibility(preset: str, base: int, scene: int) -> np.ndarray:
    """The walker's visible fraction per frame, shape (T,)."""
    return _scene(preset, base, scene)[1]


def first_lost(state: list[int | None]) -> int | None:
    """The first frame after frame 0 where the walker is not tracked, None if never."""
    for t, s in enumerate(state[1:], start=1):
        if s is not None and not s:
            return t
    return None


def lost(folder: str | Path, grace: int = 10
         ) -> tuple[dict[tuple[str, str], list[tuple]], dict[str, list[str]]]:  # fmt: skip
    """Per (preset, method label): one (first lost frame, event, visibility then, frames
    since the walker was last hidden or None) per failed run, and Nones per run that
    succeeds; and per preset the names of its scenes'
    events in time order, then ``elsewhere``."""
    exp = get(EXPERIMENT)
    labels = {m.slug: m.label for m in exp.methods}
    out: dict[tuple[str, str], list[tuple]] = defaultdict(list)
    names: dict[str, list[str]] = defaultdict(list)
    for path in sorted(glob.glob(str(Path(folder) / "runs" / "*.json"))):
        rec = read_record(path)  # sealed: a damaged record is one DataError line
        key = rec["key"]
        scene_events = events(key["preset"], key["seed"], key["scene"], grace)
        names[key["preset"]] += [n for n, _, _ in scene_events if n not in names[key["preset"]]]
        walker = next(t for t in rec["targets"] if t["name"] == exp.hard_target)
        t = first_lost(walker["state"])
        label = labels[key["method"]]
        if t is None:
            out[(key["preset"], label)].append((None, None, None, None))
            continue
        where = next((n for n, a, b in scene_events if a <= t <= b), "elsewhere")
        vis = visibility(key["preset"], key["seed"], key["scene"])
        hidden = np.flatnonzero(vis[:t + 1] < HIDDEN)
        since = int(t - hidden[-1]) if hidden.size else None
        out[(key["preset"], label)].append((t, where, float(vis[t]), since))
    return dict(out), {p: [*n, "elsewhere"] for p, n in names.items()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", help="a folder of `scenegen experiment dps-occlusion`")
    ap.add_argument("--grace", type=int, default=10,
                    help="frames after the boxes part that still count as the event")
    args = ap.parse_args()
    table, event_names = lost(args.folder, args.grace)
    order = [m.label for m in get(EXPERIMENT).methods]
    for preset, names in sorted(event_names.items()):
        print(f"{preset}: method, failed / runs, median first lost frame, "
              f"failures at {', '.join(names)}, median visibility when lost, median frames "
              "since last hidden")
        for label in order:
            rows = table.get((preset, label))
            if not rows:
                continue
            fails = [r for r in rows if r[0] is not None]
            med = f"{np.median([r[0] for r in fails]):.0f}" if fails else "-"
            vis = f"{np.median([r[2] for r in fails]):.2f}" if fails else "-"
            gaps = [r[3] for r in fails if r[3] is not None]
            since = f"{np.median(gaps):.0f}" if gaps else "-"
            counts = " ".join(f"{sum(r[1] == n for r in fails):3d}" for n in names)
            print(f"  {label:10s} {len(fails):3d} / {len(rows):3d}  {med:>5s}  {counts}  {vis}"
                  f"  {since:>4s}")


if __name__ == "__main__":
    main()
