"""A progress bar shown only on a terminal (tqdm), so pipes and logs stay clean."""

from __future__ import annotations

import sys
from typing import Any

from tqdm import tqdm

__all__ = ["bar"]


def bar(total: int, desc: str, **kwargs: Any) -> tqdm:
    """A tqdm bar on stderr, disabled when stderr is not a terminal."""
    return tqdm(total=total, desc=desc, disable=not sys.stderr.isatty(), leave=False, **kwargs)
