"""The ``fixtures`` verb: check or rewrite the committed regression fixtures.

``scenegen fixtures verify`` exits 1 naming every mismatch (one line each, on stderr);
``scenegen fixtures regen`` rewrites what changed and lists it.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from scenegen.cli.progress import bar

__all__ = ["register"]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("fixtures", help="verify or regenerate the committed regression fixtures")
    actions = p.add_subparsers(dest="action", metavar="ACTION")
    actions.required = True
    for action, help_text, func in (
        (
            "verify",
            "check that regeneration gives the same contents and every tracker its "
            "expected output (exit 1 naming each mismatch)",
            cmd_verify,
        ),
        (
            "regen",
            "rewrite the fixtures, expected outputs and registry; list what changed",
            cmd_regen,
        ),
    ):
        a = actions.add_parser(action, help=help_text, description=help_text)
        a.add_argument(
            "--dir", type=Path, default=None,
            help="fixtures folder (default: the repository's fixtures/, else ./fixtures)",
        )  # fmt: skip
        a.add_argument(
            "--fixture", action="append", default=None, metavar="NAME",
            help="only this fixture (repeatable; default all)",
        )  # fmt: skip
        a.add_argument(
            "--tracker", action="append", default=None, metavar="NAME",
            help="only this tracker (repeatable; default every tracker)",
        )  # fmt: skip
        a.set_defaults(func=func)


def _count(args: argparse.Namespace) -> int:
    import trackers
    from scenegen.testing.fixtures import definitions

    n_fix = len(args.fixture) if args.fixture else len(definitions())
    n_trk = len(args.tracker) if args.tracker else len(trackers.names())
    return n_fix * (n_trk + 1)


def _regen_command(args: argparse.Namespace) -> str:
    """The ``regen`` command for the folder, fixtures and trackers ``verify`` was given."""
    import shlex

    words = ["scenegen", "fixtures", "regen"]
    if args.dir is not None:
        words += ["--dir", str(args.dir)]
    words += [w for n in args.fixture or [] for w in ("--fixture", n)]
    words += [w for n in args.tracker or [] for w in ("--tracker", n)]
    return shlex.join(words)


def cmd_verify(args: argparse.Namespace) -> int:
    from scenegen.lab.regen import verify
    from scenegen.testing.fixtures import default_dir

    folder = args.dir if args.dir is not None else default_dir()
    start = time.perf_counter()
    with bar(_count(args), "fixtures verify", unit="run") as pb:
        problems = verify(
            folder,
            fixtures=args.fixture,
            tracker_names=args.tracker,
            progress=lambda label: (pb.set_postfix_str(label), pb.update(1)),
        )
    for line in problems:
        print(f"scenegen: mismatch: {line}", file=sys.stderr)
    took = time.perf_counter() - start
    if problems:
        print(
            f"{folder}: {len(problems)} mismatches ({took:.1f} s); if the changes are "
            f"intended, run `{_regen_command(args)}` and commit the folder"
        )
        return 1
    print(f"{folder}: fixtures and tracker outputs match ({took:.1f} s)")
    return 0


def cmd_regen(args: argparse.Namespace) -> int:
    from scenegen.lab.regen import regen
    from scenegen.testing.fixtures import default_dir

    folder = args.dir if args.dir is not None else default_dir()
    with bar(_count(args), "fixtures regen", unit="run") as pb:
        changes, errors = regen(
            folder,
            fixtures=args.fixture,
            tracker_names=args.tracker,
            progress=lambda label: (pb.set_postfix_str(label), pb.update(1)),
        )
    for line in changes:
        print(line)
    if not changes:
        print(f"{folder}: nothing changed")
    for line in errors:
        print(f"scenegen: error: {line}", file=sys.stderr)
    return 1 if errors else 0
