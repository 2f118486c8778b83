"""The ``demo`` verb behind ``make demo``: every preset with previews, every experiment at
reduced scene and run counts (indicative verdicts), and ``report/index.html``."""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from scenegen.cli.options import seed_arg

__all__ = ["register"]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("demo", help="generate every preset, run the experiments, write a report")
    p.add_argument("-o", "--output", type=Path, default=Path("report"), help="report folder")
    p.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="worker processes")
    p.add_argument("--seed", type=seed_arg, default=0,
                   help="seed of the preset sequences written to OUTPUT/presets/ (default 0); "
                        "the experiments always run on base seed 0, the seed of the demo's "
                        "rerun command (`scenegen demo -o DIR`)")
    p.set_defaults(func=cmd_demo)


def _say(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def cmd_demo(args: argparse.Namespace) -> int:
    from scenegen.errors import ConfigError
    from scenegen.lab.demo_presets import generate_presets
    from scenegen.lab.report import build_report, check_report_folder, run_demo_experiments

    if args.jobs < 1:
        raise ConfigError(f"--jobs must be >= 1, got {args.jobs}")
    out: Path = args.output
    check_report_folder(out)  # before any preset is written into it
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    _say(f"[1/3] generating every preset into {out / 'presets'}")
    generate_presets(out, args.seed)
    _say(f"[2/3] running every experiment at reduced counts ({args.jobs} jobs); verdicts are "
         "indicative, the full run is `scenegen experiment all -o out/`")
    run_demo_experiments(out, jobs=args.jobs)
    _say("[3/3] building the report")
    index = build_report(out)
    _say(f"done in {time.perf_counter() - t0:.0f} s")
    print(f"report: {Path(index).resolve()}")
    return 0
