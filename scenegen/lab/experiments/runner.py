"""Running an experiment's seeded runs on local processes or a Dask cluster, resumably.

Every run is a :class:`Task`: (experiment, method, preset, swept value, scene index s, run
index r) plus the base seed and the quick flag. An experiment runs S scenes (each its own
scene seed, shared by every method, so that runs are paired) times R tracker runs per
scene. The seeds come from a SHA-256 hash of that key (never Python's ``hash``), so a
run gives the same numbers whichever process or machine runs it.
The worker generates the run's sequence itself (cached per process), runs the tracker and
returns a small record of per-frame measures with floats rounded to fixed decimals. The
parent stores each record as it arrives (one sealed JSON file per run under ``DIR/runs/``,
written to a temporary file in that folder and renamed into place), so running the same
command again skips finished runs (and computes damaged ones again); a Dask worker lost
mid-sweep only loses the task it was running, which the scheduler retries.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
from collections.abc import Callable, Iterable
from concurrent.futures import as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from scenegen.datasets.executor import SCHEDULER_TIMEOUT, LocalPool, connect
from scenegen.errors import ConfigError
from scenegen.lab.experiments.definitions import Experiment, get

__all__ = [
    "BATCH",
    "SCHEDULER_TIMEOUT",
    "Task",
    "Workers",
    "batches",
    "derive_seed",
    "execute",
    "load_record",
    "plan_tasks",
    "run_batch",
    "run_task",
    "tracker_params",
    "workers",
    "write_json_atomic",
]


_DECIMALS = 6
#: Longest run file name with its overrides written out (``Task.filename``): the file
#: system's limit is 255 bytes, and a temporary file's name adds up to about 90.
MAX_FILENAME = 150
_MIN_OVERLAP = 0.1  # pairs overlapping less than this say nothing about depth order


def derive_seed(*parts: Any) -> int:
    """A 63-bit seed from the key ``parts``, stable across processes, runs and machines.

    The parts are joined as text, hashed with SHA-256 and fed to ``np.random.SeedSequence``.

    Parameters
    ----------
    *parts : Any
        The key; each part is taken as ``str(part)``, so ``1`` and ``"1"`` give the same
        seed.

    Returns
    -------
    int
        A seed in [0, 2**63).

    Examples
    --------
    >>> derive_seed("dps-synthetic", "dps", "lam=20.0", 3) == derive_seed(
    ...     "dps-synthetic", "dps", "lam=20.0", 3)
    True
    """
    digest = hashlib.sha256("\x1f".join(str(p) for p in parts).encode("utf-8")).digest()
    words = np.frombuffer(digest, dtype="<u4").tolist()
    return int(np.random.SeedSequence(words).generate_state(1, dtype=np.uint64)[0] >> 1)


def scene_seed(seed: int, experiment: str, preset: str, scene: int) -> int:
    """Seed of scene ``scene`` of ``preset`` in ``experiment`` under base seed ``seed``."""
    return derive_seed(seed, experiment, "scene", preset, scene)


@dataclass(frozen=True)
class Task:
    """One seeded run of one method on one sequence.

    Attributes
    ----------
    experiment, method, preset : str
        Names (``method`` is the method's slug).
    param : str
        The swept parameter ("" without a sweep).
    value : float or None
        Its value.
    scene : int
        Scene index s = 0..S-1 (the scene seed derives from it).
    run : int
        Tracker run index r = 0..R-1 on that scene.
    seed : int
        The experiment's base seed (``--seed``).
    quick : bool
        Scaled-down mode (fewer frames or particles).
    overrides : tuple of (str, value)
        Tracker parameters set for this run over the method's own (``--param``), sorted by
        name; () for the experiment as defined. They do not enter the seeds, so a run
        with overrides is paired with the default run of the same key.
    """

    experiment: str
    method: str
    preset: str
    param: str
    value: float | None
    scene: int
    run: int
    seed: int
    quick: bool
    overrides: tuple[tuple[str, Any], ...] = ()

    def __post_init__(self) -> None:
        # A key read back from a record gives the overrides as JSON lists; the task (its
        # file name, its hash) must be the one planned, with tuples.
        object.__setattr__(self, "overrides",
                           tuple((str(k), _frozen(v)) for k, v in self.overrides))  # fmt: skip

    @property
    def sweep_label(self) -> str:
        """The swept value as ``"param=value"`` (value in ``:g`` format), a str; "" without a
        sweep."""
        return f"{self.param}={self.value:g}" if self.param else ""

    @property
    def case(self) -> tuple[str, int, int]:
        """(preset, scene, run): the key that pairs runs of different methods."""
        return (self.preset, self.scene, self.run)

    def scene_seed(self) -> int:
        """Seed of the run's sequence: shared by every method and run on scene s.

        Derived from the base seed, the experiment, the preset and the scene index only
        (not the method, swept value, run or overrides).

        Returns
        -------
        int
            A seed in [0, 2**63).
        """
        return scene_seed(self.seed, self.experiment, self.preset, self.scene)

    def tracker_seed(self) -> int:
        """Seed of the tracker's random stream for this run.

        Derived from the base seed, the experiment, the method, the preset,
        :attr:`sweep_label`, the scene and the run (not ``quick`` nor the overrides).

        Returns
        -------
        int
            A seed in [0, 2**63).
        """
        return derive_seed(
            self.seed, self.experiment, self.method, self.preset, self.sweep_label,
            self.scene, self.run,
        )

    def filename(self) -> str:
        """The run's record file name, in the experiment's ``runs/`` folder.

        Equal tasks have the same name: an override value is written as
        :func:`_value_text` gives it (``n_particles=100.0`` as ``100``, like 100). A name
        longer than :data:`MAX_FILENAME` characters (many or long overrides) writes the
        overrides as ``__params-`` and 16 hex digits of their SHA-256 instead.

        Returns
        -------
        str
            ``METHOD__PRESET[__PARAMVALUE][__NAME-VALUE...]__sSSS__rRRR.json``: the swept
            value in ``:g`` format, one ``__NAME-VALUE`` per override, scene and run
            zero-padded to three digits (e.g. ``"dps__dps-occlusion__s000__r001.json"``).
        """
        sweep = f"__{self.param}{self.value:g}" if self.param else ""
        over = "".join(f"__{k}-{_value_text(v)}" for k, v in self.overrides)
        tail = f"__s{self.scene:03d}__r{self.run:03d}.json"
        name = f"{self.method}__{self.preset}{sweep}{over}{tail}"
        if len(name) > MAX_FILENAME:
            digest = hashlib.sha256(over.encode("utf-8")).hexdigest()[:16]
            name = f"{self.method}__{self.preset}{sweep}__params-{digest}{tail}"
        return name

    def key(self) -> dict[str, Any]:
        """What identifies the run's record: a stored record of another key is stale.

        Returns
        -------
        dict of str to object
            The attributes by name (``dataclasses.asdict``), without ``overrides`` when
            there are none (so records stored before overrides existed stay valid).
        """
        key = asdict(self)
        if not self.overrides:
            # Records of runs without overrides keep the key they had before overrides existed.
            del key["overrides"]
        return key


def plan_tasks(
    exp: Experiment,
    *,
    runs: int,
    scenes: int | None = None,
    seed: int,
    quick: bool,
    methods: Iterable[str] | None = None,
    values: Iterable[float] | None = None,
    overrides: dict[str, Any] | None = None,
) -> list[Task]:
    """Every task of an experiment, in a fixed order.

    Every method runs on every preset, ``scenes`` scenes (default the experiment's S) and
    ``runs`` tracker runs per scene. ``methods`` (slugs or labels) and ``values`` (of the
    swept parameter) restrict the sweep; by default every method runs at every value.
    ``overrides`` (tracker parameter -> value) is set on every chosen method's tracker
    (see ``Task.overrides``); each method's tracker must accept it with that value.

    Parameters
    ----------
    exp : Experiment
        The experiment.
    runs : int
        Tracker runs R per scene (>= 1).
    scenes : int, optional
        Scenes S per preset (>= 1); default the experiment's.
    seed : int
        Base seed (>= 0).
    quick : bool
        Scaled-down mode; without ``values``, the quick sweep values.
    methods : iterable of str, optional
        Method slugs or labels, each at most once (default all).
    values : iterable of float, optional
        Values of the swept parameter, from the full sweep (default all).
    overrides : dict, optional
        Tracker parameter -> value, set on every chosen method.

    Returns
    -------
    list of Task
        Ordered by method, swept value, preset, scene, then run.

    Raises
    ------
    ConfigError
        For runs or scenes < 1, a negative seed, an unknown method, a method given twice,
        or a value outside the sweep (listing the valid ones), or an override that a chosen
        method's tracker does not accept (naming the method).
    """
    if runs < 1:
        raise ConfigError(f"runs must be >= 1, got {runs}")
    n_scenes = exp.scenes if scenes is None else int(scenes)
    if n_scenes < 1:
        raise ConfigError(f"scenes must be >= 1, got {n_scenes}")
    if seed < 0:
        raise ConfigError(f"seed must be a non-negative integer, got {seed}")
    chosen = [exp.method(m) for m in methods] if methods else list(exp.methods)
    for i, m in enumerate(chosen):
        if m in chosen[:i]:  # each run would be stored and counted twice
            raise ConfigError(f"method {m.label!r} is given twice (--method)")
    sweep = exp.sweep_values(quick)
    if values is not None:
        wanted = [float(v) for v in values]
        valid = [v for _, v in exp.sweep_values(False) if v is not None]
        for v in wanted:
            if v not in valid:
                raise ConfigError(
                    f"value {v:g} is not in the sweep of experiment {exp.name!r}; valid "
                    f"values: {', '.join(f'{x:g}' for x in valid) or 'none (no sweep)'}"
                )
        sweep = [(p, v) for p, v in exp.sweep_values(False) if v in wanted]
    over = tuple(sorted((str(k), _frozen(v)) for k, v in (overrides or {}).items()))
    for m in chosen if over else ():
        check_overrides(exp, m.slug, dict(over))
    tasks = []
    for m in chosen:
        for param, value in sweep:
            v = None if value is None else float(value)
            for preset in exp.presets:
                for s in range(n_scenes):
                    for r in range(runs):
                        tasks.append(Task(exp.name, m.slug, preset, param, v, s, r, seed, quick,
                                          over))
    return tasks


def _value_text(value: Any) -> str:
    """An override value as a run's file name writes it: the same text for equal values
    (``100``, ``100.0`` and ``True == 1`` as numbers), a tuple as ``(a, b, c)``."""
    if isinstance(value, tuple):
        return "(" + ", ".join(_value_text(v) for v in value) + ")"
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    if isinstance(value, (bool, int)):
        return str(int(value))
    return str(value)


def _frozen(value: Any) -> Any:
    """Lists (as JSON gives them) as tuples, recursively, so that a task stays hashable."""
    if isinstance(value, (list, tuple)):
        return tuple(_frozen(v) for v in value)
    return value


def check_overrides(exp: Experiment, method: str, overrides: dict[str, Any]) -> None:
    """Check that method ``method``'s tracker accepts the parameter ``overrides``.

    Raises
    ------
    ConfigError
        Naming the method and the parameter it has not, or the tracker's own message for a
        value it rejects.
    """
    from trackers.registry import get_class as tracker_class

    m = exp.method(method)
    cls = tracker_class(m.tracker)
    fields = cls.Params.names()
    swept = exp.sweep[0][0] if exp.sweep else None
    for name in overrides:
        if name == swept:
            raise ConfigError(f"method {m.slug!r} (tracker {m.tracker!r}) cannot override the "
                              f"swept parameter {name!r}; its parameters: {', '.join(fields)}")
        if name not in fields:
            having = [x.slug for x in exp.methods
                      if name in tracker_class(x.tracker).Params.names()]  # fmt: skip
            them = "have it: name them" if len(having) > 1 else "has it: name it"
            hint = (f"; of {exp.name}'s methods only {', '.join(having)} {them}, "
                    + " ".join(f"--method {x}" for x in having) if having
                    else f"; no method of {exp.name} has it")  # fmt: skip
            raise ConfigError(f"method {m.slug!r} (tracker {m.tracker!r}) has no parameter "
                              f"{name!r}{hint}; its parameters: {', '.join(fields)}")
    params = {**m.param_dict(), **overrides}
    try:
        cls.Params(**params)
    except (TypeError, ValueError) as err:
        raise ConfigError(f"method {m.slug!r} (tracker {m.tracker!r}): {err}") from None


@functools.lru_cache(maxsize=4)
def _sequence(preset: str, seed: int, frames: int | None) -> Any:
    import scenegen

    return scenegen.generate(preset, seed=seed, frames=frames)


def _round(x: Any) -> Any:
    """Round floats (recursively) to fixed decimals; NaN and inf become None."""
    if isinstance(x, dict):
        return {str(k): _round(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_round(v) for v in x]
    if isinstance(x, np.ndarray):
        return _round(x.tolist())
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        f = float(x)
        return round(f, _DECIMALS) if np.isfinite(f) else None
    return x


def tracker_params(exp: Experiment, task: Task) -> dict[str, Any]:
    """The keyword parameters of the task's tracker (without ``rng``).

    The method's own parameters, then the swept value, then in quick mode
    ``n_particles`` capped at the experiment's ``quick_particles``, then the task's
    overrides (which win over the cap).

    Parameters
    ----------
    exp : Experiment
        The task's experiment.
    task : Task
        The run.

    Returns
    -------
    dict
        Parameter name -> value.
    """
    params = exp.method(task.method).param_dict()
    if task.param:
        params[task.param] = task.value
    if task.quick and "n_particles" in params:
        params["n_particles"] = min(int(params["n_particles"]), exp.quick_particles)
    params.update(task.overrides)  # what the user sets (--param) wins over --quick's cap
    return params


@functools.lru_cache(maxsize=64)
def scene_digest(preset: str) -> str:
    """SHA-256 (16 hex digits) of the preset's resolved config: a changed preset makes
    stored runs on it stale."""
    from scenegen import presets
    from scenegen.config import to_dict

    text = json.dumps(to_dict(presets.get(preset)), sort_keys=True, default=str)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


def run_task(task: Task) -> dict[str, Any]:
    """Run one task and return its record (JSON-ready, floats rounded).

    The record holds the task's key, seeds, tracker and parameters, and per target the
    per-frame track state, precision, recall, IoU and centre error; PF trackers add mean
    uniqueness and effective dynamics per target, SHM trackers the ordering probabilities,
    the true ordering per frame and the depth-order accuracy. Numba kernels run on one
    thread here, so results do not depend on the executor.

    Parameters
    ----------
    task : Task
        The run; its sequence is generated from its scene seed (cached per process).

    Returns
    -------
    dict
        ``key``, ``tracker``, ``params``, ``scene_seed``, ``scene_digest``,
        ``tracker_seed``, ``n_frames``, ``failure_threshold`` and ``targets`` (per target:
        ``name`` and per-frame lists of length ``n_frames``: ``state``, ``precision``,
        ``recall``, ``iou``, ``centre_error`` in px, and ``path_error`` in px when the
        sequence has a noise-free path); plus the tracker's diagnostics named above.
    """
    from scenegen.evaluation import metrics
    from scenegen.evaluation.evaluate import failure_threshold, frame_measures
    from scenegen.lab.run import run

    exp = get(task.experiment)
    frames = exp.quick_frames if task.quick else None
    seq = _sequence(task.preset, task.scene_seed(), frames)
    params = tracker_params(exp, task)
    method = exp.method(task.method)
    done = run(seq, method.tracker, params, task.tracker_seed(), single_thread=True)
    idx = done.targets
    gt = np.asarray(seq.gt.box[:, idx], dtype=np.float64)
    fm = frame_measures(np.asarray(done.result.boxes, dtype=np.float64), gt)
    present = np.all(np.isfinite(gt), axis=-1)
    names = np.asarray(seq.entities.name)[idx]
    path = getattr(seq.gt, "path_center", None)
    path_err = None
    if path is not None:
        # KAMS §3.1: accuracy against the noise-free path, not the drawn (jittered) position.
        est_c = metrics.centres(np.asarray(done.result.boxes, dtype=np.float64))
        path_err = np.linalg.norm(est_c - np.asarray(path, dtype=np.float64)[:, idx], axis=-1)
    targets = []
    for m in range(len(idx)):
        state: list[int | None] = [
            int(s) if p else None for s, p in zip(fm["state"][:, m], present[:, m], strict=True)
        ]
        targets.append(
            {
                "name": str(names[m]),
                "state": state,
                "precision": fm["precision"][:, m],
                "recall": fm["recall"][:, m],
                "iou": fm["iou"][:, m],
                "centre_error": fm["centre_error"][:, m],
            }
        )
        if path_err is not None:
            targets[-1]["path_error"] = path_err[:, m]
    record: dict[str, Any] = {
        "key": task.key(),
        "tracker": method.tracker,
        "params": params,
        "scene_seed": task.scene_seed(),
        "scene_digest": scene_digest(task.preset),
        "tracker_seed": task.tracker_seed(),
        "n_frames": int(gt.shape[0]),
        "failure_threshold": failure_threshold(gt),
        "targets": targets,
    }
    extras = done.extras
    if "uniqueness" in extras:
        record["uniqueness"] = metrics.uniqueness_percent(extras["uniqueness"])
    if "effective_dynamics" in extras:
        ed = np.asarray(extras["effective_dynamics"], dtype=np.float64)
        record["effective_dynamics"] = metrics.effective_dynamics_percent(
            ed, components=ed.ndim == 3
        )
    orderings = getattr(done.tracker, "orderings", None)
    if "order_prob" in extras and orderings is not None:
        depth = np.asarray(seq.gt.depth)[:, idx]
        record["order_prob"] = extras["order_prob"]
        record["orderings"] = np.asarray(orderings).astype(int)
        record["true_order"] = metrics.ordering_index(depth, orderings)
        # Frame 0 (the initial boxes, no estimate yet) is excluded from every measure.
        record["depth_order_accuracy"] = metrics.depth_order_accuracy(
            np.asarray(extras["order_prob"])[1:], orderings, depth[1:], gt[1:],
            min_overlap=_MIN_OVERLAP,
        )
        pairs = metrics.overlapping_pairs(gt, min_overlap=_MIN_OVERLAP)
        record["overlap"] = np.any(pairs, axis=(1, 2))
    rounded = _round(record)
    rounded["key"] = _stored_key(task)  # the run's identity, not a measure: not rounded
    return rounded


def _stored_key(task: Task) -> Any:
    """``task.key()`` as its record stores it: as JSON reads it back, floats exact (an
    override rounded to 6 decimals named another run, and reran as another one)."""
    return json.loads(json.dumps(task.key()))


def write_json_atomic(path: Path, data: Any, *, indent: int | None = None) -> None:
    """Write ``data`` as JSON (sorted keys, no NaN) to ``path`` atomically.

    Uses :func:`scenegen.io.atomic.write_json`: a temporary file in the same folder,
    flushed and renamed into place, so a killed process never leaves a half-written file.

    Parameters
    ----------
    path : pathlib.Path
        The file to write; missing parent folders are created.
    data : Any
        A JSON-serialisable value.
    indent : int, optional
        Indentation of the JSON text (None: compact).
    """
    from scenegen.io.atomic import write_json

    write_json(path, data, indent=indent, parents=True)


def load_record(path: Path, task: Task) -> dict[str, Any] | None:
    """The stored record of ``task`` at ``path``, or None if missing, damaged or stale.

    Damaged means unreadable, not matching its digest (edited), not a run record, a record
    of another run (its key names another file), or written by an older version (no
    digest, see :mod:`scenegen.lab.experiments.outputs`): the run is computed again, with
    one warning line on stderr. Stale means stored for another key (experiment, method,
    preset, value, scene, run, seed, quick), with other tracker parameters, or for another
    version of the preset's config (:func:`scene_digest`); it is computed again silently. A
    sound, fresh record that the folder's ``results.json`` (of the same seed and mode)
    lists with another digest was edited (its digest recomputed) or replaced after the
    results were computed: it is computed again, with a warning.

    Parameters
    ----------
    path : pathlib.Path
        The task's run file, ``DIR/runs/`` + :meth:`Task.filename`.
    task : Task
        The run looked for.

    Returns
    -------
    dict or None
        The stored record (without its digest), or None to compute the run.

    Raises
    ------
    ConfigError
        ``path`` is a FIFO, a device or a socket (``"PATH: is not a regular file (a
        FIFO); remove it"``): the run could not be stored there, so it is not computed.
    """
    from scenegen.errors import ConfigError, DataError
    from scenegen.io.atomic import SpecialFile
    from scenegen.io.sealed import content_digest
    from scenegen.lab.experiments.outputs import listed_digest, read_record, warn

    if not path.exists():
        return None
    try:
        data = read_record(path)
    except SpecialFile as err:  # its run could not be stored there: refused before running
        raise ConfigError(f"{err}; remove it") from None
    except DataError as err:
        warn(f"{err}; computing this run again")
        return None
    if Task(**data["key"]).filename() != path.name:
        warn(f"{path}: holds another run ({Task(**data['key']).filename()}); computing this "
             "run again")  # fmt: skip
        return None
    if data.get("key") != _stored_key(task):
        return None
    # Parameters changed since the run was stored (a new version of the experiment).
    if data.get("params") != _round(tracker_params(get(task.experiment), task)):
        return None
    if data.get("scene_digest") != scene_digest(task.preset):
        return None
    listed = listed_digest(path, task.seed, task.quick)
    if listed is not None and listed != content_digest(data):
        warn(f"{path}: is not the run its results.json was computed from (edited since); "
             "computing this run again")  # fmt: skip
        return None
    return data


def execute(
    tasks: list[Task],
    runs_dir: Path,
    *,
    jobs: int | None = None,
    scheduler: str | None = None,
    progress: bool = True,
    on_done: Callable[[Task], None] | None = None,
) -> list[dict[str, Any]]:
    """Run the tasks not yet stored under ``runs_dir`` and return every task's record.

    Inside :func:`workers` with the same ``jobs`` and ``scheduler``, the tasks run on that
    block's workers (and tasks it has already started are collected, not started again);
    otherwise on workers started for this call.

    Parameters
    ----------
    tasks : list of Task
        The runs to do (:func:`plan_tasks`).
    runs_dir : Path
        One JSON file per finished run; existing valid files are reused, not rerun.
    jobs : int or None
        Local worker processes (None: all cores; 1 runs in this process).
    scheduler : str or None
        Address of a ``dask.distributed`` scheduler; tasks then run on its workers (each
        retried up to 3 times if a worker is lost).
    progress : bool
        Show a tqdm progress bar (on stderr).
    on_done : callable, optional
        Called with each task when its record has been stored.

    Returns
    -------
    list of dict
        Records in the order of ``tasks``.

    Raises
    ------
    ConfigError
        For jobs < 1 or an unreachable scheduler.
    """
    from tqdm import tqdm

    if jobs is not None and jobs < 1:
        raise ConfigError(f"jobs must be >= 1, got {jobs}")
    runs_dir.mkdir(parents=True, exist_ok=True)
    shared = _ACTIVE[-1] if _ACTIVE and _ACTIVE[-1].serves(jobs, scheduler) else None
    records: dict[Task, dict[str, Any]] = {}
    todo = []
    for t in tasks:
        rec = None if shared and shared.started(runs_dir, t) else load_record(
            runs_dir / t.filename(), t)
        if rec is None:
            todo.append(t)
        else:
            records[t] = rec
    bar = tqdm(total=len(tasks), initial=len(records), disable=not progress, unit="run",
               desc=tasks[0].experiment if tasks else "experiment", leave=False)

    def store(t: Task, rec: dict[str, Any]) -> None:
        from scenegen.lab.experiments.outputs import write_record

        write_record(runs_dir / t.filename(), rec)
        records[t] = json.loads(json.dumps(rec, sort_keys=True))
        bar.update(1)
        if on_done is not None:
            on_done(t)

    try:
        if shared is not None:
            shared.collect(todo, runs_dir, store)
        elif todo:
            with Workers(jobs, scheduler) as own:
                own.collect(todo, runs_dir, store)
    finally:
        bar.close()
    return [records[t] for t in tasks]


BATCH = 8
"""Most tasks of one scene that a local worker runs per call (it generates the scene once)."""

# Imported by the fork server before it forks a worker, so that workers start with them.
_PRELOAD = (
    "numpy",
    "numba",
    "scenegen",
    "scenegen.lab.experiments.runner",
    "scenegen.lab.run",
    "scenegen.evaluation.evaluate",
    "scenegen.evaluation.metrics",
    "trackers",
)


def batches(tasks: list[Task], size: int = BATCH) -> list[list[Task]]:
    """``tasks`` grouped by scene (in order of first appearance), in chunks of at most
    ``size``: a worker running a chunk generates its sequence once (and keeps the last few
    in memory, so the next chunk of the same scene reuses it).

    Parameters
    ----------
    tasks : list of Task
        The tasks; a scene is (experiment, preset, scene, seed, quick).
    size : int, default BATCH
        Most tasks per chunk (>= 1).

    Returns
    -------
    list of list of Task
        The chunks, each of one scene, in the order of ``tasks`` within it.

    Raises
    ------
    ConfigError
        For ``size`` < 1.

    Examples
    --------
    >>> from scenegen.lab.experiments.definitions import get
    >>> tasks = plan_tasks(get("shm-depth"), runs=1, scenes=2, seed=0, quick=True)
    >>> [[(t.preset, t.scene) for t in b][0] for b in batches(tasks)]
    [('shm-crossing', 0), ('shm-crossing', 1), ('shm-clutter', 0), ('shm-clutter', 1)]
    """
    if size < 1:
        raise ConfigError(f"batch size must be >= 1, got {size}")
    groups: dict[tuple[Any, ...], list[Task]] = {}
    for t in tasks:
        groups.setdefault((t.experiment, t.preset, t.scene, t.seed, t.quick), []).append(t)
    return [g[i:i + size] for g in groups.values() for i in range(0, len(g), size)]


def run_batch(tasks: list[Task]) -> list[dict[str, Any]]:
    """:func:`run_task` of each task, in order (what a local worker runs per call).

    Parameters
    ----------
    tasks : list of Task
        Usually one chunk of :func:`batches`.

    Returns
    -------
    list of dict
        The records, in the order of ``tasks``.
    """
    return [run_task(t) for t in tasks]


_ACTIVE: list[Workers] = []


def workers(jobs: int | None = None, scheduler: str | None = None) -> Workers:
    """Workers that stay up for every :func:`execute` in a ``with`` block.

    ``scenegen experiment all`` starts its worker processes once (instead of once per
    experiment) and starts every experiment's tasks at once, so that the workers run the
    next experiment's tasks while this process summarises the previous one::

        with workers(jobs=2) as w:
            for tasks, runs_dir in plans:
                w.start(tasks, runs_dir)
            for tasks, runs_dir in plans:
                records = execute(tasks, runs_dir, jobs=2)   # collects what was started

    Records are the same as without the block (each task derives its seeds from its key).

    Parameters
    ----------
    jobs : int, optional
        Local worker processes (None: all cores; 1 runs in this process).
    scheduler : str, optional
        Address of a ``dask.distributed`` scheduler (connected when the block starts).

    Returns
    -------
    Workers
        To use in a ``with`` block; an :func:`execute` inside it with the same ``jobs``
        and ``scheduler`` runs on them.

    Raises
    ------
    ConfigError
        For jobs < 1 or an unreachable scheduler (when the block starts).
    """
    if jobs is not None and jobs < 1:
        raise ConfigError(f"jobs must be >= 1, got {jobs}")
    return Workers(jobs, scheduler, active=True)


class Workers:
    """A local process pool, a Dask client, or this process (``jobs`` 1), started once.

    Local workers run :data:`BATCH` tasks of one scene per call (:func:`batches`); a Dask
    client gets one task per call (retried up to 3 times if its worker is lost). Use
    :func:`workers`.

    Parameters
    ----------
    jobs : int or None
        Local worker processes (None: all cores; 1 runs in this process, as does a
        single-task collection with no pool started).
    scheduler : str or None
        Address of a ``dask.distributed`` scheduler; when given, tasks run on its workers.
    active : bool, default False
        Register the workers while the ``with`` block runs, so that :func:`execute` with
        the same settings uses them.
    """

    def __init__(self, jobs: int | None, scheduler: str | None, *, active: bool = False):
        self.jobs = jobs
        self.scheduler = scheduler
        self._n = 1 if scheduler is None and jobs == 1 else (jobs or os.cpu_count() or 1)
        self._active = active
        self._pool: Any = None
        self._client: Any = None
        self._pending: dict[tuple[Path, Task], tuple[Any, int | None]] = {}

    def serves(self, jobs: int | None, scheduler: str | None) -> bool:
        """Whether :func:`execute` with these settings runs on these workers.

        Parameters
        ----------
        jobs : int or None
            :func:`execute`'s local worker processes.
        scheduler : str or None
            :func:`execute`'s Dask scheduler address.

        Returns
        -------
        bool
            True when both equal those the workers were made with (``jobs`` None and an
            explicit count are different settings).
        """
        return (jobs, scheduler) == (self.jobs, self.scheduler)

    def __enter__(self) -> Workers:
        if self.scheduler is not None:
            self._client = connect(self.scheduler)
        if self._active:
            _ACTIVE.append(self)
        return self

    def __exit__(self, kind: Any, *exc: Any) -> None:
        if self._active:
            _ACTIVE.remove(self)
        for fut, _ in self._pending.values():
            fut.cancel()
        self._pending.clear()
        if self._pool is not None:
            # After Ctrl-C the running batches stop at once (their runs are not stored yet).
            self._pool.close(interrupt=kind is not None and issubclass(kind, KeyboardInterrupt))
            self._pool = None
        if self._client is not None:
            self._client.close()
            self._client = None

    def started(self, runs_dir: Path, task: Task) -> bool:
        """Whether ``task`` (stored under ``runs_dir``) was started and not yet collected.

        Parameters
        ----------
        runs_dir : pathlib.Path
            The experiment's ``runs/`` folder the task's record goes to.
        task : Task
            The run.

        Returns
        -------
        bool
            True while it is pending on these workers.
        """
        return (runs_dir, task) in self._pending

    def start(self, tasks: list[Task], runs_dir: Path) -> None:
        """Start the tasks not yet stored under ``runs_dir`` (nor started); their records
        are stored by the :func:`execute` that collects them. In this process (``jobs``
        1) nothing starts early: the tasks run when collected.

        Parameters
        ----------
        tasks : list of Task
            The runs to start; those with a sound stored record (:func:`load_record`) or
            already started are skipped.
        runs_dir : pathlib.Path
            The experiment's ``runs/`` folder their records go to.
        """
        todo = [t for t in tasks if not self.started(runs_dir, t)
                and load_record(runs_dir / t.filename(), t) is None]
        if self._client is not None or self._n > 1:
            self._submit(todo, runs_dir)

    def _submit(self, todo: list[Task], runs_dir: Path) -> None:
        if self._client is not None:
            for t in (t for b in batches(todo) for t in b):  # scene by scene
                fut = self._client.submit(
                    run_task, t, key=f"scenegen-{t.experiment}-{t.filename()}", retries=3,
                    pure=False,
                )
                self._pending[runs_dir, t] = (fut, None)
            return
        if self._pool is None:
            # forkserver: never fork a parent whose numba threads may already be running;
            # the server imports the heavy modules once, and every worker forks from it.
            self._pool = LocalPool(self._n, preload=["__main__", *_PRELOAD])
        for b in batches(todo):
            first = b[0]
            said = (f"running {len(b)} run{'s' if len(b) > 1 else ''} of {first.experiment} on "
                    f"{first.preset} scene {first.scene} (from {first.filename()})")  # fmt: skip
            fut = self._pool.submit(run_batch, b, said)
            for i, t in enumerate(b):
                self._pending[runs_dir, t] = (fut, i)

    def collect(
        self, todo: list[Task], runs_dir: Path, store: Callable[[Task, dict[str, Any]], None]
    ) -> None:
        """Run (or wait for) every task of ``todo`` and ``store`` each record as it
        arrives.

        With no pool or client started and one worker (or fewer than two tasks), the
        tasks run here, in order; otherwise those not yet started are started first.

        Parameters
        ----------
        todo : list of Task
            The runs to collect (stored records are not looked for: see :meth:`start`).
        runs_dir : pathlib.Path
            The experiment's ``runs/`` folder their records go to.
        store : callable
            Called as ``store(task, record)`` with each task and its record
            (:func:`run_task`), in order of completion.

        Raises
        ------
        ConfigError
            A local worker process died (out of memory, a crash), saying how and, when
            known, in which task; tasks still pending are cancelled. A task's own error is
            raised as is, after cancelling the pending tasks likewise.
        """
        if self._client is None and self._pool is None and (self._n == 1 or len(todo) < 2):
            for t in todo:
                store(t, run_task(t))
            return
        self._submit([t for t in todo if not self.started(runs_dir, t)], runs_dir)
        by_future: dict[Any, list[tuple[Task, int | None]]] = {}
        for t in todo:
            fut, i = self._pending[runs_dir, t]
            by_future.setdefault(fut, []).append((t, i))
        try:
            for fut in self._completed(list(by_future)):
                try:
                    out = fut.result()
                except BrokenProcessPool:  # a local worker died (out of memory, a crash)
                    raise self._pool.death() from None
                for t, i in by_future[fut]:
                    del self._pending[runs_dir, t]
                    store(t, out if i is None else out[i])
        except BaseException:
            for fut, _ in self._pending.values():
                fut.cancel()
            raise

    def _completed(self, futures: list[Any]) -> Iterable[Any]:
        if self._client is not None:
            from distributed import as_completed as dask_completed

            return dask_completed(futures, loop=self._client.loop)
        return as_completed(futures)
