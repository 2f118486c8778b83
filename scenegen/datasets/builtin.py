"""Built-in families for the presets, and resolving a ``FAMILY`` argument.

``kams``
    The four KAMS levels (kams-a .. kams-d: measurement noise 4..14, clutter 100..600) as
    one axis, ``preset``.
``kams-noise``
    kams-a with the target's measurement noise drawn uniformly in [0, 16] px and the
    clutter count uniformly in 0..600: the same difficulty axes as ``kams``, continuous.
``kams-size``
    kams-b with the target's size swept over 16, 24, 30, 40 px.
``dps-occlusion``
    DPS RealSeq1: the two standing people's width swept over 36, 44, 56, 72 px, so the
    walker is totally hidden for about 2.5, 7.5, 15 and 25 frames at each crossing
    (occlusion length = (width - 32) / 1.6 frames).
``dps-synthetic``
    The DPS synthetic scene with the distractor's colour jitter (distractor similarity)
    swept over 0, 6, 12, 24.
``shm-crossing``
    The SHM crossing hands with the clutter around the crossing swept over 0, 15, 40
    items.

Any preset name is a family too: that preset with fresh seeds, no parameter varied.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from scenegen import presets
from scenegen.datasets.family import Family, family_from_dict, load_family
from scenegen.errors import ConfigError

__all__ = ["BUILTIN", "builtin_names", "resolve_family"]

BUILTIN: dict[str, dict[str, Any]] = {
    "kams": {
        "name": "kams",
        "description": "the four KAMS levels (noise 4..14 px, clutter 100..600) as one axis",
        "sweep": {"preset": ["kams-a", "kams-b", "kams-c", "kams-d"]},
    },
    "kams-noise": {
        "name": "kams-noise",
        "description": "kams-a with measurement noise ~ U[0, 16] px and clutter ~ U{0..600}",
        "base": "kams-a",
        "count": 100,
        "vary": {
            "entities[target].position_noise": {"uniform": [0.0, 16.0]},
            "clutter[clutter].count": {"randint": [0, 600]},
        },
    },
    "kams-size": {
        "name": "kams-size",
        "description": "kams-b with the target's size swept over 16..40 px",
        "base": "kams-b",
        "sweep": {"entities[target].appearance.size": [[16, 16], [24, 24], [30, 30], [40, 40]]},
    },
    "dps-occlusion": {
        "name": "dps-occlusion",
        "description": "DPS RealSeq1 with occluder width 36..72 px (total occlusion "
        "~2.5..25 frames per crossing)",
        "base": "dps-occlusion",
        "sweep": {
            "occluder_width": {
                "entities[standing1].appearance.size[0]": [36, 44, 56, 72],
                "entities[standing2].appearance.size[0]": [36, 44, 56, 72],
            }
        },
    },
    "dps-synthetic": {
        "name": "dps-synthetic",
        "description": "the DPS synthetic scene with distractor colour jitter 0..24 "
        "(similarity to object 1)",
        "base": "dps-synthetic",
        "sweep": {"entities[distractor1].color_jitter": [0.0, 6.0, 12.0, 24.0]},
    },
    "shm-crossing": {
        "name": "shm-crossing",
        "description": "the SHM crossing hands with 0, 15 or 40 clutter items at the crossing",
        "base": "shm-crossing",
        "sweep": {"clutter[clutter].count": [0, 15, 40]},
    },
}


def builtin_names() -> list[str]:
    """Names of the built-in families.

    Returns
    -------
    list of str
        The names of :data:`BUILTIN`, in definition order.
    """
    return list(BUILTIN)


def resolve_family(family: str | Path | Family | dict[str, Any]) -> Family:
    """A :class:`Family` from a file, a built-in family name, a preset name or a mapping.

    Parameters
    ----------
    family : str, Path, Family or dict
        A family itself (returned as is); a mapping (:func:`family_from_dict`); a path
        ending in ``.yaml``, ``.yml`` or ``.json``, or naming an existing file
        (:func:`load_family`); else a name of :data:`BUILTIN` or a preset (that preset
        with fresh seeds, no parameter varied).

    Returns
    -------
    Family
        The family.

    Raises
    ------
    ConfigError
        For an unknown name (listing the built-in families and presets) or an invalid
        family.
    """
    if isinstance(family, Family):
        return family
    if isinstance(family, dict):
        return family_from_dict(family)
    text = str(family)
    if text.lower().endswith((".yaml", ".yml", ".json")) or Path(text).is_file():
        return load_family(text)
    if text in BUILTIN:
        return family_from_dict(BUILTIN[text], source=f"family {text}")
    if text in presets.all_names():
        return family_from_dict({"name": text, "base": text}, source=f"family {text}")
    raise ConfigError(
        f"unknown family {text!r}: not a .yaml/.json file; built-in families: "
        f"{', '.join(BUILTIN)}; or a preset: {', '.join(presets.all_names())}"
    )
