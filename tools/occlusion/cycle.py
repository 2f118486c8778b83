"""The occluded walker's particle diversity at the same point of every method's cycle.

Usage (tuning seeds only; never the judged base seed 0)::

    python tools/occlusion/cycle.py dps-occlusion --seeds 1,2,3 --scenes 3 --runs 1

For each method of the ``dps-occlusion`` experiment it prints, averaged over frames 1..T-1
(and over the frames where the walker is totally hidden, visibility < 5 %):

- *ancestors*: distinct walker sub-states among the particles that are about to be
  propagated for the walker, divided by N: how many hypotheses its dynamics spread from;
- *spread*: the standard deviation (px) of the walker's u over its propagated candidates;
- *end uniqueness*: the walker's uniqueness at the end of the step (what ``Estimate.extras``
  and the experiment records report, DPS Fig. 8).

The end-of-step uniqueness depends on where the walker sits in the ordering; the first two
are measured at the walker's own propagation, the same point of the cycle for every
method (docs/experiments.md, "DPS Table 3: why the orderings cannot differ with the
`placed` weighting"). Those numbers are of ``--weighting placed``; the default is the
trackers' own (``stage``, the papers' weighting, since round 4), measured in
"DPS Table 3 with the `stage` weighting" (round 5). ``--param KEY=VALUE`` sets a tracker
parameter of every method that has it, as ``scenegen experiment --param`` reads it, e.g.
``--param lam=150`` or ``--param resample_scope=placed`` (PS and DPS only).
It reads the walker's states before each propagation through the trackers'
``propagation_hook`` (tested in ``tests/trackers/test_ps_cycle.py``).

``--mixture`` prints instead, per scene and run, DPS's largest mixture weight
(median and 90th percentile over the frames): how far the evidence moves the components'
shares from 1/3 (docs/experiments.md, "A fair share for every component"; ``--param
mixture=prior`` keeps them at 1/3).
"""

from __future__ import annotations

import argparse
import dataclasses

import numba
import numpy as np

import scenegen
import trackers
from scenegen.cli.experiment import parse_overrides
from scenegen.lab.experiments.definitions import get
from scenegen.lab.experiments.runner import derive_seed, scene_seed
from trackers.particle import ParticleParams


def measure(preset: str, base: int, scene: int, slug: str, run: int,
            weighting: str | None = None,
            extra: dict[str, object] | None = None) -> np.ndarray:
    """(ancestors, spread, end uniqueness) averaged over all frames, then over hidden ones."""
    exp = get("dps-occlusion")
    method = exp.method(slug)
    seq = scenegen.generate(preset, seed=scene_seed(base, exp.name, preset, scene))
    params = method.param_dict()
    if weighting is not None and method.tracker in ("ps", "dps"):
        params["weighting"] = weighting
    # Parameters of PS and DPS alone (weighting, resample_scope, …) skip the other filters.
    shared = {f.name for f in dataclasses.fields(ParticleParams)}
    params.update({k: v for k, v in (extra or {}).items()
                   if method.tracker in ("ps", "dps") or k in shared})
    tr = trackers.make(method.tracker, rng=derive_seed(base, "cycle", slug, preset, scene, run),
                       **params)
    frames = seq.frames
    tr.init(np.asarray(frames[0]), seq.init_boxes(0))
    walker = 0  # the walker is the first target of both presets
    vis = np.asarray(seq.gt.visibility[:, seq.initial_targets(0)[walker]])
    moved: list[tuple[np.ndarray, np.ndarray]] = []

    def hook(before: np.ndarray, after: np.ndarray, objects: np.ndarray) -> None:
        moved.append((before[objects == walker], after[objects == walker]))

    tr.propagation_hook = hook
    rows = []
    for t in range(1, len(frames)):
        moved.clear()
        est = tr.step(np.asarray(frames[t]))
        old = np.concatenate([b for b, _ in moved])
        new = np.concatenate([a for _, a in moved])  # the walker's propagated candidates
        rows.append((np.unique(old, axis=0).shape[0] / old.shape[0], new[:, 0].std(),
                     est.extras["uniqueness"][walker]))
    rows_a = np.asarray(rows)
    hidden = vis[1:] < 0.05
    return np.concatenate([rows_a.mean(axis=0), rows_a[hidden].mean(axis=0)])


def largest_mixture_weight(preset: str, base: int, scene: int, run: int,
                           extra: dict[str, object] | None = None) -> np.ndarray:
    """DPS's largest mixture weight max_c π_c,t over frames 1..T-1: its median and 90th
    percentile (2,). 1/C (C = 3) means that every component kept its share; with the
    evidence (``mixture="evidence"``, the default) one component takes more."""
    exp = get("dps-occlusion")
    seq = scenegen.generate(preset, seed=scene_seed(base, exp.name, preset, scene))
    params = {**exp.method("dps").param_dict(), **(extra or {})}
    tr = trackers.make("dps", rng=derive_seed(base, "mixture", preset, scene, run), **params)
    frames = seq.frames
    tr.init(np.asarray(frames[0]), seq.init_boxes(0))
    top = [tr.step(np.asarray(frames[t])).extras["mixture_weights"].max()
           for t in range(1, len(frames))]
    return np.quantile(top, [0.5, 0.9])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("preset", choices=("dps-occlusion", "dps-occlusion-2"))
    ap.add_argument("--seeds", default="1,2,3", help="base seeds (tuning seeds only)")
    ap.add_argument("--scenes", type=int, default=3)
    ap.add_argument("--runs", type=int, default=1)
    ap.add_argument("--weighting", default=None,
                    help="PS/DPS weighting (default: the trackers'; round 3 used placed)")
    ap.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                    help="a tracker parameter for every method that has it, e.g. lam=150")
    ap.add_argument("--mixture", action="store_true",
                    help="print DPS's largest mixture weight per scene instead")
    args = ap.parse_args()
    extra = parse_overrides(args.param)
    bases = [int(b) for b in args.seeds.split(",")]
    numba.set_num_threads(1)
    if args.mixture:
        print("seed scene run  largest mixture weight: median  90th percentile")
        for b in bases:
            for s in range(args.scenes):
                for r in range(args.runs):
                    q = largest_mixture_weight(args.preset, b, s, r, extra)
                    print(f"{b:4d} {s:5d} {r:3d} {q[0]:33.3f} {q[1]:16.3f}", flush=True)
        return
    print("method   ancestors %  spread px  end uniq. %  | hidden: ancestors %  spread px")
    for m in get("dps-occlusion").methods:
        v = np.mean([measure(args.preset, b, s, m.slug, r, args.weighting,
                                 extra) for b in bases
                     for s in range(args.scenes) for r in range(args.runs)], axis=0)
        print(f"{m.label:9s} {100 * v[0]:8.0f} {v[1]:10.1f} {100 * v[2]:11.0f}  | "
              f"{100 * v[3]:17.0f} {v[4]:10.1f}", flush=True)


if __name__ == "__main__":
    main()
