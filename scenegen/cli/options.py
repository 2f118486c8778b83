"""Argument types shared by the verbs."""

from __future__ import annotations

import argparse

__all__ = ["MAX_SEED", "seed_arg"]

MAX_SEED = 2**63 - 1
"""Largest seed a verb takes: seeds are stored as 64-bit signed integers in the files."""


def seed_arg(text: str) -> int:
    """``--seed``: an integer in [0, :data:`MAX_SEED`] (argparse reports anything else as a
    usage error, exit 2).

    Raises
    ------
    argparse.ArgumentTypeError
        ``"must be an integer in [0, 2**63 - 1], got '<text>'"``.
    """
    try:
        value = int(text)
    except ValueError:
        value = -1
    if not 0 <= value <= MAX_SEED:
        raise argparse.ArgumentTypeError(
            f"must be an integer in [0, 2**63 - 1], got {text[:40]!r}"
        )
    return value
