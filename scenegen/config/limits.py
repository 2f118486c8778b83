"""Upper limits of a scenario config's values: sizes, counts and magnitudes.

A config beyond them is rejected with a ConfigError naming the field rather than
attempted. The limits of a config *file* (bytes, values, YAML aliases) are in
:mod:`scenegen.config.files`.
"""

from __future__ import annotations

__all__ = [
    "MAX_BLUR",
    "MAX_COLORS",
    "MAX_FRAMES",
    "MAX_FRAME_ENTITIES",
    "MAX_MAGNITUDE",
    "MAX_MOTION_BLUR",
    "MAX_NAME",
    "MAX_PATH",
    "MAX_SIDE",
    "MAX_TEMPLATE_PIXELS",
]

_MAX_ENTITIES = 65535  # labels are uint16 and 0 is the background

# Upper limits that keep a valid config within sane memory and time: a config beyond them
# is rejected with a ConfigError naming the field rather than attempted (a width of 10^9
# would otherwise fail deep inside the generator, or exhaust memory).
MAX_SIDE = 8192
"""Largest frame width or height, and largest appearance (template) side, in pixels."""
MAX_FRAMES = 1_000_000
"""Most frames in one sequence."""
MAX_FRAME_ENTITIES = 20_000_000
"""Most frames x entities (clutter items included). Planning keeps about 50 bytes per
entity per frame (trajectories, presence, depths), so this caps it near 1 GB; e.g.
20,000 frames of 1,000 entities."""
MAX_MAGNITUDE = 1e9
"""Largest absolute value of any number in a config (positions, velocities, sigmas,
frame indices, depths, ...): far beyond any canvas, and safe from int64 overflow."""
MAX_PATH = 1e18
"""Largest absolute value an :class:`AR2` path may reach (pixels; log units for a scale,
zoom or gain; grey levels for an offset). A path that goes beyond it (or overflows to
infinity) is refused when planned, naming the field and the frame: only an explosive
``a1, a2`` (a root of ``z^2 - a1 z - a2`` outside the unit circle) gets there, or a
sigma near :data:`MAX_MAGNITUDE` over most of :data:`MAX_FRAMES` frames. Twice it (a
2x zoom) still fits a 64-bit pixel index."""
MAX_COLORS = 256
"""Most colours drawn per clutter item (``n_colors``)."""
MAX_BLUR = 256.0
"""Largest background texture ``scale`` (Gaussian std, pixels): the blur costs time in
proportion to it."""
MAX_MOTION_BLUR = 4.0
"""Largest ``Photometric.motion_blur`` (exposure in frame intervals)."""
MAX_TEMPLATE_PIXELS = 2**24
"""Most appearance template pixels of a scene: every entity's ``appearance.size`` (a mimic's
that of its model) plus, per clutter group, ``count`` x its ``appearance.size``. Planning
keeps about 75 bytes per template pixel (pattern, mask, colour and alpha layers), so this
caps it near 1.2 GB; e.g. one 4096x4096 entity, or 65,535 clutter items of 16x16. The
presets use at most 154,500."""
MAX_NAME = 256
"""Longest sequence, entity or clutter name, in characters."""
