"""The ``bench`` verb: speed figures as medians and ratios against same-run baselines."""

from __future__ import annotations

import argparse
import json
import sys

__all__ = ["register"]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("bench", help="measure speed (medians, ratios against baselines)")
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.add_argument("--repeats", type=int, default=7, help="timed repeats per row (default 7)")
    p.add_argument("--only", default=None, help="only modules whose name contains this")
    p.add_argument("--figure", default=None, metavar="PNG",
                   help="write the scaling figure here (when the scaling rows are run)")
    p.set_defaults(func=cmd_bench)


def cmd_bench(args: argparse.Namespace) -> int:
    from scenegen.errors import ConfigError
    from scenegen.lab.bench import MODULES, format_table, run_all

    if args.repeats < 1:
        raise ConfigError(f"--repeats must be >= 1, got {args.repeats}")
    if args.only is not None and not any(args.only in name for name in MODULES):
        short = ", ".join(name.rsplit(".", 1)[-1] for name in MODULES)
        raise ConfigError(f"--only {args.only!r} matches no bench module; modules: {short}")
    rows = run_all(args.repeats, only=args.only, log=lambda m: print(m, file=sys.stderr))
    if args.figure is not None and any(r.params.get("axis") for r in rows):
        from scenegen.lab.bench.scaling import write_figure

        print(f"wrote {write_figure(rows, args.figure)}", file=sys.stderr)
    sizes = []
    if args.only is None or args.only in "scenegen.lab.bench.generation":
        from scenegen.lab.bench.generation import sizes as measure_sizes

        sizes = measure_sizes()
    if args.json:
        doc = {"repeats": args.repeats, "rows": [r.to_dict() for r in rows], "compression": sizes}
        print(json.dumps(doc, indent=2))
        return 0
    print(format_table(rows))
    if sizes:
        print("\n| preset | filter | frames: raw/stored | labels: raw/stored |")
        print("|---|---|---:|---:|")
        for s in sizes:
            print(
                f"| {s['preset']} | {s['compression']} | {s['frames_ratio']:.2f}x "
                f"| {s['labels_ratio']:.1f}x |"
            )
    return 0
