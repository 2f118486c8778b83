"""Image sources: the images an appearance or background ``source`` may name
(:data:`SKIMAGE_NAMES`, :func:`check_source`), and the folder a relative path read from a
file is relative to (:func:`relative_to`)."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import TYPE_CHECKING, Any

from scenegen.config.messages import _short
from scenegen.errors import ConfigError

if TYPE_CHECKING:
    from scenegen.config.scene import SceneConfig

__all__ = ["N_FACES", "SKIMAGE_NAMES", "check_source", "relative_to"]

SKIMAGE_NAMES = (
    "astronaut", "brick", "camera", "cell", "chelsea", "clock", "coffee", "coins",
    "colorwheel", "grass", "gravel", "hubble_deep_field", "immunohistochemistry",
    "microaneurysms", "moon", "page", "retina", "rocket", "text",
)  # fmt: skip
"""Images of ``skimage.data`` an image ``source`` may name (``skimage:coffee``); all ship
with scikit-image (no download). ``skimage:lfw_subset[i]`` (``0 <= i < 200``) names one of
the 200 faces of ``skimage.data.lfw_subset``."""
N_FACES = 200


def check_source(source: str) -> None:
    """Validate the syntax of an image source (a file is read only when planning).

    Parameters
    ----------
    source : str
        ``skimage:NAME`` (a name of :data:`SKIMAGE_NAMES`), ``skimage:lfw_subset[i]``
        (``0 <= i < 200``) or a file path (any non-empty string not starting with
        ``skimage:``).

    Raises
    ------
    ConfigError
        Unknown ``skimage:`` name, face index out of range, or an empty source.
    """
    if not source:
        raise ConfigError("must be 'skimage:NAME' or a path to an image file, got ''")
    if not source.startswith("skimage:"):
        return
    name = source[len("skimage:") :]
    if name.startswith("lfw_subset[") and name.endswith("]") and name[11:-1].isdigit():
        if int(name[11:-1]) >= N_FACES:
            raise ConfigError(f"lfw_subset has faces 0..{N_FACES - 1}, got {_short(source)}")
        return
    if name not in SKIMAGE_NAMES:
        raise ConfigError(
            f"unknown image {_short(source)}; known: {', '.join(SKIMAGE_NAMES)}, lfw_subset[0..199]"
        )


def relative_to(path: str | Path, folder: str | Path | None) -> Path:
    """``path`` read from a file in ``folder``: joined to it when relative (``None``: as
    given). The one rule for every path a config or family file names (image sources,
    a family's ``base`` config).

    Parameters
    ----------
    path : str or Path
        The path as read.
    folder : str or Path or None
        The folder of the file it was read from.

    Returns
    -------
    Path
        ``folder / path`` when ``path`` is relative and ``folder`` given, else ``path``.
    """
    p = Path(path)
    return p if folder is None or p.is_absolute() else Path(folder) / p


def _sources_relative_to(config: SceneConfig, folder: Path) -> SceneConfig:
    """``config`` with every relative image file source joined to ``folder``."""

    def fix(obj: Any) -> Any:
        src = obj.source
        if src is None or src.startswith("skimage:") or Path(src).is_absolute():
            return obj
        return dataclasses.replace(obj, source=str(relative_to(src, folder)))

    background = fix(config.background)
    entities = tuple(dataclasses.replace(e, appearance=fix(e.appearance)) for e in config.entities)
    clutter = tuple(dataclasses.replace(c, appearance=fix(c.appearance)) for c in config.clutter)
    if (background, entities, clutter) == (config.background, config.entities, config.clutter):
        return config
    return dataclasses.replace(config, background=background, entities=entities, clutter=clutter)
