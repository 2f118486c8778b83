"""Declarative scenario configuration: frozen dataclasses validated on construction.

A scenario is described by a :class:`SceneConfig` built from Python objects, a dict, or a
YAML/JSON file (:func:`load_config`). Every error raises :class:`~scenegen.errors.ConfigError`
whose one-line message names the field path (``entities[1].motion.x.boundary``) and the bad
value.

One module per concept, each re-exported here:

- ``limits``: upper limits of a config's values (``MAX_SIDE``, ``MAX_FRAMES``, ...);
- ``messages``: the one-line ConfigError naming a field path, short excerpts of bad values;
- ``fields``: which fields each pattern, background kind, clutter pattern and AR2 boundary
  uses (``PATTERN_FIELDS``, ...), and fields added after the first release;
- ``checks``: value checks that several classes share (colours, names, keyframes);
- ``coerce``: a value read as its field's type, by :func:`from_dict` and by every class on
  construction (a bad type or choice is a ConfigError naming the field; numpy numbers
  become Python numbers and lists tuples);
- ``sources``: image sources (``SKIMAGE_NAMES``, ``check_source``) and ``relative_to``;
- ``motion`` (``AR2``, ``Motion``), ``appearance`` (``Appearance``, ``Variation``),
  ``background`` (``Background``), ``entities`` (``EntitySpec``, ``ClutterSpec``),
  ``camera`` (``Camera``), ``photometric`` (``Photometric``), ``scene``
  (``SceneConfig``): the frozen dataclasses and their validation;
- ``plain``: to and from plain data (``from_dict``, ``from_stored``, ``to_dict``);
- ``files``: reading and writing YAML/JSON files (``load_config``, ``load_data``,
  ``dump_yaml``, ``json_object``) and the limits of a file (``MAX_VALUES``, ...).

Examples
--------
>>> cfg = from_dict({
...     "width": 64, "height": 48, "n_frames": 10,
...     "entities": [{"name": "t1", "role": "target", "position": [20, 20],
...                   "appearance": {"shape": "ellipse", "size": [9, 9]},
...                   "motion": {"x": {"sigma": 1, "boundary": "reflect"},
...                              "y": {"sigma": 1, "boundary": "reflect"}}}]})
>>> cfg.entities[0].motion.x.a1
2.0
"""

from __future__ import annotations

from scenegen.config.appearance import Appearance, Variation
from scenegen.config.appearance import Color as Color
from scenegen.config.appearance import Fit as Fit
from scenegen.config.appearance import Pattern as Pattern
from scenegen.config.appearance import Shape as Shape
from scenegen.config.background import Background
from scenegen.config.camera import Camera
from scenegen.config.entities import ClutterSpec, EntitySpec
from scenegen.config.entities import Role as Role
from scenegen.config.fields import AR2_FIELDS, BACKGROUND_FIELDS, CLUTTER_FIELDS, PATTERN_FIELDS
from scenegen.config.files import MAX_ALIASES as MAX_ALIASES
from scenegen.config.files import MAX_CONFIG_BYTES as MAX_CONFIG_BYTES
from scenegen.config.files import MAX_NODES as MAX_NODES
from scenegen.config.files import MAX_VALUES, dump_yaml, load_config, load_data
from scenegen.config.files import json_object as json_object
from scenegen.config.limits import (
    MAX_BLUR,
    MAX_COLORS,
    MAX_FRAME_ENTITIES,
    MAX_FRAMES,
    MAX_MAGNITUDE,
    MAX_PATH,
    MAX_SIDE,
    MAX_TEMPLATE_PIXELS,
)
from scenegen.config.limits import MAX_MOTION_BLUR as MAX_MOTION_BLUR
from scenegen.config.limits import MAX_NAME as MAX_NAME
from scenegen.config.messages import SHORT as SHORT
from scenegen.config.motion import AR2, Motion
from scenegen.config.motion import Boundary as Boundary
from scenegen.config.photometric import Photometric
from scenegen.config.plain import from_dict, from_stored, to_dict
from scenegen.config.scene import SceneConfig
from scenegen.config.sources import N_FACES as N_FACES
from scenegen.config.sources import SKIMAGE_NAMES, relative_to
from scenegen.config.sources import check_source as check_source

__all__ = [
    "AR2",
    "AR2_FIELDS",
    "BACKGROUND_FIELDS",
    "CLUTTER_FIELDS",
    "MAX_BLUR",
    "MAX_COLORS",
    "MAX_FRAMES",
    "MAX_FRAME_ENTITIES",
    "MAX_MAGNITUDE",
    "MAX_PATH",
    "MAX_SIDE",
    "MAX_TEMPLATE_PIXELS",
    "MAX_VALUES",
    "PATTERN_FIELDS",
    "Appearance",
    "Background",
    "Camera",
    "ClutterSpec",
    "EntitySpec",
    "Motion",
    "Photometric",
    "SKIMAGE_NAMES",
    "SceneConfig",
    "Variation",
    "dump_yaml",
    "from_dict",
    "from_stored",
    "load_config",
    "load_data",
    "relative_to",
    "to_dict",
]
