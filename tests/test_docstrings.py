"""Every public function and class documents what it takes and gives, in numpydoc form.

"Public" is a module's ``__all__`` (objects defined in that module), in ``scenegen`` and
``trackers``, but the command line's modules, whose verbs document themselves in
``--help``; and the methods and properties a public class defines whose names do not start
with ``_``. Checked, with numpydoc's own parser:

- a docstring exists (for a property, that is all);
- every parameter of the signature (but a private ``_name``) is documented (under
  ``Parameters`` or ``Other Parameters``; for a class, ``Attributes`` also counts: a
  dataclass's fields are its parameters), and no documented parameter is missing from
  the signature;
- every documented parameter has a type (for arrays, its shape);
- a function that returns a value has a ``Returns`` (or ``Yields``) section.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import warnings

import pytest
from numpydoc.docscrape import ClassDoc, FunctionDoc
from numpydoc.validate import Validator, get_doc_object

import scenegen
import trackers


def _public() -> list[str]:
    names = []
    for pkg in (scenegen, trackers):
        for info in pkgutil.walk_packages(pkg.__path__, pkg.__name__ + "."):
            if info.name.startswith("scenegen.cli"):
                continue
            module = importlib.import_module(info.name)
            if module.__name__ != info.name:  # an old import path of another module
                continue
            for name in getattr(module, "__all__", ()):
                obj = getattr(module, name, None)
                if (inspect.isfunction(obj) or inspect.isclass(obj)) and \
                        obj.__module__ == module.__name__:
                    names.append(f"{module.__name__}.{name}")
                    if inspect.isclass(obj):
                        names += [f"{module.__name__}.{name}.{m}" for m in _methods(obj)]
    return sorted(names)


def _methods(cls: type) -> list[str]:
    """The public methods and properties ``cls`` defines itself."""
    out = []
    for name, member in vars(cls).items():
        if name.startswith("_"):
            continue
        if isinstance(member, (staticmethod, classmethod)):
            member = member.__func__
        if inspect.isfunction(member) or isinstance(member, property):
            out.append(name)
    return out


PUBLIC = _public()


def _object(path: str) -> object:
    """The function, class, method or property named by a dotted path."""
    parts = path.split(".")
    for cut in range(len(parts) - 1, 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for i, name in enumerate(parts[cut:]):
            owner = obj
            obj = getattr(owner, name)
            if inspect.isclass(owner) and i == len(parts) - cut - 1:
                member = inspect.getattr_static(owner, name)
                if isinstance(member, property):
                    return member
        return obj
    raise ImportError(path)


def _names(entries: list) -> dict[str, str]:
    """Documented name -> its type, a ``x, y : float`` entry giving both names."""
    out = {}
    for entry in entries:
        for name in entry.name.split(","):
            out[name.strip().lstrip("*")] = entry.type
    return out


def _signature(obj: object) -> list[str] | None:
    try:
        sig = inspect.signature(obj)  # a class: its constructor's
    except (TypeError, ValueError):
        return None
    return [p.name for p in sig.parameters.values() if p.name not in ("self", "cls")]


def problems(path: str) -> list[str]:
    """What the docstring of the public object ``path`` lacks (empty when complete)."""
    obj = _object(path)
    if not (inspect.getdoc(obj) or "").strip():
        return ["no docstring"]
    if isinstance(obj, property):
        return []
    is_class = inspect.isclass(obj)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # an unknown section (say "Example") is a problem
        try:
            doc = ClassDoc(obj, config={"show_class_members": False}) if is_class \
                else FunctionDoc(obj)
        except Warning as warning:
            return [str(warning)]
    params = _names(doc["Parameters"] + doc["Other Parameters"])
    documented = dict(params)
    if is_class:
        documented.update(_names(doc["Attributes"]))
    out = []
    signature = _signature(obj)
    if signature is not None:
        undocumented = [p for p in signature if p not in documented and not p.startswith("_")]
        if undocumented:
            out.append(f"parameters not documented: {', '.join(undocumented)}")
        kinds = inspect.signature(obj).parameters.values()
        if not any(p.kind is p.VAR_KEYWORD for p in kinds):
            stale = [p for p in params if p not in signature]
            if stale:
                out.append(f"documented but not in the signature: {', '.join(stale)}")
    untyped = [name for name, kind in documented.items() if not kind.strip()]
    if untyped:
        out.append(f"parameters without a type: {', '.join(untyped)}")
    if not is_class and not (doc["Returns"] or doc["Yields"]):
        if Validator(get_doc_object(obj)).method_returns_something:
            out.append("returns a value but has no Returns section")
    return out


def test_the_public_objects_are_found():
    assert len(PUBLIC) > 600
    assert {"trackers.run.track", "scenegen.io.hdf5.read", "scenegen.config.motion.AR2",
            "scenegen.datasets.family.Family.draws", "scenegen.sequence.Sequence.init_boxes",
            "trackers.filters.kalman.KalmanFilter.predict"} <= set(PUBLIC)
    assert not any(name.rpartition(".")[2].startswith("_") for name in PUBLIC)


@pytest.mark.parametrize("path", PUBLIC)
def test_public_docstring_is_complete(path):
    found = problems(path)
    assert not found, f"{path}: " + "; ".join(found)


def _heading(a: int) -> None:
    """Nothing.

    Parameters
    ----------
    a : int

    Example
    -------
    >>> _heading(1)
    """


def _partial(a: int, b: float = 1.0, **kwargs: object) -> float:
    """Sum.

    Parameters
    ----------
    a : int
    c
        Not a parameter: tolerated, as ``**kwargs`` may take it, but it needs a type.
    """
    return a + b


def _stale(a: int) -> None:
    """Nothing.

    Parameters
    ----------
    a : int
    b : float
    """


def test_the_check_finds_what_it_names():
    assert "Unknown section Example" in problems(f"{__name__}._heading")[0]
    assert problems(f"{__name__}._partial") == [
        "parameters not documented: b, kwargs",
        "parameters without a type: c",
        "returns a value but has no Returns section",
    ]
    assert problems(f"{__name__}._stale") == ["documented but not in the signature: b"]
    assert problems("scenegen.io.hdf5.read") == []  # a complete one
