"""The conformance checks: small generated scenes, a protocol-only runner, one function
per check (``CHECKS``), and their :class:`Options`.

Each check takes ``(factory, options)`` and returns a message (passed), raises
``AssertionError`` (failed, saying why) or :class:`NotApplicable` (skipped: the tracker
does not claim the property). :func:`scenegen.testing.check_tracker` runs them; the
module docstring of :mod:`scenegen.testing.conformance` lists what each one checks.
The runner uses only ``init`` and ``step`` (the library never imports ``trackers``).
"""

from __future__ import annotations

import inspect
import numbers
import operator
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cache, partial
from typing import Any

import numpy as np
from numpy.typing import NDArray

from scenegen.evaluation.metrics import centres, iou

__all__ = [
    "CHECKS",
    "EDGE_FIXTURES",
    "SHIFT",
    "NotApplicable",
    "Options",
    "SceneError",
    "first_line",
    "label",
]

EDGE_FIXTURES = (
    "single-frame",
    "one-pixel",
    "enter-leave",
    "full-occlusion",
    "distractor-on-target",
)
SHIFT = (7, 5)  # camera shift (dx, dy) of the equivariance check, pixels


@dataclass(frozen=True)
class Options:
    """What :func:`check_tracker` accepts (keyword options), with their defaults.

    Attributes
    ----------
    seed : int
        First seed (>= 0, a seed of ``numpy.random.default_rng``) given to the factory
        (``rng=seed``) when it accepts ``rng``.
    deterministic, handles_occlusion : bool or None
        The tracker's claims; None: read the tracker's attribute of that name (defaults
        True and False).
    repeats : int
        Runs of each behavioural check (seeds ``seed .. seed + repeats - 1``).
    min_pass_rate : float
        Fraction of those runs that must pass, in (0, 1].
    iou_threshold : float
        IoU a kept target must reach.
    equivariance_tol : float
        Pixels the shifted centres may differ by.
    checks : tuple of str or None
        Run only these checks (default: all of :data:`CHECKS`).
    """

    seed: int = 0
    deterministic: bool | None = None
    handles_occlusion: bool | None = None
    repeats: int = 1
    min_pass_rate: float = 1.0
    iou_threshold: float = 0.5
    equivariance_tol: float = 1.0
    checks: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        if (
            isinstance(self.seed, bool)
            or not isinstance(self.seed, (int, np.integer))
            or self.seed < 0
        ):
            raise ValueError(f"seed must be an integer >= 0, got {self.seed!r}")
        if (
            isinstance(self.repeats, (bool, np.bool_))
            or not isinstance(self.repeats, numbers.Integral)
            or self.repeats < 1
        ):
            raise ValueError(f"repeats must be an integer >= 1, got {self.repeats!r}")
        object.__setattr__(self, "repeats", operator.index(self.repeats))  # a numpy int too
        for name in ("deterministic", "handles_occlusion"):
            value = getattr(self, name)
            if value is not None and not isinstance(value, (bool, np.bool_)):
                raise ValueError(f"{name} must be True, False or None, got {value!r}")
        for name in ("min_pass_rate", "iou_threshold", "equivariance_tol"):
            value = getattr(self, name)
            if isinstance(value, (bool, np.bool_)) or not isinstance(
                value, (int, float, np.integer, np.floating)
            ):
                raise ValueError(f"{name} must be a number, got {value!r}")
        if not 0 < self.min_pass_rate <= 1:
            raise ValueError(f"min_pass_rate must be in (0, 1], got {self.min_pass_rate!r}")
        if not 0 < self.iou_threshold <= 1:
            raise ValueError(f"iou_threshold must be in (0, 1], got {self.iou_threshold!r}")
        if not self.equivariance_tol >= 0:
            raise ValueError(f"equivariance_tol must be >= 0, got {self.equivariance_tol!r}")
        if self.checks is not None:
            for name in self.checks:
                if name not in CHECKS:
                    raise ValueError(f"unknown check {name!r}; valid: {', '.join(CHECKS)}")


class NotApplicable(Exception):
    """A check that does not apply (the message says why)."""


# --------------------------------------------------------------------------------------
# Building and running trackers


def label(factory: Any) -> str:
    """A name for ``factory`` that is the same in every process (a pytest test id).

    Its ``__qualname__`` (or ``__name__``) when it has one, even a ``functools.partial``
    given one; else a partial ``functools.partial(f, a, k=v)`` is ``f(a, k=v)``, and
    another object with no name is named by its type (a ``repr`` may hold a memory
    address, which changes from run to run).

    Parameters
    ----------
    factory : callable
        A tracker factory (a class, a function, a ``functools.partial``, ...).

    Returns
    -------
    str
        The name.
    """
    name = getattr(factory, "__qualname__", None) or getattr(factory, "__name__", None)
    if isinstance(name, str) and name:  # a partial given a name keeps it
        return name
    if isinstance(factory, partial):
        args = [_stable_repr(a) for a in factory.args]
        args += [f"{k}={_stable_repr(v)}" for k, v in factory.keywords.items()]
        return f"{label(factory.func)}({', '.join(args)})"
    return _stable_repr(factory)


def _stable_repr(value: Any) -> str:
    text = repr(value)
    return type(value).__qualname__ if " at 0x" in text else text


def _accepts_rng(factory: Callable[..., Any]) -> bool:
    try:
        params = inspect.signature(factory).parameters.values()
    except (TypeError, ValueError):
        return False
    return any(p.name == "rng" or p.kind is p.VAR_KEYWORD for p in params)


def _build(factory: Callable[..., Any], seed: int) -> Any:
    return factory(rng=seed) if _accepts_rng(factory) else factory()


@dataclass
class _Run:
    boxes: NDArray[np.float64] | None = None  # (T, K, 4); None if it raised
    error: str | None = None
    problems: list[str] = field(default_factory=list)  # protocol breaches of the estimates


def _readonly(frames: Any) -> NDArray[np.uint8]:
    arr = np.array(frames, dtype=np.uint8, copy=True)
    arr.setflags(write=False)
    return arr


def _run(tracker: Any, frames: NDArray[np.uint8], init: NDArray[np.float64]) -> _Run:
    """Run ``tracker`` over ``frames`` (T, H, W, 3) from ``init`` (K, 4), recording the
    first exception (with its frame) and every malformed estimate."""
    k = init.shape[0]
    out = np.full((len(frames), k, 4), np.nan)
    out[0] = init
    run = _Run()
    try:
        tracker.init(frames[0], init.copy())
    except (KeyboardInterrupt, GeneratorExit):
        raise
    except BaseException as err:  # a SystemExit too: the tracker failing, not a pass
        run.error = f"init raised {type(err).__name__}: {first_line(err)}"
        run.error += _writes_hint(lambda f: tracker.init(f, init.copy()), frames[0])
        return run
    for t in range(1, len(frames)):
        try:
            est = tracker.step(frames[t])
        except (KeyboardInterrupt, GeneratorExit):
            raise
        except BaseException as err:
            run.error = f"step at frame {t} raised {type(err).__name__}: {first_line(err)}"
            run.error += _writes_hint(tracker.step, frames[t])
            return run
        boxes = getattr(est, "boxes", None)
        if boxes is None:
            run.problems.append(f"frame {t}: the estimate ({type(est).__name__}) has no .boxes")
            continue
        try:
            arr = np.asarray(boxes, dtype=np.float64)
        except (TypeError, ValueError):
            run.problems.append(f"frame {t}: .boxes is not numeric")
            continue
        if arr.shape != (k, 4):
            run.problems.append(f"frame {t}: .boxes has shape {arr.shape}, expected ({k}, 4)")
            continue
        finite = np.isfinite(arr)
        mixed = ~(finite.all(axis=1) | np.isnan(arr).all(axis=1))
        mixed |= finite.all(axis=1) & (arr[:, 2:] < 0).any(axis=1)
        if mixed.any():
            j = int(np.flatnonzero(mixed)[0])
            run.problems.append(
                f"frame {t}: box {j} is {arr[j].tolist()} (a row must be finite with "
                "w, h >= 0, or all NaN)"
            )
        out[t] = arr
    run.boxes = out
    return run


def _writes_hint(call: Callable[[Any], Any], frame: NDArray[np.uint8]) -> str:
    """After ``call(frame)`` raised on a read-only frame: a hint if the call, repeated on
    a writable copy, writes into it (OpenCV's error for a read-only array does not say
    so), else ``""``."""
    copy = np.array(frame, copy=True)
    try:
        call(copy)
    except (KeyboardInterrupt, GeneratorExit):
        raise
    except BaseException:
        pass
    if np.array_equal(copy, frame):
        return ""
    return (
        " (it writes into its input frame, which is read-only here: frames are shared, "
        "copy one before drawing on it)"
    )


def first_line(err: BaseException) -> str:
    """The first line of an exception's message, for one-line reports.

    Parameters
    ----------
    err : BaseException
        The exception.

    Returns
    -------
    str
        The first line of ``str(err)`` with surrounding whitespace stripped; "" when the
        message is empty.
    """
    text = str(err).strip().splitlines()
    return text[0] if text else ""


def _iou(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """:func:`scenegen.evaluation.metrics.iou` of boxes (..., 4), with 0 (a miss) where
    either box is missing (NaN)."""
    return np.nan_to_num(iou(a, b), nan=0.0)


# --------------------------------------------------------------------------------------
# Scenes (small, generated once per process)


def _disc() -> Any:
    from scenegen.config import Appearance

    return Appearance(
        shape="ellipse",
        size=(14, 14),
        pattern="sectors",
        colors=((230, 30, 30), (30, 170, 30), (30, 60, 230), (240, 210, 0)),
    )


def _lone_config(width: int, height: int, background: Any) -> Any:
    from scenegen.config import AR2, EntitySpec, Motion, SceneConfig

    still = AR2(boundary="free", sigma=0.0)
    return SceneConfig(
        name="conformance-lone-target",
        width=width,
        height=height,
        n_frames=16,
        background=background,
        entities=(
            EntitySpec(
                name="target",
                role="target",
                appearance=_disc(),
                position=(width / 2 - 10.0, height / 2 - 4.0),
                motion=Motion(x=still, y=still, velocity=(1.25, 0.5)),
            ),
        ),
    )


class SceneError(RuntimeError):
    """A conformance scene could not be built (say an unwritable fixture cache): a fault
    of the environment, not of the tracker under test, so it is raised, not reported as
    a failed check."""


@cache
def _scene(name: str) -> tuple[NDArray[np.uint8], NDArray[np.float64], NDArray[np.float64]]:
    """(frames (T, H, W, 3) read-only, init boxes (K, 4), ground-truth boxes (T, K, 4)).

    Raises
    ------
    SceneError
        If the scene cannot be built or read.
    """
    try:
        return _make_scene(name)
    except Exception as err:
        raise SceneError(
            f"cannot build the conformance scene {name!r}: {type(err).__name__}: "
            f"{first_line(err)}"
        ) from err


def _make_scene(
    name: str,
) -> tuple[NDArray[np.uint8], NDArray[np.float64], NDArray[np.float64]]:
    from scenegen.config import AR2, Appearance, Background, EntitySpec, Motion, SceneConfig
    from scenegen.render.plan import generate

    if name in EDGE_FIXTURES:
        from scenegen.testing.builtin import builtin_fixture

        seq = builtin_fixture(name)
    elif name == "lone":
        bg = Background(kind="texture", color=(200, 200, 180), low=90, high=170, scale=4)
        seq = generate(_lone_config(96, 72, bg), seed=3)
    elif name == "shifted":
        # A uniform background: the scene seen by two cameras SHIFT pixels apart.
        bg = Background(kind="uniform", color=(235, 235, 235))
        seq = generate(_lone_config(96 + SHIFT[0], 72 + SHIFT[1], bg), seed=3)
    elif name == "pair":
        # Two targets (K = 2) apart on a uniform background, moving slowly.
        still = AR2(boundary="free", sigma=0.0)
        cfg = SceneConfig(
            name="conformance-pair",
            width=96,
            height=64,
            n_frames=6,
            background=Background(kind="uniform", color=(235, 235, 235)),
            entities=tuple(
                EntitySpec(
                    name=f"target-{i}",
                    role="target",
                    appearance=_disc(),
                    position=(x, 32.0),
                    motion=Motion(x=still, y=still, velocity=(v, 0.0)),
                    depth=((0, i),),
                )
                for i, (x, v) in enumerate(((24.0, 1.0), (72.0, -1.0)))
            ),
        )
        seq = generate(cfg, seed=3)
    elif name == "occlusion":
        still = AR2(boundary="free", sigma=0.0)
        cfg = SceneConfig(
            name="conformance-occlusion",
            width=120,
            height=64,
            n_frames=20,
            background=Background(kind="uniform", color=(235, 235, 235)),
            entities=(
                EntitySpec(
                    name="walker",
                    role="target",
                    appearance=_disc(),
                    position=(16.0, 32.0),
                    motion=Motion(x=still, y=still, velocity=(4.0, 0.0)),
                    depth=((0, 1),),
                ),
                EntitySpec(
                    name="wall",
                    role="occluder",
                    appearance=Appearance(shape="rect", size=(24, 32), colors=((90, 90, 90),)),
                    position=(48.0, 32.0),
                    depth=((0, 0),),
                ),
            ),
        )
        seq = generate(cfg, seed=3)
    else:
        raise KeyError(name)
    targets = seq.initial_targets(0)
    return (
        _readonly(seq.frames),
        seq.init_boxes(0),
        np.asarray(seq.gt.box[:, targets], dtype=np.float64),
    )


# --------------------------------------------------------------------------------------
# The checks: each takes (factory, options) and returns a message, raises AssertionError
# (failed) or NotApplicable (not applicable).


def _claim(factory: Callable[..., Any], opts: Options, name: str, default: bool) -> bool:
    given = getattr(opts, name)
    if given is not None:
        return bool(given)
    return bool(getattr(_build(factory, opts.seed), name, default))


def check_protocol(factory: Callable[..., Any], opts: Options) -> str:
    """The object has callable ``init`` and ``step``."""
    try:
        tracker = _build(factory, opts.seed)
    except (KeyboardInterrupt, GeneratorExit):
        raise
    except BaseException as err:
        raise AssertionError(
            f"the factory raised {type(err).__name__}: {first_line(err)}"
        ) from None
    if isinstance(tracker, type):  # a class has init and step too, unbound
        raise AssertionError(
            f"the factory returned the class {tracker.__name__}, not a tracker (return an "
            f"instance, {tracker.__name__}(...))"
        )
    missing = [m for m in ("init", "step") if not callable(getattr(tracker, m, None))]
    if missing:
        raise AssertionError(
            f"{type(tracker).__name__} has no {' or '.join(missing)} method "
            "(a tracker needs init(frame, boxes) and step(frame) -> estimate with .boxes)"
        )
    return f"{type(tracker).__name__} has init and step"


def _edge_runs(factory: Callable[..., Any], opts: Options) -> dict[str, _Run]:
    runs = {}
    for name in EDGE_FIXTURES:
        frames, init, _ = _scene(name)
        runs[name] = _run(_build(factory, opts.seed), frames, init)
    return runs


def check_edge_fixtures(factory: Callable[..., Any], opts: Options) -> str:
    """Runs without exception on every edge-case fixture."""
    bad = [f"{n}: {r.error}" for n, r in _edge_runs(factory, opts).items() if r.error]
    if bad:
        raise AssertionError(
            f"raised on {len(bad)} of {len(EDGE_FIXTURES)} edge fixtures: " + "; ".join(bad)
        )
    return f"ran on {', '.join(EDGE_FIXTURES)}"


#: Scenes of the ``boxes`` check beside the edge fixtures: ``pair`` has two targets.
BOX_SCENES = ("pair",)


def check_boxes(factory: Callable[..., Any], opts: Options) -> str:
    """Estimates have ``boxes`` (K, 4), each row finite or all NaN, on the edge fixtures
    and on a scene of two targets (K = 2)."""
    runs = _edge_runs(factory, opts)
    for name in BOX_SCENES:
        frames, init, _ = _scene(name)
        runs[name] = _run(_build(factory, opts.seed), frames, init)
    bad = [
        f"{n}: {r.problems[0]}"
        + (f" (and {len(r.problems) - 1} more)" if len(r.problems) > 1 else "")
        for n, r in runs.items()
        if r.problems
    ]
    if bad:
        raise AssertionError("malformed estimates: " + "; ".join(bad))
    # A run that raised, or a one-frame scene, has no estimate to examine.
    ran = [n for n, r in runs.items() if r.boxes is not None and len(r.boxes) > 1]
    if not ran:
        raise NotApplicable("no estimate to check: every run raised (see edge_fixtures)")
    lost = sum(int(np.isnan(runs[n].boxes[1:, :, 0]).sum()) for n in ran)
    return f"(K, 4), finite or NaN on {len(ran)} scenes, K up to 2 ({lost} NaN boxes)"


#: Scenes of the ``deterministic`` check: one target, then two (a tracker may draw
#: unseeded only when it has several targets, e.g. to order them).
DETERMINISM_SCENES = ("lone", "pair")


def check_deterministic(factory: Callable[..., Any], opts: Options) -> str:
    """Two trackers with the same seed give identical boxes, on a scene of one target
    and on one of two."""
    if not _claim(factory, opts, "deterministic", True):
        raise NotApplicable("the tracker does not claim to be deterministic")
    for name in DETERMINISM_SCENES:
        frames, init, _ = _scene(name)
        a, b = (_run(_build(factory, opts.seed), frames, init) for _ in range(2))
        if a.error or b.error:
            raise AssertionError(f"the run on {name!r} raised: {a.error or b.error}")
        if not np.array_equal(a.boxes, b.boxes, equal_nan=True):
            # NaN in both runs (lost in both) is no difference; NaN in one is infinite.
            diff = np.abs(np.nan_to_num(a.boxes - b.boxes, nan=np.inf))
            diff[np.isnan(a.boxes) & np.isnan(b.boxes)] = 0.0
            t = int(np.argwhere(diff > 0)[0][0])
            raise AssertionError(
                f"two runs with seed {opts.seed} differ from frame {t} (largest difference "
                f"{float(diff.max()):.3g} px) on the {a.boxes.shape[1]}-target scene "
                f"{name!r}; pass deterministic=False if the tracker is "
                "stochastic (then judge it with repeats and min_pass_rate)"
            )
    return f"same boxes twice with seed {opts.seed} on {', '.join(DETERMINISM_SCENES)}"


def _judge(opts: Options, name: str, one: Callable[[int], str | None]) -> str:
    """Run ``one(seed)`` (None: passed, else why not) ``opts.repeats`` times."""
    seeds = [opts.seed + i for i in range(opts.repeats)]
    failures = [(s, why) for s in seeds if (why := one(s)) is not None]
    rate = 1 - len(failures) / len(seeds)
    if rate + 1e-12 < opts.min_pass_rate:
        if len(seeds) == 1:
            raise AssertionError(failures[0][1])
        detail = "; ".join(f"seed {s}: {why}" for s, why in failures[:3])
        if len(failures) > 3:
            detail += f"; and {len(failures) - 3} more failing runs"
        raise AssertionError(
            f"passed {len(seeds) - len(failures)} of {len(seeds)} runs, "
            f"below the required rate {opts.min_pass_rate:g}: {detail}"
        )
    if len(seeds) == 1:
        return name
    return f"{name} in {len(seeds) - len(failures)} of {len(seeds)} runs"


def check_translation_equivariance(factory: Callable[..., Any], opts: Options) -> str:
    """Centres on a shifted scene are the centres shifted, within ``equivariance_tol``."""
    full, _, gt = _scene("shifted")
    dx, dy = SHIFT
    h, w = full.shape[1] - dy, full.shape[2] - dx
    a_frames, b_frames = full[:, :h, :w], full[:, dy:, dx:]
    init = gt[0]
    shift = np.array([dx, dy, 0.0, 0.0])

    def one(seed: int) -> str | None:
        a = _run(_build(factory, seed), a_frames, init)
        b = _run(_build(factory, seed), b_frames, init - shift)
        if a.error or b.error:
            return f"the run raised: {a.error or b.error}"
        err = np.abs(centres(b.boxes) + shift[:2] - centres(a.boxes))
        worst = np.nan_to_num(err, nan=0.0).max(axis=-1)  # (T, K)
        # A box with any NaN is a lost target (a row with some NaN fails ``boxes``).
        nan_differs = np.isnan(a.boxes).any(axis=-1) != np.isnan(b.boxes).any(axis=-1)
        if nan_differs.any():
            t = int(np.argwhere(nan_differs)[0][0])
            return f"the target is lost (NaN) in only one of the two views from frame {t}"
        if worst.max() > opts.equivariance_tol:
            t = int(np.argwhere(worst > opts.equivariance_tol)[0][0])
            return (
                f"shifting the scene by ({dx}, {dy}) px moved the estimated centre by "
                f"{float(worst[t].max()):.2f} px more at frame {t} (tolerance "
                f"{opts.equivariance_tol:g} px)"
            )
        return None

    return _judge(opts, f"equivariant within {opts.equivariance_tol:g} px", one)


#: Box conventions a tracker may return by mistake, and their [x, y, w, h] boxes.
_CONVENTIONS: dict[str, Callable[[NDArray[np.float64]], NDArray[np.float64]]] = {
    "[cx, cy, w, h] (centre)": lambda b: np.concatenate(
        [b[..., :2] - b[..., 2:] / 2, b[..., 2:]], axis=-1
    ),
    "[x0, y0, x1, y1] (corners)": lambda b: np.concatenate(
        [b[..., :2], b[..., 2:] - b[..., :2]], axis=-1
    ),
    "[y, x, h, w] (row first)": lambda b: b[..., [1, 0, 3, 2]],
}


def _convention_hint(
    boxes: NDArray[np.float64], gt: NDArray[np.float64], threshold: float
) -> str:
    """If ``boxes`` (T, K, 4), read in another convention, keep IoU >= ``threshold``
    with ``gt`` every frame: a phrase naming that convention, else ``""``."""
    for name, convert in _CONVENTIONS.items():
        if _iou(convert(boxes), gt).min() >= threshold:
            return (
                f"; read as {name} the boxes would match: a box is [x, y, w, h], "
                "(x, y) its top-left corner"
            )
    return ""


def _iou_check(
    factory: Callable[..., Any], opts: Options, scene: str, frames_from: int, what: str
) -> str:
    frames, init, gt = _scene(scene)

    def one(seed: int) -> str | None:
        run = _run(_build(factory, seed), frames, init)
        if run.error:
            return f"the run raised: {run.error}"
        iou = _iou(run.boxes, gt)[frames_from:].min(axis=-1)
        if iou.min() < opts.iou_threshold:
            t = frames_from + int(np.argmax(iou < opts.iou_threshold))
            return (
                f"IoU fell to {float(iou.min()):.2f} (first below {opts.iou_threshold:g} "
                f"at frame {t} of {len(frames)})"
            ) + _convention_hint(run.boxes[frames_from:], gt[frames_from:], opts.iou_threshold)
        return None

    return _judge(opts, what, one)


def check_keeps_lone_target(factory: Callable[..., Any], opts: Options) -> str:
    """A lone, slow, unoccluded target: IoU >= ``iou_threshold`` every frame."""
    return _iou_check(factory, opts, "lone", 1, f"IoU >= {opts.iou_threshold:g} in all 16 frames")


def check_recovers_after_occlusion(factory: Callable[..., Any], opts: Options) -> str:
    """After 3 frames fully hidden: IoU >= ``iou_threshold`` in the last 4 of 20 frames."""
    if not _claim(factory, opts, "handles_occlusion", False):
        raise NotApplicable("the tracker does not claim to handle occlusion")
    return _iou_check(
        factory,
        opts,
        "occlusion",
        16,
        f"IoU >= {opts.iou_threshold:g} in frames 16-19 after the occlusion",
    )


#: The checks, by name, in the order they run.
CHECKS: dict[str, Callable[[Callable[..., Any], Options], str]] = {
    "protocol": check_protocol,
    "edge_fixtures": check_edge_fixtures,
    "boxes": check_boxes,
    "deterministic": check_deterministic,
    "translation_equivariance": check_translation_equivariance,
    "keeps_lone_target": check_keeps_lone_target,
    "recovers_after_occlusion": check_recovers_after_occlusion,
}
