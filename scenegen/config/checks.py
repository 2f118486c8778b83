"""Value checks that several config classes share: colours, names and keyframes."""

from __future__ import annotations

from scenegen.config.limits import MAX_NAME
from scenegen.config.messages import _fail, _short

__all__: list[str] = []


def _check_color(path: str, c: tuple[int, int, int]) -> None:
    if len(c) != 3 or any(not 0 <= v <= 255 for v in c):
        _fail(path, f"colour must be three integers in 0..255, got {_short(list(c))}")


def _check_name(path: str, name: str) -> None:
    """Names become HDF5 group names and fixed-length strings: no NUL, no '/', not '.'
    or '..', not empty, at most :data:`MAX_NAME` characters."""
    if not name:
        _fail(path, "must not be empty")
    if len(name) > MAX_NAME:
        _fail(path, f"must be at most {MAX_NAME} characters, got {len(name)}: {_short(name)}")
    if "\0" in name:
        _fail(path, f"must not contain a NUL character, got {_short(name)}")
    if "/" in name:
        _fail(path, f"must not contain '/', got {_short(name)}")
    if name in (".", ".."):
        _fail(path, f"must not be '.' or '..', got {_short(name)}")
    if not name.isprintable():
        _fail(path, f"must be printable (no newline or control character), got {_short(name)}")


def _check_keyframes(name: str, keys: tuple[tuple[int, float, float], ...]) -> None:
    frames = [k[0] for k in keys]
    if frames and frames[0] < 0:
        _fail(name, f"frames must be >= 0, got {_short(frames)}")
    if any(b <= a for a, b in zip(frames, frames[1:], strict=False)):
        _fail(name, f"keyframe frames must increase, got {_short(frames)}")
