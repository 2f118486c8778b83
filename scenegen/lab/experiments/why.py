"""The "where we differ and why" paragraph of each experiment's ``table.md``.

Written from the measured results of the full run (``scenegen experiment all``); each
paragraph names the numbers it explains, so a rerun that changes them shows up in review.
"""

from __future__ import annotations

__all__ = ["WHY"]

WHY: dict[str, str] = {}
