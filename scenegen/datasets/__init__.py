"""Benchmark datasets: scenario families, sharded reproducible generation, lazy reading.

- :mod:`scenegen.datasets.family`: the family file format (base + ``set`` + ``sweep`` +
  ``vary`` + ``count``) and how sequence ``i`` is drawn.
- :mod:`scenegen.datasets.builtin`: built-in families (``kams``, ``dps-occlusion``, ...).
- :mod:`scenegen.datasets.build`: :func:`build_dataset` (shards, manifest, resume).
- :mod:`scenegen.datasets.reader`: :func:`open_dataset`.
- :mod:`scenegen.datasets.validate`: :func:`validate_dataset`.
- :mod:`scenegen.datasets.executor`: local processes or Dask, the same tasks.
"""

from scenegen.datasets.build import MANIFEST, build_dataset, read_manifest
from scenegen.datasets.builtin import builtin_names, resolve_family
from scenegen.datasets.family import Family, family_from_dict, load_family
from scenegen.datasets.reader import Dataset, Samples, open_dataset
from scenegen.datasets.validate import validate_dataset

__all__ = [
    "MANIFEST",
    "Dataset",
    "Family",
    "Samples",
    "build_dataset",
    "builtin_names",
    "family_from_dict",
    "load_family",
    "open_dataset",
    "read_manifest",
    "resolve_family",
    "validate_dataset",
]
