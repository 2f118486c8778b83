"""Which fields each kind uses, and fields added after the first release.

A field that only some kinds use (an appearance's ``crop`` only on the ``image`` pattern)
must keep its default on every other kind, else the config is refused naming the field
and the kind: its value would be silently ignored. The tables here say which kinds use
which fields; :func:`_check_unused` applies them. A config read back from a file
(:func:`~scenegen.config.from_stored`) is exempt, through the :data:`_STORED` flag.
"""

from __future__ import annotations

import contextvars
import dataclasses
from dataclasses import field
from typing import Any

from scenegen.config.messages import _fail

__all__ = [
    "AR2_FIELDS",
    "BACKGROUND_FIELDS",
    "CLUTTER_FIELDS",
    "PATTERN_FIELDS",
]

_STORED = contextvars.ContextVar("scenegen_config_stored", default=False)
"""True while :func:`from_stored` builds a config read back from a file."""


def _unused(path: str, msg: str) -> None:
    """Refuse a field that holds a value the scene would silently ignore (``msg`` says
    why), except in a config read back from a file (:func:`from_stored`): a file written
    before the refusal existed keeps it ignored, as it was when the file was made."""
    if not _STORED.get():
        _fail(path, msg)


_DRAWN = ("solid", "rings", "sectors", "stripes", "bands", "checker", "texture", "perlin")
PATTERN_FIELDS: dict[str, tuple[str, ...]] = {
    "colors": _DRAWN,
    "texture_sigma": ("texture",),
    "noise_scale": ("perlin",),
    "source": ("image",),
    "crop": ("image",),
    "fit": ("image",),
    "tint": ("image",),
}
"""The :class:`Appearance` fields that only some patterns use, with those patterns: on any
other pattern such a field must keep its default, else the config is refused naming the
field and the pattern (``appearance.crop: not used by pattern 'solid' (it applies to
pattern: image)``). ``stripe_width`` (used by ``stripes`` and ``checker``) is tolerated on
every pattern: the regression fixtures, scaled down, record it on every pattern."""
BACKGROUND_FIELDS: dict[str, tuple[str, ...]] = {
    "color": ("uniform", "texture", "perlin", "image"),
    "low": ("noise", "texture", "perlin"),
    "high": ("noise", "texture", "perlin"),
    "source": ("image",),
    "fit": ("image",),
}
"""The :class:`Background` fields that only some kinds use, as :data:`PATTERN_FIELDS`.
``scale`` (used by ``texture`` and ``perlin``) is tolerated on every kind: the regression
fixtures, scaled down, record it on every kind."""
CLUTTER_FIELDS: dict[str, tuple[str, ...]] = {
    "palette": PATTERN_FIELDS["colors"],
    "n_colors": PATTERN_FIELDS["colors"],
}
"""The :class:`ClutterSpec` fields that only some ``appearance.pattern`` values use (the
patterns that take colours: an ``image`` item takes its pixels from the image), as
:data:`PATTERN_FIELDS`."""
AR2_FIELDS: dict[str, tuple[str, ...]] = {"margin": ("reflect", "clamp")}
"""The :class:`AR2` fields that only some ``boundary`` rules use (``free`` has no limits
for a margin to move), as :data:`PATTERN_FIELDS`."""
_MIMIC_FIELDS = ("color_jitter", "mimic_offset")
"""The :class:`EntitySpec` fields that only a mimic uses."""


def _check_unused(
    obj: Any, kind: str, users: dict[str, tuple[str, ...]], *, chosen: Any = None
) -> None:
    """Refuse a field that the chosen ``kind`` (an appearance's ``pattern``, a background's
    ``kind``) does not use, unless it holds its default: it would be silently ignored.

    ``users`` maps each kind-specific field of ``obj`` to the kinds that use it; ``chosen``
    is the kind's value when it is not ``obj``'s own field ``kind`` (a clutter group's
    ``appearance.pattern``)."""
    chosen = getattr(obj, kind) if chosen is None else chosen
    defaults = {f.name: f.default for f in dataclasses.fields(obj)}
    for name, kinds in users.items():
        if chosen not in kinds and getattr(obj, name) != defaults[name]:
            where = " | ".join(kinds)
            _unused(name, f"not used by {kind} {chosen!r} (it applies to {kind}: {where})")


def _new(default: Any) -> Any:
    """A field added after the first release: left out of :func:`to_dict` while it holds
    its default, so configs written before it existed still compare equal."""
    return field(default=default, metadata={"omit_default": True})
