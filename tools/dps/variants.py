"""The DPS experiments on variants of their scenes and trackers, for analyses.

Usage::

    python tools/dps/variants.py dps-synthetic --seeds 1,2,3 -o /tmp/v --astray
    python tools/dps/variants.py dps-synthetic --seeds 1,2,3 -o /tmp/v --lam 150
    python tools/dps/variants.py dps-occlusion --seeds 7 -o /tmp/v --lam 150 \\
        --method ps-123 --method ps-231 --method ps-312 --method dps --param weighting=stage
    python tools/dps/variants.py dps-occlusion --seeds 1,2,3 --crowd --scenes 3 --runs 2 -o /tmp/v

It runs ``scenegen experiment NAME`` once per base seed into ``OUT/seed-<N>/`` (the same
``results.json``, ``table.md`` and run records), with any of:

- ``--astray``: the distractor of ``dps-synthetic`` is present from frame 0, drawn over
  object 1, so that every tracker learns object 1's model from the distractor, as the DPS
  paper did (§3.3: "the histogram model was learned from a distracter object"); it still
  drifts 8 px/frame to the right and vanishes at frame 9. In the preset the model is
  learned from object 1 itself and the distractor appears at frame 3;
- ``--lam V`` (repeatable): run at λ = V instead of the experiment's λ (``dps-synthetic``
  sweeps 20…50; the others use one λ), e.g. a λ at which PS's first-stage uniqueness is
  as low as the paper's (1.99 of 300 particles at λ = 20, DPS §3.3);
- ``--crowd``: the occlusion scenes with four more tracked objects (looks 2–5 of
  ``dps-synthetic``, 30x30, standing near the frame's corners, away from the walker's
  path), so that seven objects are tracked as on ``dps-synthetic``, with its N = 300
  and its seven circular-shift PS orderings; the paper expects impoverishment to "only
  become more pronounced as ... more objects are added" (DPS §3.3);
- ``--preset NAME``: run only this preset of the experiment (``dps-occlusion`` has two);
- ``--tune KEY=VALUE`` (repeatable): set one of the preset's tuned quantities, the entries
  of its ``*_TUNING`` dict in :mod:`scenegen.presets` (``OCCLUSION_TUNING``,
  ``OCCLUSION2_TUNING``, ``DANCERS_TUNING``), VALUE read as JSON with lists as tuples, e.g.
  ``--preset dps-occlusion-2 --tune 'shirt2=[[40, 140, 40]]' --tune speed=1.4``;
- ``--param KEY=VALUE``, ``--method SLUG``, ``--scenes S`` and ``--runs R`` as for
  ``scenegen experiment``.

``OUT/seed-<N>/variant.json`` records the variant. The variant replaces the preset and
the experiment in this process only, so the runs use one process (``jobs = 1``); start
one command per seed to use more cores. The analyses that used it are in
docs/experiments.md ("Other readings of PS, and the paper's conditions"). Tune only on
seeds that are not then used to judge.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path

from scenegen import presets
from scenegen.cli.experiment import parse_overrides
from scenegen.config import Appearance, EntitySpec
from scenegen.lab.experiments import definitions, run_experiment

DPS_EXPERIMENTS = ("dps-synthetic", "dps-occlusion", "dps-dancers")


def astray(cfg):
    """``dps-synthetic`` with its distractor present, over object 1, from frame 0."""
    ents = tuple(dataclasses.replace(e, appear=0) if e.role == "distractor" else e
                 for e in cfg.entities)
    if ents == cfg.entities:
        raise SystemExit(f"--astray: preset {cfg.name} has no distractor")
    return dataclasses.replace(cfg, entities=ents)


CROWD_POSITIONS = ((70.0, 55.0), (290.0, 55.0), (70.0, 240.0), (290.0, 240.0))
"""Where ``--crowd`` stands its four extra objects (centres, px)."""


def crowd(cfg):
    """``cfg`` with four more tracked, stationary objects: looks 2–5 of ``dps-synthetic``
    at :data:`CROWD_POSITIONS`, behind everything else (they overlap nothing)."""
    top = max(d for e in cfg.entities for _, d in e.depth)
    extra = tuple(
        EntitySpec(name=f"extra{i + 1}", role="target",
                   appearance=Appearance(shape=shape, size=(30, 30), pattern=pattern,
                                         colors=colors),
                   position=pos, depth=((0, top + 1 + i),))
        for i, ((shape, pattern, colors), pos) in enumerate(
            zip(presets._DPS_LOOKS[1:5], CROWD_POSITIONS, strict=True)))
    return dataclasses.replace(cfg, entities=(*cfg.entities, *extra))


def crowd_experiment(exp: definitions.Experiment, m: int) -> definitions.Experiment:
    """``exp`` with ``m`` tracked objects: Non-PS, the ``m`` circular-shift PS orderings
    and DPS, at N = 300 and the experiment's λ."""
    params = tuple((k, 300 if k == "n_particles" else v) for k, v in exp.methods[0].params)
    return dataclasses.replace(exp, methods=(
        definitions.Method("Non-PS", "nonps", "joint-pf", params),
        *definitions._ps_methods(m, params),
        definitions.Method("DPS", "dps", "dps", params)))


def with_lam(exp: definitions.Experiment, lams: tuple[float, ...]) -> definitions.Experiment:
    """The experiment at the λ values ``lams``: its sweep if it sweeps λ, else every
    method's ``lam`` (one value)."""
    if exp.sweep and exp.sweep[0][0] == "lam":
        return dataclasses.replace(exp, sweep=(("lam", lams),))
    if len(lams) != 1:
        raise SystemExit(f"{exp.name} does not sweep λ: give one --lam")
    methods = tuple(dataclasses.replace(m, params=(*[(k, v) for k, v in m.params if k != "lam"],
                                                   ("lam", lams[0])))
                    for m in exp.methods)
    return dataclasses.replace(exp, methods=methods)


TUNING = {"dps-occlusion": "OCCLUSION_TUNING", "dps-occlusion-2": "OCCLUSION2_TUNING",
          "dps-dancers": "DANCERS_TUNING"}
"""The dict of :mod:`scenegen.presets` that holds each tunable preset's tuned quantities."""


def _tuples(v):
    return tuple(_tuples(x) for x in v) if isinstance(v, list) else v


def tune(preset: str, items: list[str]) -> dict[str, object]:
    """Set ``KEY=VALUE`` items in ``preset``'s tuning dict (in this process); returns them."""
    if preset not in TUNING:
        raise SystemExit(f"--tune: preset {preset} has no tuned quantities; "
                         f"tunable: {', '.join(TUNING)}")
    table = getattr(presets, TUNING[preset])
    done: dict[str, object] = {}
    for key, value in parse_overrides(items).items():
        if key not in table:
            raise SystemExit(f"--tune: {preset} has no tuned quantity {key!r}; "
                             f"its quantities: {', '.join(table)}")
        table[key] = done[key] = _tuples(value)
    return done


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("experiment", choices=DPS_EXPERIMENTS)
    ap.add_argument("--seeds", required=True, help="base seeds, e.g. 1,2,3")
    ap.add_argument("-o", "--output", required=True, type=Path)
    ap.add_argument("--astray", action="store_true",
                    help="dps-synthetic: the distractor over object 1 from frame 0")
    ap.add_argument("--crowd", action="store_true",
                    help="dps-occlusion: four more tracked objects (seven in all), N = 300")
    ap.add_argument("--lam", action="append", type=float, default=None)
    ap.add_argument("--scenes", type=int, default=None)
    ap.add_argument("--runs", type=int, default=None)
    ap.add_argument("--param", action="append", default=None, metavar="KEY=VALUE")
    ap.add_argument("--method", action="append", default=None, metavar="SLUG")
    ap.add_argument("--preset", default=None, help="run only this preset of the experiment")
    ap.add_argument("--tune", action="append", default=[], metavar="KEY=VALUE",
                    help="a tuned quantity of the preset, VALUE as JSON (lists as tuples)")
    args = ap.parse_args()
    exp = definitions.EXPERIMENTS[args.experiment]
    if args.preset is not None:
        if args.preset not in exp.presets:
            raise SystemExit(f"--preset: {args.experiment} has the presets "
                             f"{', '.join(exp.presets)}")
        exp = definitions.EXPERIMENTS[args.experiment] = dataclasses.replace(
            exp, presets=(args.preset,))
    tuned = {}
    if args.tune:
        if args.preset is None and len(exp.presets) != 1:
            raise SystemExit(f"--tune: name the preset (--preset), {args.experiment} has "
                             f"{', '.join(exp.presets)}")
        tuned = tune(exp.presets[0], args.tune)
    if args.astray:
        if args.experiment != "dps-synthetic":
            raise SystemExit("--astray applies to dps-synthetic only")
        base = presets._PRESETS["dps-synthetic"]
        presets._PRESETS["dps-synthetic"] = lambda: astray(base())
    if args.crowd:
        if args.experiment != "dps-occlusion":
            raise SystemExit("--crowd applies to dps-occlusion only")
        for name in exp.presets:
            base_occ = presets._PRESETS[name]
            presets._PRESETS[name] = lambda b=base_occ: crowd(b())
        m = len(presets.get(exp.presets[0]).entities)
        exp = definitions.EXPERIMENTS[args.experiment] = crowd_experiment(exp, m)
    if args.lam:
        definitions.EXPERIMENTS[args.experiment] = with_lam(exp, tuple(args.lam))
    overrides = parse_overrides(args.param)
    variant = {"experiment": args.experiment, "astray": args.astray, "crowd": args.crowd,
               "lam": args.lam, "overrides": overrides, "methods": args.method,
               "scenes": args.scenes, "runs": args.runs, "preset": args.preset,
               "tune": {k: v for k, v in tuned.items()}}
    for seed in (int(s) for s in args.seeds.split(",")):
        out = args.output / f"seed-{seed}"
        results = run_experiment(args.experiment, out, seed=seed, jobs=1, methods=args.method,
                                 scenes=args.scenes, runs=args.runs,
                                 overrides=overrides or None, progress=False, figures=False)
        (out / "variant.json").write_text(json.dumps({**variant, "seed": seed}, indent=1) + "\n")
        print(f"== {out}")
        for c in results["claims"]:
            print(f"  p = {c['p_value']:.3f}  {c['verdict']:15s} {c['ours']}")


if __name__ == "__main__":
    main()
