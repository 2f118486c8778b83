"""Argument types shared by the verbs."""

from __future__ import annotations

import argparse

from scenegen.render.plan import MAX_SEED

__all__ = ["seed_arg"]


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
