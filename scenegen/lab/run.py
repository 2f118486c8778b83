"""The one bridge from a sequence to a tracker: which targets, how it runs, what is recorded.

``scenegen track``, the experiments and fixture regeneration all go through :func:`run`,
so the tracked targets (those present at frame 0, :meth:`Sequence.initial_targets`), the
initial boxes and the recorded result are decided here and nowhere else.

The tracker is one of ours by name (``trackers.names()``), a ``"module:factory"`` or
``"path/to/file.py:factory"`` string naming a user's factory, or the factory itself: any
callable returning an object with ``init(frame, boxes)`` and ``step(frame) -> .boxes``
(:class:`trackers.Tracker`). A factory gets ``rng=seed`` when it accepts ``rng`` (or
``**kwargs``), and the parameters as keywords.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from scenegen.errors import ConfigError, DataError, TrackerError
from scenegen.io import TrackerResult

__all__ = ["Run", "make_tracker", "resolve_factory", "run", "run_tracker", "tracker_label"]

TrackerSpec = str | Callable[..., Any]


@dataclass(frozen=True)
class Run:
    """A tracker run over a sequence.

    Attributes
    ----------
    result : TrackerResult
        What a result file holds (boxes (T, M, 4) float32, target ids, SHM orderings).
    targets : ndarray of shape (M,)
        Indices into the sequence's entities of the tracked targets, in result order.
    extras : dict of str to ndarray
        The tracker's per-frame diagnostics, shape (T, ...) (see ``trackers.track``).
    tracker : object
        The tracker after the run (for attributes such as ``orderings``).
    """

    result: TrackerResult
    targets: NDArray[np.intp]
    extras: dict[str, NDArray[Any]] = field(default_factory=dict)
    tracker: Any = None


def resolve_factory(spec: str) -> Callable[..., Any]:
    """The callable named by ``"module:attr"`` or ``"path/to/file.py:attr"``.

    The current directory is searched first for ``module`` (as ``python -m`` does), so a
    user's module next to their data is found. A ``.py`` file is imported with its folder
    put first on ``sys.path`` (its sibling modules import, as with ``python FILE``);
    ``attr`` may be dotted (``module:Class.create``).

    Parameters
    ----------
    spec : str
        ``"MODULE:ATTR"`` or ``"path/to/file.py:ATTR"`` (split at the last colon).

    Returns
    -------
    callable
        The object named, checked to be callable.

    Raises
    ------
    ConfigError
        One line naming ``spec`` and what is wrong (no colon, module not importable,
        attribute missing or not callable).
    """
    import importlib
    import importlib.util
    import sys
    from pathlib import Path

    module_name, sep, attr = spec.rpartition(":")
    if not sep or not module_name or not attr:
        raise ConfigError(f"tracker {spec!r}: expected a tracker name or MODULE:FACTORY")
    try:
        if module_name.endswith(".py"):
            path = Path(module_name)
            if not path.is_file():
                raise ConfigError(f"tracker {spec!r}: no such file {module_name}")
            name = f"scenegen_user_tracker_{path.stem}"
            folder = str(path.resolve().parent)  # its sibling modules import, as with python FILE
            if folder not in sys.path:
                sys.path.insert(0, folder)
            loader_spec = importlib.util.spec_from_file_location(name, path)
            assert loader_spec is not None and loader_spec.loader is not None
            module = importlib.util.module_from_spec(loader_spec)
            sys.modules[name] = module
            loader_spec.loader.exec_module(module)
        else:
            if "" not in sys.path and str(Path.cwd()) not in sys.path:
                sys.path.insert(0, str(Path.cwd()))
            module = importlib.import_module(module_name)
    except (ConfigError, KeyboardInterrupt, GeneratorExit):
        raise
    except BaseException as err:  # a user's module may raise anything on import, even exit
        text = str(err).strip().splitlines()
        raise ConfigError(
            f"tracker {spec!r}: cannot import {module_name}: {type(err).__name__}: "
            f"{text[0] if text else ''}"
        ) from None
    obj: Any = module
    for part in attr.split("."):
        if not hasattr(obj, part):
            where = getattr(module, "__file__", None)
            raise ConfigError(
                f"tracker {spec!r}: {module_name} has no attribute {attr!r}"
                + (f" (imported from {where})" if where else "")
            )
        obj = getattr(obj, part)
    if not callable(obj):
        raise ConfigError(f"tracker {spec!r}: {attr} is not callable ({type(obj).__name__})")
    return obj


def tracker_label(tracker: TrackerSpec) -> str:
    """The name a result records for ``tracker``: the name or ``module:factory`` string
    (a file spec by its file name, since a result group's name holds no ``/``), else
    ``module:qualname`` of a factory.

    Parameters
    ----------
    tracker : str or callable
        A tracker name, a ``module:factory`` or ``path/to/file.py:factory`` spec, or a
        factory.

    Returns
    -------
    str
        The label (``"?"`` for a factory without a module).

    Examples
    --------
    >>> tracker_label("dps")
    'dps'
    >>> tracker_label("path/to/file.py:make")
    'file.py:make'
    """
    if isinstance(tracker, str):
        module, sep, attr = tracker.rpartition(":")
        if sep and "/" in module:
            return f"{module.rsplit('/', 1)[-1]}:{attr}"
        return tracker
    module = getattr(tracker, "__module__", None) or "?"
    name = getattr(tracker, "__qualname__", None) or type(tracker).__name__
    return f"{module}:{name}"


def _accepts_rng(factory: Callable[..., Any]) -> bool:
    import inspect

    try:
        sig = inspect.signature(factory)
    except (TypeError, ValueError):
        return False
    return any(
        p.name == "rng" or p.kind is inspect.Parameter.VAR_KEYWORD
        for p in sig.parameters.values()
    )


def make_tracker(tracker: TrackerSpec, params: dict[str, Any], seed: int) -> Any:
    """Build ``tracker`` (a name, a ``module:factory`` spec or a factory) with ``params``
    and ``rng=seed`` (a factory gets ``rng`` only if it accepts it).

    Parameters
    ----------
    tracker : str or callable
        A tracker name (``trackers.names()``), a ``module:factory`` or
        ``path/to/file.py:factory`` spec (:func:`resolve_factory`), or a factory.
    params : dict
        Keyword parameters, without ``rng``.
    seed : int
        The tracker's ``rng``.

    Returns
    -------
    trackers.Tracker
        The tracker, not yet initialised.

    Raises
    ------
    ConfigError
        For an ``rng`` in ``params``, a spec that does not resolve, an unknown name or
        parameter (a ``TypeError`` or ``ValueError`` of the factory), or an object that
        is not a tracker (a class, or naming the method it lacks).
    TrackerError
        If a user's factory raises anything else.
    """
    import trackers

    if "rng" in params:
        raise ConfigError(
            "parameter 'rng': the tracker's seed is given by the seed (--seed), not as a parameter"
        )
    if isinstance(tracker, str) and ":" not in tracker:
        try:
            return trackers.make(tracker, rng=seed, **params)
        except (TypeError, ValueError) as err:
            raise ConfigError(str(err)) from None
    factory = resolve_factory(tracker) if isinstance(tracker, str) else tracker
    label = tracker_label(tracker)
    kwargs = dict(params)
    if _accepts_rng(factory):
        kwargs.setdefault("rng", seed)
    try:
        obj = factory(**kwargs)
    except (TypeError, ValueError) as err:
        raise ConfigError(f"tracker {label!r}: {err}") from None
    except (KeyboardInterrupt, GeneratorExit):
        raise
    except BaseException as err:  # the user's factory failed for its own reasons (or exited)
        raise TrackerError(
            f"tracker {label!r} failed while being built: {type(err).__name__}: "
            f"{_first_line(err)} (rerun with --debug for its traceback)"
        ) from err
    if isinstance(obj, type):  # a class has init and step too, unbound
        raise ConfigError(
            f"tracker {label!r} returned the class {obj.__name__}, not a tracker "
            f"(return an instance, {obj.__name__}(...))"
        )
    if not isinstance(obj, trackers.Tracker):
        missing = [m for m in ("init", "step") if not callable(getattr(obj, m, None))]
        raise ConfigError(
            f"tracker {label!r} returned a {type(obj).__name__}, which has no "
            f"{' or '.join(missing)} method (a tracker needs init(frame, boxes) and step(frame))"
        )
    return obj


def run(
    seq: Any,
    name: TrackerSpec,
    params: dict[str, Any] | None = None,
    seed: int = 0,
    *,
    progress: Callable[[int], None] | None = None,
    single_thread: bool = False,
) -> Run:
    """Track the targets of ``seq`` present at frame 0 with tracker ``name``.

    Parameters
    ----------
    seq : Sequence
        The sequence (frames may be lazy).
    name : str or callable
        A tracker name (``trackers.names()``), a ``"module:factory"`` spec, or a factory.
    params : dict, optional
        Tracker parameters (``trackers.make(name, **params)``, or the factory's keywords).
    seed : int, default 0
        The tracker's ``rng``.
    progress : callable, optional
        Called with the number of frames done.
    single_thread : bool, default False
        Run compiled kernels on one thread (what experiment workers do), restoring the
        thread count afterwards.

    Returns
    -------
    Run
        The result (tracker label, parameters, seed, boxes (T, M, 4) float32 in px, target
        ids, SHM orderings), the tracked targets' entity indices (M,), the tracker's
        per-frame extras, and the tracker itself.

    Raises
    ------
    DataError
        If no target is present at frame 0, or the file is damaged.
    ConfigError
        If the tracker rejects its parameters or the scene (a ``ValueError``).
    TrackerError
        If a user's tracker (a factory or spec, not one of ours) raises anything else
        while it runs; or if a tracker's boxes (finite but beyond the float32 range),
        ``orderings`` or ``order_prob`` cannot be stored in a result.
    """
    import numba

    import trackers

    params = dict(params or {})
    targets = seq.initial_targets(0)
    if targets.size == 0:
        raise DataError(f"sequence {seq.name!r} has no target present at frame 0")
    init = seq.init_boxes(0)
    previous = numba.get_num_threads()
    if single_thread:
        numba.set_num_threads(1)
    done = [0]  # steps completed, for the message of a user's tracker that raises

    def step_done(t: int) -> None:
        done[0] = t
        if progress is not None:
            progress(t)

    ours = isinstance(name, str) and ":" not in name
    try:
        tracker = make_tracker(name, params, seed)
        out = trackers.track(tracker, seq.frames, init, progress=step_done)
    except (DataError, ConfigError, TrackerError):
        raise  # a damaged file (exit 1), bad parameters (2), a user's factory failed (1)
    except ValueError as err:
        if ours:
            raise ConfigError(str(err)) from None  # ours rejects its parameters or the scene
        raise _failed(name, seq, done[0], err) from err
    except (KeyboardInterrupt, GeneratorExit):
        raise
    except BaseException as err:  # a user's SystemExit too: its failure, not a clean exit
        if ours:
            raise  # ours: a bug to report, with its traceback
        raise _failed(name, seq, done[0], err) from err
    finally:
        numba.set_num_threads(previous)
    result = _result(seq, name, params, seed, tracker, out)
    return Run(result=result, targets=targets, extras=out.extras, tracker=tracker)


def _first_line(err: BaseException) -> str:
    text = str(err).strip()
    return text.splitlines()[0][:200] if text else ""


def _failed(name: TrackerSpec, seq: Any, done: int, err: BaseException) -> TrackerError:
    """The one line for a user's tracker that raised (or broke the protocol) while it ran."""
    return TrackerError(
        f"tracker {tracker_label(name)!r} failed on sequence {seq.name!r} after "
        f"{done} of {len(seq.frames) - 1} steps: {type(err).__name__}: {_first_line(err)}"
        " (rerun with --debug for its traceback)"
    )


def _result(
    seq: Any, name: TrackerSpec, params: dict[str, Any], seed: int, tracker: Any, out: Any
) -> TrackerResult:
    """The :class:`TrackerResult` of a run, its depth-order outputs checked.

    Raises
    ------
    TrackerError
        If a tracker's boxes (beyond the float32 range), ``orderings`` or ``order_prob``
        are not what a result file holds.
    """
    targets = seq.initial_targets(0)
    label = tracker_label(name)
    orderings = getattr(tracker, "orderings", None)
    order_prob = out.extras.get("order_prob")
    if orderings is None or order_prob is None:
        # Stored together or not at all (a one-frame sequence has no step, no order_prob).
        orderings = order_prob = None
    try:
        if orderings is not None:
            orderings = np.asarray(orderings, dtype=np.int16)
        if order_prob is not None:
            order_prob = np.array(order_prob, dtype=np.float32)
            if order_prob.ndim == 2:
                # Frame 0 is the initialisation: every ordering equally likely.
                order_prob[0] = 1.0 / order_prob.shape[1]
    except (TypeError, ValueError) as err:
        raise TrackerError(
            f"tracker {label!r}: orderings and order_prob must be numeric arrays: "
            f"{_first_line(err)}"
        ) from None
    target_ids = seq.entities.id[targets]
    result = TrackerResult(
        tracker=label,
        params=params,
        seed=seed,
        sequence=seq.name,
        target_ids=target_ids,
        boxes=_float32_boxes(label, out.boxes, target_ids),
        orderings=orderings,
        order_prob=order_prob,
    )
    if bad := result.problems():
        raise TrackerError(f"tracker {label!r}: its output cannot be stored: {bad[0]}")
    return result


def _float32_boxes(label: str, boxes: NDArray[Any], target_ids: NDArray[Any]) -> NDArray[Any]:
    """``boxes`` (T, M, 4) as the float32 a result file holds.

    Raises
    ------
    TrackerError
        Naming the frame, the target and the box, if a finite value is beyond the float32
        range (it would become inf).
    """
    with np.errstate(over="ignore"):
        out = np.asarray(boxes).astype(np.float32)
    over = np.isfinite(boxes) & ~np.isfinite(out)
    if over.any():
        t, m, _ = (int(i[0]) for i in np.nonzero(over))
        raise TrackerError(
            f"tracker {label!r}: its box at frame {t} for target {target_ids[m].item()} is "
            f"{np.asarray(boxes)[t, m].tolist()}, out of the range a result file holds "
            f"(|value| <= {float(np.finfo(np.float32).max):.4g}, float32)"
        )
    return out


def run_tracker(
    seq: Any,
    name: TrackerSpec,
    params: dict[str, Any] | None = None,
    seed: int = 0,
    progress: Callable[[int], None] | None = None,
) -> TrackerResult:
    """:func:`run`, returning only the :class:`~scenegen.io.TrackerResult`.

    Parameters
    ----------
    seq : Sequence
        The sequence (frames may be lazy).
    name : str or callable
        A tracker name, a ``"module:factory"`` spec, or a factory.
    params : dict, optional
        Tracker parameters.
    seed : int, default 0
        The tracker's ``rng``.
    progress : callable, optional
        Called with the number of frames done.

    Returns
    -------
    TrackerResult
        The result of :func:`run` (compiled kernels on the current thread count).

    Raises
    ------
    DataError, ConfigError, TrackerError
        As :func:`run`.
    """
    return run(seq, name, params, seed, progress=progress).result
