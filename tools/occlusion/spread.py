"""Whether the walker's spread decides the occlusion scenes: success against σ.

Usage::

    python tools/occlusion/spread.py --seeds 1,2,3 --sigmas 1,2,3,4 -o DIR

The DPS paper explains its Table 3 by spread: the occluded object's "dynamics must be
sufficiently spread so that particles can cross the distracting face", and PS's ordering
reduces that spread. This tool asks the first half of that on our scenes: it runs
``scenegen experiment dps-occlusion`` (both presets) once per base seed and tracker
dynamics σ_u = σ_v = σ (``--param sigma=[σ, σ, 0.001]`` for every method; the runs stay
paired across σ) into ``DIR/sigma-<σ>/seed-<N>/``, resuming what is there, and prints

- per preset and σ, each method's walker success (the experiment's own success, frame 0
  excluded) and the PS orderings pooled;
- per preset, the success of PS and DPS pooled at the largest σ minus the smallest, with
  the paired bootstrap over scenes (each (base seed, scene) a cluster;
  :func:`scenegen.lab.experiments.stats.bootstrap_clustered_diff`, seeded).

A difference near 0 says the scene's failures are not spread-limited, so no sampling
scheme could act on them through the spread. ``tools/occlusion/cycle.py … --param
'sigma=[σ, σ, 0.001]'`` measures the spread itself. docs/experiments.md ("Does the
walker's spread decide it?") used it. Use tuning seeds: this is an analysis.
"""

from __future__ import annotations

import argparse
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from scenegen.cli import main as scenegen_main
from scenegen.lab.experiments.stats import bootstrap_clustered_diff

sys.path.insert(0, str(Path(__file__).resolve().parent))
from independence import EXPERIMENT, outcomes  # noqa: E402  (the sibling tool's reader)


def _ints(text: str) -> list[int]:
    return [int(v) for v in text.split(",") if v.strip()]


def _floats(text: str) -> list[float]:
    return [float(v) for v in text.split(",") if v.strip()]


def folder(out: Path, sigma: float, seed: int) -> Path:
    """``OUT/sigma-<σ>/seed-<N>``, σ written as it was given (``2`` or ``2.5``)."""
    return out / f"sigma-{sigma:g}" / f"seed-{seed}"


def run(out: Path, sigmas: list[float], seeds: list[int], extra: list[str]) -> None:
    """Run (or resume) every (σ, seed) experiment; a failure stops with its exit code."""
    for sigma in sigmas:
        for seed in seeds:
            code = scenegen_main(["experiment", EXPERIMENT, "--seed", str(seed), "--param",
                                  f"sigma=[{sigma:g}, {sigma:g}, 0.001]", *extra,
                                  "-o", str(folder(out, sigma, seed))])  # fmt: skip
            if code:
                raise SystemExit(code)


def table(out: Path, sigmas: list[float], seeds: list[int]) -> list[str]:
    """The printed lines (see the module docstring)."""
    # preset -> σ -> method label -> (seed, scene) -> outcomes of that scene's runs
    got: dict[str, dict[float, dict[str, dict[tuple[int, int], list[bool]]]]] = defaultdict(
        lambda: defaultdict(lambda: defaultdict(lambda: defaultdict(list))))
    for sigma in sigmas:
        for seed in seeds:
            for preset, runs in outcomes(folder(out, sigma, seed)).items():
                for label, cases in runs.items():
                    for (scene, _), ok in sorted(cases.items()):
                        got[preset][sigma][label][(seed, scene)].append(ok)
    lines = []
    for preset in sorted(got):
        for sigma in sigmas:
            by = got[preset][sigma]
            rate = {lb: float(np.mean([v for c in by[lb].values() for v in c])) for lb in by}
            ps = [v for lb in by if lb.startswith("PS(") for c in by[lb].values() for v in c]
            cells = ", ".join(f"{lb} {100 * r:.0f} %" for lb, r in rate.items())
            lines.append(f"{preset} sigma {sigma:g}: {cells}; PS pooled "
                         f"{100 * float(np.mean(ps)):.0f} %")  # fmt: skip

        def pooled(sigma: float, preset: str = preset) -> dict[tuple[int, int], list[bool]]:
            cl: dict[tuple[int, int], list[bool]] = defaultdict(list)
            for lb, cases in got[preset][sigma].items():
                if lb == "DPS" or lb.startswith("PS("):
                    for key, oks in cases.items():
                        cl[key] += oks
            return cl

        lo, hi = min(sigmas), max(sigmas)
        if lo != hi:
            low = pooled(lo)
            d, (a, b), _ = bootstrap_clustered_diff(pooled(hi), low, rng=0)
            lines.append(f"{preset}: PS and DPS pooled, sigma {hi:g} - sigma {lo:g}: "
                         f"{100 * d:+.1f} points (95 % interval {100 * a:+.1f} to "
                         f"{100 * b:+.1f}; {len(low)} scenes)")  # fmt: skip
    return lines


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=_ints, default=[1, 2, 3], help="base seeds (tuning seeds)")
    ap.add_argument("--sigmas", type=_floats, default=[1.0, 2.0, 3.0, 4.0])
    ap.add_argument("--scenes", type=int)
    ap.add_argument("--runs", type=int)
    ap.add_argument("--jobs", type=int)
    ap.add_argument("--method", action="append", default=[])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("-o", "--output", type=Path, required=True)
    args = ap.parse_args(argv)
    extra = [*(["--scenes", str(args.scenes)] if args.scenes else []),
             *(["--runs", str(args.runs)] if args.runs else []),
             *(["--jobs", str(args.jobs)] if args.jobs else []),
             *[a for m in args.method for a in ("--method", m)],
             *(["--quick"] if args.quick else [])]  # fmt: skip
    run(args.output, args.sigmas, args.seeds, extra)
    print("\n".join(table(args.output, args.sigmas, args.seeds)))


if __name__ == "__main__":
    main()
