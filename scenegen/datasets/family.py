"""Scenario families: a base scenario plus the parameters to vary, declared in YAML/JSON.

A family file::

    name: kams-clutter           # names the sequences: kams-clutter-00000, ...
    base: kams-a                 # a preset name, a config file (.yaml/.json) or a config mapping
    count: 200                   # sequences (default: one per grid point)
    seed: 0                      # default --seed
    set:                         # fixed overrides of the base
      n_frames: 60
    sweep:                       # grid axes: sequence i takes grid point i mod (grid size)
      clutter[0].count: [100, 300, 500, 600]
      preset: [kams-a, kams-b]   # the base itself can be an axis
      occluder:                  # a named axis that moves several fields together
        entities[standing1].appearance.size[0]: [44, 56]
        entities[standing2].appearance.size[0]: [44, 56]
    vary:                        # distributions, drawn per sequence from its own stream
      entities[0].position_noise: {uniform: [2, 14]}
      entities[0].motion.x.sigma: {loguniform: [0.1, 2]}
      clutter[0].min_size: {randint: [4, 12]}        # inclusive
      background.kind: {choice: [uniform, noise]}
      sensor_noise: {normal: [2, 0.5]}               # mean, std

Order of application: base (or the ``preset`` axis), ``set``, ``sweep``, ``vary``; the
result is validated by :func:`scenegen.config.from_dict`. Every error is a
:class:`~scenegen.errors.ConfigError` of one line naming the file and the field path.

Seeds: sequence ``i`` of a family drawn with seed ``S`` takes its parameters and its scene
seed from ``numpy.random.SeedSequence(entropy=(digest of the family, S), spawn_key=(i, ...))``.
They depend on the family's content (not its count) and ``i`` only, so a dataset is the
same whichever process makes which sequence, and its first N sequences are the same
whatever the count.
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import itertools
import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, get_args, get_origin

import numpy as np

from scenegen import presets
from scenegen.config import from_dict, load_config, load_data, relative_to, to_dict
from scenegen.datasets.paths import canonical_path, leaf_type, set_path
from scenegen.errors import ConfigError
from scenegen.render.plan import MAX_SEED

__all__ = [
    "DISTRIBUTIONS",
    "Axis",
    "Distribution",
    "Draw",
    "Family",
    "family_from_dict",
    "load_family",
]

DISTRIBUTIONS = ("uniform", "loguniform", "normal", "randint", "choice")
"""Distribution kinds a ``vary`` entry may use."""

_KEYS = ("name", "description", "base", "count", "seed", "set", "sweep", "vary")
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]{0,63}$")
_REAL_KINDS = ("uniform", "loguniform", "normal")


def _json(value: Any) -> str:
    return json.dumps(value, sort_keys=True, separators=(",", ":"))


@dataclass(frozen=True)
class Axis:
    """One grid axis: one field path (or ``preset``), or several moved together.

    Attributes
    ----------
    name : str
        The key in ``sweep`` (the path itself for a one-field axis).
    paths : tuple of str
        The field paths set by the axis.
    values : tuple of tuple
        ``values[j][p]`` is the value of ``paths[p]`` at grid position ``j``.
    """

    name: str
    paths: tuple[str, ...]
    values: tuple[tuple[Any, ...], ...]

    def __len__(self) -> int:
        return len(self.values)

    @property
    def named(self) -> bool:
        """A named axis (a mapping in ``sweep``, one field or several): each sequence records
        its grid position under ``name``, besides its fields' values."""
        return self.paths != (self.name,)

    def level(self, j: int) -> Any:
        """The axis's value at grid position ``j``: that of its field, the one all its
        fields share (``occluder_width``: 36, 44, ...), or the list of its fields' values.

        Parameters
        ----------
        j : int
            Grid position along the axis, in ``0 .. len(axis) - 1``.

        Returns
        -------
        object or list
            ``values[j][0]`` when every field of the axis takes the same value there,
            else the list ``values[j]`` (one value per path, in ``paths`` order).
        """
        vals = list(self.values[j])
        return vals[0] if all(v == vals[0] for v in vals) else vals


@dataclass(frozen=True)
class Distribution:
    """A distribution over one field.

    Attributes
    ----------
    path : str
    kind : {'uniform', 'loguniform', 'normal', 'randint', 'choice'}
    args : tuple
        ``(low, high)`` for uniform, loguniform and randint (inclusive), ``(mean, std)``
        for normal, the options for choice.
    """

    path: str
    kind: str
    args: tuple[Any, ...]

    def draw(self, rng: np.random.Generator) -> Any:
        """One value, drawn from ``rng`` (floats kept to 6 significant digits).

        Parameters
        ----------
        rng : numpy.random.Generator
            The stream to draw from (one draw is taken from it).

        Returns
        -------
        float, int or object
            A float for uniform, loguniform and normal; an int in ``[low, high]``
            (inclusive) for randint; a deep copy of one of the options for choice.
        """
        if self.kind == "uniform":
            return _tidy(rng.uniform(self.args[0], self.args[1]))
        if self.kind == "loguniform":
            lo, hi = math.log(self.args[0]), math.log(self.args[1])
            return _tidy(math.exp(rng.uniform(lo, hi)))
        if self.kind == "normal":
            return _tidy(rng.normal(self.args[0], self.args[1]))
        if self.kind == "randint":
            return int(rng.integers(self.args[0], self.args[1] + 1))
        return copy.deepcopy(self.args[int(rng.integers(len(self.args)))])


def _tidy(x: float) -> float:
    return float(f"{float(x):.6g}")


@dataclass(frozen=True)
class Draw:
    """What sequence ``index`` of a family is: its name, seed, parameters and config.

    Attributes
    ----------
    index : int
    name : str
        ``FAMILY-NNNNN``; also the sequence name in its shard file.
    seed : int
        The scene seed (63-bit).
    preset : str
        The base preset ("" if the base is a config).
    params : dict
        Swept and drawn values keyed by axis name or field path (JSON-ready).
    config : dict
        The fully resolved config (``scenegen.config.to_dict``).
    """

    index: int
    name: str
    seed: int
    preset: str
    params: dict[str, Any]
    config: dict[str, Any]


@dataclass(frozen=True)
class Family:
    """A parsed, validated family (see the module docstring for the file format).

    Attributes
    ----------
    name : str
    description : str
    bases : dict of str to dict
        Base config data by preset name ("" for a config base).
    base : str
        The base's key in ``bases`` when there is no ``preset`` axis.
    overrides : tuple of (path, value)
        The ``set`` section.
    axes : tuple of Axis
    distributions : tuple of Distribution
    count : int
    seed : int
    source : str
        Where it came from (a file name or ``built-in``), for messages.
    spec : dict
        The family as given (:meth:`with_overrides` keeps it: its overrides are in
        ``overrides``).
    folder : Path or None
        Folder that relative ``base`` config files and image sources are read from
        (:func:`scenegen.config.relative_to`; the family file's, absolute).
    """

    name: str
    description: str
    bases: dict[str, dict[str, Any]]
    base: str
    overrides: tuple[tuple[str, Any], ...]
    axes: tuple[Axis, ...]
    distributions: tuple[Distribution, ...]
    count: int
    seed: int
    source: str = ""
    spec: dict[str, Any] = field(default_factory=dict, compare=False)
    folder: Path | None = field(default=None, compare=False)

    @property
    def grid_size(self) -> int:
        """Grid points (product of the axis lengths; 1 without ``sweep``)."""
        return math.prod(len(a) for a in self.axes)

    @property
    def param_names(self) -> list[str]:
        """Parameter names recorded per sequence: axis names, their paths, drawn paths."""
        out: list[str] = []
        for a in self.axes:
            for n in (a.name, *a.paths):
                if n not in out:
                    out.append(n)
        out += [d.path for d in self.distributions if d.path not in out]
        return out

    def with_overrides(self, overrides: dict[str, Any]) -> Family:
        """The family with more ``set`` entries (applied after its own); re-validated.

        Its ``spec`` stays the family as given.

        Parameters
        ----------
        overrides : dict of str to object
            Field path (``n_frames``, ``entities[0].position_noise``) -> value; an entry
            replaces a ``set`` entry of the same path.

        Returns
        -------
        Family
            A new, validated family; this one is unchanged.

        Raises
        ------
        ConfigError
            If the family sweeps or draws one of the fields (the override would be
            ignored), or the result is invalid.
        """
        for p in overrides:
            for where, q in _setters(self.axes, [d.path for d in self.distributions]):
                rel = _overlap(self.bases, self.overrides, str(p), q)
                if rel:
                    what = f"a field of {p}" if rel == "holds" else str(p)
                    raise _fail(self.source, f"{where}.{q}",
                                f"sets {what} per sequence; it cannot be overridden")  # fmt: skip
        spec = copy.deepcopy(self.spec)
        spec["set"] = {**dict(self.overrides), **overrides}
        spec.setdefault("count", self.count)
        fam = family_from_dict(spec, source=self.source, folder=self.folder)
        return dataclasses.replace(fam, spec=copy.deepcopy(self.spec))

    def digest(self) -> str:
        """SHA-256 (hex) of everything that defines the sequences except the count and seed.

        The name, bases, ``set``, ``sweep`` and ``vary`` sections are hashed; the
        description, source, spec and folder are not.

        Returns
        -------
        str
            64 lowercase hex digits.
        """
        ident = {
            "name": self.name,
            "bases": self.bases,
            "base": self.base,
            "set": [list(o) for o in self.overrides],
            "sweep": [[a.name, list(a.paths), [list(v) for v in a.values]] for a in self.axes],
            "vary": [[d.path, d.kind, list(d.args)] for d in self.distributions],
        }
        return hashlib.sha256(_json(ident).encode("utf-8")).hexdigest()

    def _entropy(self, seed: int) -> list[int]:
        words = np.frombuffer(bytes.fromhex(self.digest()), dtype="<u4").tolist()
        return [*words, int(seed)]

    def grid_point(self, index: int) -> list[int]:
        """Position along each axis of sequence ``index`` (last axis fastest).

        Parameters
        ----------
        index : int
            Sequence index (>= 0); it takes grid point ``index mod grid_size``.

        Returns
        -------
        list of int
            One position per axis, in ``axes`` order (empty without ``sweep``).
        """
        j = index % self.grid_size
        out = []
        for a in reversed(self.axes):
            out.append(j % len(a))
            j //= len(a)
        return out[::-1]

    def draw(self, index: int, seed: int | None = None, *, _entropy: Any = None) -> Draw:
        """Sequence ``index``: its parameters, seed and validated config.

        Parameters
        ----------
        index : int
            Sequence index (>= 0); any index is valid, not only those below ``count``.
        seed : int, optional
            The family seed; None: :attr:`seed`.

        Returns
        -------
        Draw
            Its name ``FAMILY-NNNNN``, scene seed, parameters and config.

        Raises
        ------
        ConfigError
            If ``index`` is not an integer >= 0, or the resulting config is invalid
            (naming the sequence, its parameters and the field).
        """
        if isinstance(index, bool) or not isinstance(index, (int, np.integer)) or index < 0:
            raise ConfigError(f"index must be an integer >= 0, got {index!r}")
        index = int(index)
        seed = self.seed if seed is None else seed
        entropy = self._entropy(seed) if _entropy is None else _entropy
        rng = np.random.default_rng(np.random.SeedSequence(entropy, spawn_key=(index, 0)))
        scene_ss = np.random.SeedSequence(entropy, spawn_key=(index, 1))
        scene_seed = int(scene_ss.generate_state(1, dtype=np.uint64)[0] >> 1)
        params: dict[str, Any] = {}
        sets: list[tuple[str, Any]] = []
        base = self.base
        for axis, j in zip(self.axes, self.grid_point(index), strict=True):
            if axis.named:
                params[axis.name] = j
            for p, v in zip(axis.paths, axis.values[j], strict=True):
                params[p] = v
                if p == "preset":
                    base = v
                else:
                    sets.append((p, v))
        for d in self.distributions:
            v = d.draw(rng)
            params[d.path] = v
            sets.append((d.path, v))
        name = f"{self.name}-{index:05d}"
        config = self._config(base, sets, name, f"sequence {index}")
        return Draw(index, name, scene_seed, base, params, config)

    def _config(
        self, base: str, sets: list[tuple[str, Any]], name: str, what: str
    ) -> dict[str, Any]:
        data = copy.deepcopy(self.bases[base])
        try:
            for p, v in self.overrides:
                set_path(data, p, copy.deepcopy(v))
            for p, v in sets:
                set_path(data, p, copy.deepcopy(v))
            data["name"] = name
            return to_dict(from_dict(data, folder=self.folder))
        except ConfigError as err:
            shown = ", ".join(f"{p}={_short(v)}" for p, v in sets)
            detail = f" ({shown})" if shown else ""
            raise ConfigError(f"{self.source}: {what}{detail}: {err}") from None

    def draws(self, count: int | None = None, seed: int | None = None) -> list[Draw]:
        """Draws of sequences ``0 .. count-1`` (default: the family's count).

        Parameters
        ----------
        count : int, optional
            Number of sequences (>= 1); None: :attr:`count`.
        seed : int, optional
            The family seed; None: :attr:`seed`.

        Returns
        -------
        list of Draw
            ``count`` draws, in index order (as :meth:`draw` gives them).

        Raises
        ------
        ConfigError
            If ``count < 1``, or a sequence's config is invalid (:meth:`draw`).
        """
        n = self.count if count is None else count
        if n < 1:
            raise ConfigError(f"count must be >= 1, got {n}")
        entropy = self._entropy(self.seed if seed is None else seed)
        return [self.draw(i, seed, _entropy=entropy) for i in range(n)]


def _short(v: Any) -> str:
    try:
        text = _json(v)
    except (TypeError, ValueError):  # not JSON, or an integer too long to print
        text = f"an integer of {v.bit_length()} bits" if isinstance(v, int) else repr(v)
    return text if len(text) <= 30 else text[:27] + "..."


# --------------------------------------------------------------------------------------
# Parsing


def _fail(source: str, where: str, msg: str) -> ConfigError:
    return ConfigError(f"{source}: {where}: {msg}" if where else f"{source}: {msg}")


def _load_base(
    value: Any, source: str, folder: Path | None, where: str = "base"
) -> tuple[str, dict[str, Any]]:
    """(preset name or "", full config data) of a ``base`` entry (errors name ``where``)."""
    if isinstance(value, str):
        if value.lower().endswith((".yaml", ".yml", ".json")):
            p = relative_to(value, folder)
            # Its relative image sources: relative to the family's folder (joined to it
            # when drawn, by _config), so the family's digest, and the seeds drawn from
            # it, do not depend on where the files are.
            rel = None if Path(value).is_absolute() else Path(value).parent
            try:
                return "", to_dict(load_config(p, folder=rel))
            except ConfigError as err:
                raise _fail(source, where, str(err)) from None
        if value not in presets.all_names():
            raise _fail(
                source, where,
                f"unknown preset {value!r}; valid presets: {', '.join(presets.all_names())}",
            )  # fmt: skip
        return value, to_dict(presets.get(value))
    if isinstance(value, dict):
        try:
            return "", to_dict(from_dict(value))
        except ConfigError as err:
            raise _fail(source, where, str(err)) from None
    raise _fail(source, where, f"must be a preset name, a config file or a mapping, got {value!r}")


def _check_path(source: str, section: str, bases: dict[str, dict[str, Any]], path: str) -> Any:
    tp = None
    for data in bases.values():
        try:
            tp = leaf_type(data, path)
        except ConfigError as err:
            raise _fail(source, f"{section}.{path}", str(err).removeprefix(f"{path}: ")) from None
    return tp


def _axis(source: str, key: Any, value: Any) -> Axis:
    where = f"sweep.{key}"
    if isinstance(value, dict):
        if not value:
            raise _fail(source, where, "a named axis needs at least one field path")
        paths, cols = [], []
        for p, vs in value.items():
            if not isinstance(vs, list):
                raise _fail(source, f"{where}.{p}", f"must be a list of values, got {_short(vs)}")
            paths.append(str(p))
            cols.append(vs)
        lengths = {len(c) for c in cols}
        if len(lengths) != 1:
            raise _fail(
                source, where, f"the lists must have the same length, got {sorted(lengths)}"
            )
        if 0 in lengths:
            raise _fail(source, where, "empty sweep: needs at least one value")
        return Axis(str(key), tuple(paths), tuple(zip(*cols, strict=True)))
    if not isinstance(value, list):
        raise _fail(source, where, f"must be a list of values, got {_short(value)}")
    if not value:
        raise _fail(source, where, "empty sweep: needs at least one value")
    return Axis(str(key), (str(key),), tuple((v,) for v in value))


def _number(source: str, where: str, v: Any) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise _fail(source, where, f"bounds must be finite numbers, got {_short(v)}")
    return v


def _distribution(source: str, path: str, spec: Any, tp: Any) -> Distribution:
    where = f"vary.{path}"
    if not isinstance(spec, dict) or len(spec) != 1:
        raise _fail(
            source, where,
            f"must be one distribution such as {{uniform: [low, high]}}, got {_short(spec)}",
        )  # fmt: skip
    kind, args = next(iter(spec.items()))
    if kind not in DISTRIBUTIONS:
        raise _fail(
            source, where, f"unknown distribution {kind!r}; valid: {', '.join(DISTRIBUTIONS)}"
        )
    if not isinstance(args, list):
        raise _fail(source, where, f"{kind} takes a list, got {_short(args)}")
    if kind == "choice":
        if not args:
            raise _fail(source, where, "empty choice: needs at least one option")
        return Distribution(path, kind, tuple(args))
    if len(args) != 2:
        names = "[mean, std]" if kind == "normal" else "[low, high]"
        raise _fail(source, where, f"{kind} takes {names}, got {_short(args)}")
    a, b = (_number(source, where, v) for v in args)
    is_int = tp is int
    is_real = tp is float
    if not (is_int or is_real):
        raise _fail(
            source, where,
            f"{kind} draws numbers but {path} is {_kind_name(tp)}; use choice",
        )  # fmt: skip
    if is_int and kind in _REAL_KINDS:
        raise _fail(source, where, f"{kind} draws real numbers but {path} is an integer; "
                    "use randint or choice")  # fmt: skip
    if kind == "normal":
        if b <= 0:
            raise _fail(source, where, f"normal std must be > 0, got {b}")
        return Distribution(path, kind, (float(a), float(b)))
    if kind == "randint":
        if int(a) != a or int(b) != b:
            raise _fail(source, where, f"randint bounds must be integers, got {_short(args)}")
        if b < a:
            raise _fail(source, where, f"empty range [{a}, {b}]: need low <= high")
        return Distribution(path, kind, (int(a), int(b)))
    if not a < b:
        raise _fail(source, where, f"empty range [{a}, {b}]: need low < high")
    if kind == "loguniform" and a <= 0:
        raise _fail(source, where, f"loguniform needs low > 0, got {a}")
    return Distribution(path, kind, (float(a), float(b)))


def _kind_name(tp: Any) -> str:
    if get_origin(tp) is Literal:
        return "one of " + ", ".join(map(str, get_args(tp)))
    if tp is str:
        return "a string"
    if tp is bool:
        return "true or false"
    if get_origin(tp) is tuple:
        return "a list"
    return f"a {getattr(tp, '__name__', str(tp))}"


def _setters(axes: Any, vary: list[str]) -> list[tuple[str, str]]:
    """(section, path) of every field path the sweep and vary sections set, in order."""
    out = [(f"sweep.{a.name}" if a.named else "sweep", p)
           for a in axes for p in a.paths if p != "preset"]  # fmt: skip
    return out + [("vary", p) for p in vary]


def _inside(a: str, b: str) -> bool:
    """Whether path ``a`` lies inside path ``b`` (``b`` is a prefix of it by whole
    components: ``entities[0].motion.x`` is inside ``entities[0].motion``, not
    ``clutter[10]`` inside ``clutter[1]``)."""
    return len(a) > len(b) and a.startswith(b) and a[len(b)] in ".["


def _relation(a: str, b: str) -> str:
    return "same" if a == b else "inside" if _inside(a, b) else "holds" if _inside(b, a) else ""


def _overlap(bases: dict[str, dict[str, Any]], overrides: Any, a: str, b: str) -> str:
    """How paths ``a`` and ``b`` overlap in one of the bases with ``overrides`` ((path,
    value) pairs) set: ``"same"`` field (``clutter[clutter].count`` and
    ``clutter[0].count``), ``a`` ``"inside"`` the sub-config ``b`` (``entities[0].motion.x``
    and ``entities[target].motion``), ``a`` ``"holds"`` ``b``, or ``""`` (apart)."""
    if a == b:
        return "same"
    for data in bases.values():
        if overrides:
            data = copy.deepcopy(data)
            for p, v in overrides:
                set_path(data, p, copy.deepcopy(v))
        try:
            if rel := _relation(canonical_path(data, a), canonical_path(data, b)):
                return rel
        except ConfigError:  # a path this base lacks (reported where it is checked)
            continue
    return ""


def family_from_dict(data: Any, *, source: str = "family", folder: Path | None = None) -> Family:
    """Parse and validate a family from plain data (as read from YAML/JSON).

    Parameters
    ----------
    data : dict
        The family (see the module docstring).
    source : str
        Prefix of error messages (the file name).
    folder : Path, optional
        Folder that relative ``base`` config files and image sources (in the family or
        in a base config file, whose are relative to that file) are read from; ``None``:
        the current directory.

    Returns
    -------
    Family
        The validated family (every grid point's config checked).

    Raises
    ------
    ConfigError
        One line naming ``source`` and the section and field path at fault.
    """
    if not isinstance(data, dict):
        raise _fail(source, "", f"a family must be a mapping, got {_short(data)}")
    for key in data:
        if key not in _KEYS:
            raise _fail(source, str(key), f"unknown key; valid keys: {', '.join(_KEYS)}")
    name = data.get("name")
    if not isinstance(name, str) or not _NAME.match(name):
        raise _fail(source, "name", "is required: letters, digits, '.', '_' or '-' "
                    f"(at most 64), got {name!r}")  # fmt: skip
    description = data.get("description", "")
    if not isinstance(description, str):
        raise _fail(source, "description", f"must be a string, got {_short(description)}")
    sweep = data.get("sweep") or {}
    vary = data.get("vary") or {}
    overrides = data.get("set") or {}
    for sec, val in (("sweep", sweep), ("vary", vary), ("set", overrides)):
        if not isinstance(val, dict):
            raise _fail(source, sec, f"must be a mapping of field paths, got {_short(val)}")
    axes = [_axis(source, k, v) for k, v in sweep.items()]
    preset_axes = [a for a in axes if "preset" in a.paths]
    bases: dict[str, dict[str, Any]] = {}
    base = ""
    if preset_axes:
        axis = preset_axes[0]
        where = "sweep.preset" if axis.name == "preset" else f"sweep.{axis.name}.preset"
        for vals in axis.values:
            p = vals[axis.paths.index("preset")]
            if not isinstance(p, str):
                raise _fail(source, where, f"values must be preset names, got {_short(p)}")
            if p not in presets.all_names():  # not a config file either: names only
                raise _fail(source, where, f"unknown preset {p!r}; valid presets: "
                            f"{', '.join(presets.all_names())}")  # fmt: skip
            key, cfg = _load_base(p, source, folder, where)
            bases[key] = cfg
        if len(preset_axes) > 1:
            raise _fail(source, "sweep", "only one axis may sweep the preset")
        if "base" in data:
            raise _fail(source, "base", "give either base or a preset axis in sweep, not both")
    else:
        if "base" not in data:
            raise _fail(source, "base", "is required (a preset name, a config file or a mapping)")
        base, bases[base] = _load_base(data["base"], source, folder)
    # Overrides apply first: later paths are checked against the base with them set.
    checked: dict[str, dict[str, Any]] = {}
    for key, cfg in bases.items():
        cfg = copy.deepcopy(cfg)
        for p, v in overrides.items():
            try:
                set_path(cfg, str(p), copy.deepcopy(v))
            except ConfigError as err:
                raise _fail(source, f"set.{p}", str(err).removeprefix(f"{p}: ")) from None
        checked[key] = cfg
    for a in axes:
        for p in a.paths:
            if p != "preset":
                _check_path(source, f"sweep.{a.name}" if a.named else "sweep", checked, p)
    dists = []
    for p, spec in vary.items():
        if p == "preset":
            raise _fail(source, "vary.preset", "sweep the preset instead (sweep: {preset: [...]})")
        tp = _check_path(source, "vary", checked, str(p))
        dists.append(_distribution(source, str(p), spec, tp))
    setters = _setters(axes, [str(p) for p in vary])
    for k, (where, p) in enumerate(setters):
        for other, q in setters[:k]:
            rel = _overlap(checked, (), p, q)
            if rel:
                how = {"same": "", "inside": ", which holds it", "holds": ", a field inside it"}
                raise _fail(source, f"{where}.{p}", "set by two axes or distributions "
                            f"(also by {other}.{q}{how[rel]})")  # fmt: skip
    fam = Family(
        name=name,
        description=description,
        bases=bases,
        base=base,
        overrides=tuple((str(k), v) for k, v in overrides.items()),
        axes=tuple(axes),
        distributions=tuple(dists),
        count=1,
        seed=0,
        source=source,
        spec=copy.deepcopy(data),
        folder=folder,
    )
    grid = fam.grid_size
    count = data.get("count", grid)
    if isinstance(count, bool) or not isinstance(count, int) or count < 1:
        raise _fail(source, "count", f"must be an integer >= 1, got {count!r}")
    seed = data.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= MAX_SEED:
        raise _fail(source, "seed", f"must be an integer in [0, 2**64 - 1], got {_short(seed)}")
    fam = dataclasses.replace(fam, count=count, seed=seed)
    # Every grid point with the distributions at their base values must be a valid config.
    for point in itertools.product(*(range(len(a)) for a in axes)):
        sets, b = [], base
        for a, j in zip(axes, point, strict=True):
            for p, v in zip(a.paths, a.values[j], strict=True):
                if p == "preset":
                    b = v
                else:
                    sets.append((p, v))
        try:
            fam._config(b, sets, f"{name}-check", "sweep")
        except ConfigError:
            fam._config(b, [], f"{name}-check", "set")  # the set section's own error first
            raise
    return fam


def load_family(path: str | Path) -> Family:
    """Read a family file (``.yaml``, ``.yml`` or ``.json``) and validate it.

    It is read as a scenario config is (:func:`scenegen.config.load_data`: UTF-8, at most
    :data:`~scenegen.config.MAX_CONFIG_BYTES`, YAML aliases bounded, duplicate keys
    refused).

    Parameters
    ----------
    path : str or Path
        The family file; relative ``base`` files and image sources in it are relative to
        its folder.

    Returns
    -------
    Family
        The validated family.

    Raises
    ------
    ConfigError
        If the file cannot be read or parsed, or the family is invalid (one line naming
        the file and the field path).
    """
    p = Path(path)
    data = load_data(p, "family")
    return family_from_dict(data, source=str(p), folder=p.absolute().parent)
