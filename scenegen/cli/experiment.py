"""The ``experiment`` verb: run one of the papers' experiments (or ``all``), locally or on
Dask."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from scenegen.cli.options import seed_arg

__all__ = ["cmd_experiment", "parse_overrides", "register"]


def register(sub: argparse._SubParsersAction) -> None:
    from scenegen.lab.experiments import names

    p = sub.add_parser(
        "experiment",
        help="run a paper's experiment (or all): results.json, table.md and figures",
        description="Experiments: " + ", ".join(names()) + "; `all` runs every one into "
        "DIR/experiments/<name>/ and writes the report DIR/index.html. Finished runs are kept "
        "under .../runs/; running the same command again resumes.",
    )
    p.add_argument("name", help="experiment name, or `all`")
    p.add_argument("--runs", type=int, default=None,
                   help="tracker runs R per scene (default: the experiment's)")
    p.add_argument("--scenes", type=int, default=None,
                   help="scenes S per preset (default: the experiment's)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--jobs", type=int, default=None, help="local processes (default: all)")
    where.add_argument("--scheduler", default=None, metavar="ADDRESS",
                       help="dask.distributed scheduler address, e.g. tcp://host:8786")
    p.add_argument("--seed", type=seed_arg, default=0, help="base seed (default 0)")
    p.add_argument("--method", action="append", default=None, metavar="NAME",
                   help="run only this method (repeatable; not with `all`)")
    p.add_argument("--param", action="append", default=None, metavar="KEY=VALUE",
                   help="set a tracker parameter on every method run, e.g. kernel=box; VALUE is "
                   "read as JSON when it parses, else as a string (repeatable; not with "
                   "`all`); the runs stay paired with the default ones")
    p.add_argument("--value", action="append", type=float, default=None, metavar="V",
                   help="run only this value of the swept parameter, e.g. λ = 20 for "
                   "dps-synthetic (repeatable; not with `all`)")
    p.add_argument("--quick", action="store_true",
                   help="scaled-down settings (fewer frames/particles), for smoke tests")
    p.add_argument("-o", "--output", required=True, type=Path, help="output folder DIR")
    p.set_defaults(func=cmd_experiment)


def _say_verdicts(name: str, results: dict, where: Path) -> None:
    from scenegen.lab.experiments import verdict_counts

    c = verdict_counts(results)
    print(f"{name}: {c['reproduced']} reproduced, {c['not reproduced']} not reproduced, "
          f"{c['inconclusive']} inconclusive; table: {where}", file=sys.stderr)


def parse_overrides(items: list[str] | None) -> dict:
    """``["kernel=box", "box_levels=4"]`` -> ``{"kernel": "box", "box_levels": 4}``.

    As ``scenegen track --param``: a value is read as JSON when it parses (``4``,
    ``[2, 2, 0.001]``, ``null``), else kept as the string.

    Raises
    ------
    ConfigError
        For an item without ``=`` or a parameter given twice.
    """
    from scenegen.cli.track import parse_params
    from scenegen.errors import ConfigError

    out: dict = {}
    for item in items or ():
        parsed = parse_params([item])
        name = next(iter(parsed))
        if name in out:
            raise ConfigError(f"--param {name} given twice")
        out.update(parsed)
    return out


def cmd_experiment(args: argparse.Namespace) -> int:
    """Run the experiment (or all of them) and print where the results are; 0 on success.

    Raises
    ------
    ConfigError
        Unknown experiment, method or swept value (listing the valid ones), bad
        --runs/--scenes/--jobs/--seed/--param, or an unreachable scheduler (within 10 s,
        naming the address).
    """
    from scenegen.errors import ConfigError
    from scenegen.lab.experiments import get, run_experiment

    if args.name == "all":
        from scenegen.lab.report import run_all

        if args.method or args.value:
            raise ConfigError("--method and --value cannot be used with `experiment all`")
        if args.param:
            raise ConfigError("--param cannot be used with `experiment all`")
        index = run_all(args.output, runs=args.runs, scenes=args.scenes, jobs=args.jobs,
                        scheduler=args.scheduler, seed=args.seed, quick=args.quick,
                        progress=sys.stderr.isatty(), say=_say_verdicts)
        print(str(Path(index).resolve()))
        return 0
    get(args.name)
    results = run_experiment(
        args.name,
        args.output,
        runs=args.runs,
        scenes=args.scenes,
        jobs=args.jobs,
        scheduler=args.scheduler,
        seed=args.seed,
        quick=args.quick,
        methods=args.method,
        values=args.value,
        progress=sys.stderr.isatty(),
        overrides=parse_overrides(args.param),
    )
    _say_verdicts(args.name, results, args.output / "table.md")
    print(str((args.output / "results.json").resolve()))
    return 0
