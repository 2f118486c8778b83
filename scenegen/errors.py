"""Errors a user can cause. Each carries one line that names the field or value at fault.

The CLI maps :class:`ConfigError` (bad usage, bad config, bad parameter) to exit code 2,
:class:`DataError` (an invalid or mismatched data file, a failed check) and
:class:`TrackerError` (a user's tracker raised) to exit code 1.
"""

from __future__ import annotations

__all__ = ["ConfigError", "DataError", "NotInFile", "TrackerError"]


class ConfigError(ValueError):
    """A configuration or usage error; the message names the field and the bad value."""


class DataError(ValueError):
    """An invalid, damaged or mismatched data file; the message names the file and problem."""


class NotInFile(DataError):
    """A file holds no sequence (or tracker result) of the name asked for, or several and
    none was named. A :class:`DataError` where the name comes from data (a manifest); the
    CLI verbs whose ``--sequence`` / ``--tracker`` option picks it report a usage error
    (exit 2) naming the option."""


class TrackerError(RuntimeError):
    """A user's tracker (a factory, not one of ours) raised while it ran; the message names
    the tracker, the sequence, how far it got and its exception (the original is the
    ``__cause__``)."""
