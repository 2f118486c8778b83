"""Argument types shared by the verbs."""

from __future__ import annotations

import argparse
from collections.abc import Iterator
from contextlib import contextmanager

from scenegen.errors import ConfigError, NotInFile
from scenegen.render.plan import MAX_SEED

__all__ = ["picked_by", "seed_arg"]


@contextmanager
def picked_by(option: str) -> Iterator[None]:
    """Report a name the file does not hold (:class:`scenegen.errors.NotInFile`) as the
    usage error it is when ``option`` chose it: ``ConfigError`` (exit 2) naming the option.

    ``with picked_by("--sequence"): seq = read(path, args.sequence)``
    """
    try:
        yield
    except NotInFile as err:
        raise ConfigError(f"{err} (choose with {option})") from None


def seed_arg(text: str) -> int:
    """``--seed``: an integer in [0, 2**64 - 1] (:data:`scenegen.render.plan.MAX_SEED`,
    what a file stores); argparse reports anything else as a usage error, exit 2.

    Raises
    ------
    argparse.ArgumentTypeError
        ``"must be an integer in [0, 2**64 - 1], got '<text>'"``.
    """
    try:
        value = int(text)
    except ValueError:
        value = -1
    if not 0 <= value <= MAX_SEED:
        raise argparse.ArgumentTypeError(
            f"must be an integer in [0, 2**64 - 1], got {text[:40]!r}"
        )
    return value
