"""scenegen: procedural synthetic video scenarios with exact ground truth.

>>> import scenegen
>>> seq = scenegen.generate("kams-a", seed=0)
>>> seq.frames.shape, seq.gt.box.shape
((140, 240, 320, 3), (140, 101, 4))
"""

__version__ = "0.1.0"

from scenegen import presets
from scenegen.config import SceneConfig, from_dict, load_config
from scenegen.datasets import open_dataset
from scenegen.errors import ConfigError, DataError
from scenegen.io import read, write
from scenegen.render.plan import generate, plan
from scenegen.sequence import Entities, GroundTruth, Sequence

__all__ = [
    "ConfigError",
    "DataError",
    "Entities",
    "GroundTruth",
    "SceneConfig",
    "Sequence",
    "__version__",
    "from_dict",
    "generate",
    "load_config",
    "open_dataset",
    "plan",
    "presets",
    "read",
    "write",
]
