"""The ``demo`` verb behind ``make demo``: every preset with previews, every experiment at
a reduced run count, and ``report/index.html`` linking it all."""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

__all__ = ["register"]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("demo", help="generate every preset, run the experiments, write a report")
    p.add_argument("-o", "--output", type=Path, default=Path("report"), help="report folder")
    p.add_argument("--runs", type=int, default=3, help="runs per method (default 3)")
    p.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="worker processes")
    p.add_argument("--seed", type=int, default=0, help="seed of the preset sequences")
    p.set_defaults(func=cmd_demo)


def _say(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def generate_presets(out: Path, seed: int) -> list[Path]:
    """Generate every preset into ``out/presets/`` with a PNG sheet and a GIF each."""
    from scenegen import presets
    from scenegen.io import write
    from scenegen.io.preview import write_preview
    from scenegen.render.plan import generate

    folder = out / "presets"
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for name in presets.names():
        t0 = time.perf_counter()
        seq = generate(name, seed=seed)
        write(folder / f"{name}.h5", seq)
        write_preview(seq, folder / f"{name}.png")
        write_preview(seq, folder / f"{name}.gif", max_frames=80)
        written.append(folder / f"{name}.h5")
        _say(f"  preset {name}: {seq.n_frames} frames ({time.perf_counter() - t0:.1f} s)")
    return written


def cmd_demo(args: argparse.Namespace) -> int:
    from scenegen.errors import ConfigError
    from scenegen.lab.report import build_report, run_demo_experiments

    if args.runs < 1 or args.jobs < 1:
        raise ConfigError(f"--runs and --jobs must be >= 1, got {args.runs} and {args.jobs}")
    out: Path = args.output
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    _say(f"[1/3] generating every preset into {out / 'presets'}")
    generate_presets(out, args.seed)
    _say(f"[2/3] running every experiment ({args.runs} runs per method, {args.jobs} jobs)")
    run_demo_experiments(out, runs=args.runs, jobs=args.jobs)
    _say("[3/3] building the report")
    index = build_report(out)
    _say(f"done in {time.perf_counter() - t0:.0f} s")
    print(f"report: {Path(index).resolve()}")
    return 0
