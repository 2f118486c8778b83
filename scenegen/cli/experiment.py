"""The ``experiment`` verb: run one of the papers' experiments, locally or on Dask."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

__all__ = ["cmd_experiment", "register"]


def register(sub: argparse._SubParsersAction) -> None:
    from scenegen.lab.experiments import names

    p = sub.add_parser(
        "experiment",
        help="run a paper's experiment: results.json, table.md and figures",
        description="Experiments: " + ", ".join(names()) + ". Finished runs are kept under "
        "DIR/runs/; running the same command again resumes.",
    )
    p.add_argument("name", help="experiment name")
    p.add_argument("--runs", type=int, default=None, help="runs per method (default: paper's)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--jobs", type=int, default=None, help="local processes (default: all)")
    where.add_argument("--scheduler", default=None, metavar="ADDRESS",
                       help="dask.distributed scheduler address, e.g. tcp://host:8786")
    p.add_argument("--seed", type=int, default=0, help="base seed (default 0)")
    p.add_argument("--method", action="append", default=None, metavar="NAME",
                   help="run only this method (repeatable)")
    p.add_argument("--quick", action="store_true",
                   help="scaled-down settings (fewer frames/particles), for smoke tests")
    p.add_argument("-o", "--output", required=True, type=Path, help="output folder DIR")
    p.set_defaults(func=cmd_experiment)


def cmd_experiment(args: argparse.Namespace) -> int:
    """Run the experiment and print where its table is; 0 on success.

    Raises
    ------
    ConfigError
        Unknown experiment or method (listing the valid ones), bad --runs/--jobs/--seed,
        or an unreachable scheduler (within 10 s, naming the address).
    """
    from scenegen.lab.experiments import get, run_experiment

    get(args.name)
    results = run_experiment(
        args.name,
        args.output,
        runs=args.runs,
        jobs=args.jobs,
        scheduler=args.scheduler,
        seed=args.seed,
        quick=args.quick,
        methods=args.method,
        progress=sys.stderr.isatty(),
    )
    bad = [c["claim"] for c in results["fidelity"] if not c["holds"]]
    print(f"{args.name}: {len(results['fidelity']) - len(bad)} of {len(results['fidelity'])} "
          f"paper claims hold; table: {args.output / 'table.md'}", file=sys.stderr)
    print(str((args.output / "results.json").resolve()))
    return 0
