"""The ``scenegen`` command line. Each verb group lives in its own module with a
``register(subparsers)`` function; handlers return an exit code.

Exit codes: 0 success; 1 invalid data or a failed check; 2 bad usage or a bad config.
Errors print one line on stderr; ``--debug`` shows the traceback instead.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from typing import NoReturn

from scenegen.errors import ConfigError, DataError, TrackerError

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    from scenegen import __version__
    from scenegen.cli import bench, data, demo, evaluate, experiment, fixtures, track
    from scenegen.cli import benchmark as benchmark_verb
    from scenegen.cli import dataset as dataset_verb

    parser = _OneLineParser(
        prog="scenegen",
        description="Synthetic video scenarios with exact ground truth, and trackers to test.",
    )
    parser.add_argument("--version", action="version", version=f"scenegen {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks on errors")
    sub = parser.add_subparsers(dest="verb", metavar="VERB")
    sub.required = True
    for module in (data, track, evaluate, experiment, bench, demo, fixtures):
        module.register(sub)
    dataset_verb.register(sub)
    benchmark_verb.register(sub)
    for action in sub._choices_actions:  # each verb's --help opens with its one-line summary
        verb = sub.choices[action.dest]
        if verb.description is None and action.help:
            verb.description = action.help[0].upper() + action.help[1:] + "."
    return parser


class _OneLineParser(argparse.ArgumentParser):
    """argparse, with a usage error as one line (the contract: an error is one line on
    stderr) that points at the verb's ``--help`` instead of printing the usage block.
    The verbs' parsers are of this class too (``add_subparsers`` makes its own kind).

    Flags must be spelt in full: argparse's prefix matching would read ``--gt`` as
    ``--gt-mode`` today and refuse it as ambiguous once another ``--gt…`` flag exists, so a
    script that relied on it would break with a new release."""

    def __init__(self, *args: object, **kwargs: object) -> None:
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)  # type: ignore[arg-type]

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _interrupted(err: BaseException) -> bool:
    """Whether ``err`` came of a Ctrl-C: a compiled kernel interrupted mid-call raises
    ``SystemError`` with the ``KeyboardInterrupt`` as its cause."""
    seen: set[int] = set()
    cur: BaseException | None = err
    while cur is not None and id(cur) not in seen:
        if isinstance(cur, KeyboardInterrupt):
            return True
        seen.add(id(cur))
        cur = cur.__cause__ or cur.__context__
    return False


def _silence_stdout() -> None:
    """Point stdout at /dev/null, so that the interpreter's last flush to a closed pipe
    prints nothing."""
    import os

    try:
        fd = sys.stdout.fileno()
    except (AttributeError, OSError, ValueError):  # not a real file (a test's buffer)
        return
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, fd)
    os.close(devnull)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the exit code (also used as the console script)."""
    args_list = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in args_list
    # --debug is taken anywhere (the error lines say "rerun with --debug"), not only
    # before the verb.
    args_list = [a for a in args_list if a != "--debug"]
    parser = _parser()
    try:
        args = parser.parse_args(args_list)
        return int(args.func(args) or 0)
    except SystemExit as exc:  # argparse: usage errors exit 2, --help exits 0
        return int(exc.code or 0) if isinstance(exc.code, int) else 2
    except KeyboardInterrupt:
        print("scenegen: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # the reader of our output went away (`scenegen ... | head`)
        _silence_stdout()
        return 1  # the contract's codes are 0, 1 and 2: not a success, and nothing to say
    except ConfigError as err:
        if debug:
            raise
        print(f"scenegen: error: {err}", file=sys.stderr)
        return 2
    except (DataError, TrackerError) as err:
        if debug:
            raise
        print(f"scenegen: error: {err}", file=sys.stderr)
        return 1
    except Exception as err:
        if _interrupted(err):
            print("scenegen: interrupted", file=sys.stderr)
            return 130
        if debug:
            raise
        first = str(err).strip().splitlines()[0] if str(err).strip() else ""
        print(
            f"scenegen: internal error: {type(err).__name__}: {first} (rerun with --debug)",
            file=sys.stderr,
        )
        return 1
