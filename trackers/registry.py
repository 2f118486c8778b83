"""Tracker names, looked up lazily so that importing ``trackers`` stays cheap."""

from __future__ import annotations

import importlib
import inspect
from typing import Any

from trackers.base import Tracker

__all__ = ["defaults", "get_class", "make", "names", "parameters"]

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
    """All tracker names, in the contract's order.

    Returns
    -------
    list of str
        The registered names (``"condensation"``, ``"joint-pf"``, ..., ``"shm-fast"``).

    Examples
    --------
    >>> from trackers.registry import names
    >>> names()[:4]
    ['condensation', 'joint-pf', 'ps', 'dps']
    """
    return list(_REGISTRY)


def get_class(name: str) -> type[Tracker]:
    """The tracker class registered under ``name``.

    Parameters
    ----------
    name : str
        A name of :func:`names`.

    Returns
    -------
    type
        The class (its module is imported on first use).

    Raises
    ------
    ValueError
        For an unknown name, listing the valid ones.
    """
    if name not in _REGISTRY:
        raise ValueError(f"unknown tracker {name!r}; valid trackers: {', '.join(_REGISTRY)}")
    module, cls = _REGISTRY[name].split(":")
    return getattr(importlib.import_module(module), cls)


def defaults(name: str) -> dict[str, Any]:
    """Keyword parameters of tracker ``name`` and their defaults (``rng`` last, None).

    Read from the fields of the tracker's parameter dataclass (``cls.Params``); a
    registered class without one is read from its constructor's signature.

    Parameters
    ----------
    name : str
        A name of :func:`names`.

    Returns
    -------
    dict of str to Any
        Parameter name -> default, in declaration order, ``"rng": None`` last.

    Raises
    ------
    ValueError
        For an unknown name, listing the valid ones.

    Examples
    --------
    >>> from trackers.registry import defaults
    >>> defaults("meanshift")
    {'kernel': 'cone', 'bins': 10, 'max_iter': 20, 'eps': 0.5, 'rng': None}
    """
    cls = get_class(name)
    if cls.Params is not None:
        return {**cls.Params.defaults(), "rng": None}
    sig = inspect.signature(cls.__init__)
    return {p.name: p.default for p in sig.parameters.values()
            if p.name != "self" and p.kind is p.KEYWORD_ONLY}


def parameters(name: str) -> list[str]:
    """Keyword parameters accepted by tracker ``name`` (``rng`` included, last).

    Parameters
    ----------
    name : str
        A name of :func:`names`.

    Returns
    -------
    list of str
        The keys of :func:`defaults`, in the same order.

    Raises
    ------
    ValueError
        For an unknown name, listing the valid ones.
    """
    return list(defaults(name))


def make(name: str, **params: Any) -> Tracker:
    """Construct tracker ``name`` with keyword ``params``.

    Parameters
    ----------
    name : str
        A name of :func:`names`.
    **params : Any
        Keyword parameters of that tracker (:func:`parameters`), ``rng`` included;
        the others take their defaults.

    Returns
    -------
    Tracker
        A new, uninitialised tracker (call ``init`` before ``step``).

    Raises
    ------
    ValueError
        For an unknown tracker or parameter name, listing the valid ones; from the
        tracker's parameter dataclass for a bad value, naming the parameter.
    """
    cls = get_class(name)
    valid = parameters(name)
    for key in params:
        if key not in valid:
            raise ValueError(
                f"unknown parameter {key!r} for tracker {name!r}; valid: {', '.join(valid)}"
            )
    return cls(**params)
