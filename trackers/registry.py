"""Tracker names, looked up lazily so that importing ``trackers`` stays cheap."""

from __future__ import annotations

import importlib
import inspect
from typing import Any

from trackers.base import Tracker

__all__ = ["get_class", "make", "names"]

# name -> "module:Class"; modules are imported on first use.
_REGISTRY: dict[str, str] = {
    "condensation": "trackers.particle:Condensation",
    "joint-pf": "trackers.particle:JointPF",
    "ps": "trackers.particle:PartitionedSampling",
    "dps": "trackers.particle:DistributedPartitionedSampling",
    "meanshift": "trackers.meanshift:MeanShiftTracker",
    "annealed": "trackers.annealed:AnnealedPF",
    "hybrid": "trackers.hybrid:HybridPF",
    "sok": "trackers.sok:SOK",
    "kams": "trackers.kams:KAMS",
    "kalman": "trackers.kalman:KalmanTracker",
    "shm": "trackers.shm:SHMTracker",
    "shm-fast": "trackers.shm:FastSHMTracker",
}


def names() -> list[str]:
    """All tracker names, in the contract's order."""
    return list(_REGISTRY)


def get_class(name: str) -> type[Tracker]:
    """The tracker class registered under ``name``.

    Raises
    ------
    ValueError
        For an unknown name, listing the valid ones.
    """
    if name not in _REGISTRY:
        raise ValueError(f"unknown tracker {name!r}; valid trackers: {', '.join(_REGISTRY)}")
    module, cls = _REGISTRY[name].split(":")
    return getattr(importlib.import_module(module), cls)


def parameters(name: str) -> list[str]:
    """Keyword parameters accepted by tracker ``name`` (``rng`` included)."""
    sig = inspect.signature(get_class(name).__init__)
    return [p for p in sig.parameters if p != "self"]


def make(name: str, **params: Any) -> Tracker:
    """Construct tracker ``name`` with keyword ``params``.

    Raises
    ------
    ValueError
        For an unknown tracker or parameter name, listing the valid ones.
    """
    cls = get_class(name)
    valid = parameters(name)
    for key in params:
        if key not in valid:
            raise ValueError(
                f"unknown parameter {key!r} for tracker {name!r}; valid: {', '.join(valid)}"
            )
    return cls(**params)
