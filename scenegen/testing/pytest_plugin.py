"""pytest plugin (entry point ``pytest11: scenegen``): generated scenes as fixtures.

Installed with scenegen, it is active in every pytest run; nothing to import.

Fixtures
--------
scenegen_sequence
    Session-scoped factory ``scenegen_sequence(source, seed=0, frames=None) -> Sequence``
    with ``source`` a preset name, a :class:`~scenegen.config.SceneConfig` or a config
    dict. Sequences are cached in memory for the session and on disk across sessions (in
    pytest's cache folder, ``.pytest_cache/d/scenegen``), keyed by the generator
    fingerprint (version and source of the rendering modules), the resolved config, the
    frame count and the seed; ``pytest --cache-clear`` empties it. Being session-scoped,
    it can be used inside ``@given`` tests.
scenegen_fixture
    Session-scoped factory ``scenegen_fixture(name) -> Sequence`` reading the committed
    regression fixture ``<fixtures>/<name>.h5``. If the folder holds a ``registry.json``
    (as written by ``scenegen fixtures regen``), the arrays are checked against its
    SHA-256 digests first. A name not in the folder but built in (``one-pixel``,
    ``single-frame``, ``enter-leave``, ``full-occlusion``, ``distractor-on-target`` and
    ``<preset>-small``) is regenerated from its definition, checked against the digests
    shipped with scenegen and cached (:mod:`scenegen.testing.builtin`), so it works in
    any project.
scenegen_expect
    ``scenegen_expect(key, array, atol=None, rtol=None)`` compares ``array`` with the
    stored expectation ``<fixtures>/expected/<key>.npy``: shapes must agree, NaN must
    match NaN, and every other element must satisfy
    ``|actual - expected| <= atol + rtol * |expected|`` (defaults: the test's
    ``scenegen_tolerance`` marker, else 0 — exact). With ``--scenegen-regen`` it writes
    the expectation instead (only if it changed) and the run ends with a list of what
    was written.
scenegen_expect_distribution
    ``scenegen_expect_distribution(key, samples, z=4.0, atol=0.0)`` for stochastic
    outputs: ``samples`` (R, ...) holds one summary per run (R >= 2); the stored runs and
    the new ones must have means within ``z`` standard errors (plus ``atol``) element by
    element, so a tracker that is not reproducible run to run can be pinned without
    flaky failures (:mod:`scenegen.testing.distribution`). ``--scenegen-regen`` stores
    the runs.

Every sequence the fixtures return holds in-memory, read-only numpy arrays (they are
shared between tests).

The fixtures work under pytest-xdist: every cached or expected file is written to a
temporary name and renamed, and the list ``--scenegen-regen`` prints is gathered from the
tests' reports, so it names what every worker wrote.

``<fixtures>`` is ``--scenegen-fixtures DIR`` (relative to the folder pytest is run from,
as other command-line paths are), else the ini option ``scenegen_fixtures`` (relative to
the rootdir), else ``<rootdir>/fixtures``.

Markers
-------
scenegen
    The test uses scenegen fixtures; added automatically to every test that requests one
    of the fixtures above, so ``pytest -m scenegen`` selects them.
scenegen_tolerance(atol=0.0, rtol=0.0)
    Default tolerances of ``scenegen_expect`` in the marked test.

Examples
--------
::

    def test_kams_regression(scenegen_sequence, scenegen_expect):
        seq = scenegen_sequence("kams-a", seed=1, frames=8)
        result = trackers.track(trackers.make("kams", rng=0), seq.frames, seq.init_boxes())
        scenegen_expect("kams-a/kams", result.boxes, atol=0.01)
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable
from dataclasses import replace
from functools import lru_cache
from pathlib import Path, PurePosixPath
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray

__all__ = [
    "FIXTURE_NAMES",
    "assert_close_to_expected",
    "cache_key",
    "frozen",
    "generator_fingerprint",
]

FIXTURE_NAMES = (
    "scenegen_sequence",
    "scenegen_fixture",
    "scenegen_expect",
    "scenegen_expect_distribution",
)
# Modules whose source decides the pixels and ground truth of a generated sequence, as
# patterns under the package folder: a module added to config/ or render/ is covered.
_GENERATOR_MODULES = (
    "config/*.py",
    "io/hdf5.py",
    "io/schema.py",
    "presets.py",
    "render/*.py",
    "sequence.py",
)
# An expectation written under --scenegen-regen is recorded as a user property of its test
# (name _WROTE, value the file's path): user properties travel with the test's reports, so
# the list at the end of the run is complete under pytest-xdist too, where the tests run in
# worker processes and only the reports reach the process that prints the summary.
_WROTE = "scenegen-regen-wrote"
_SUMMARY_NAME = "scenegen-regen-summary"


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("scenegen", "scenegen generated scenes")
    group.addoption(
        "--scenegen-regen",
        action="store_true",
        default=False,
        help="write the expectations of scenegen_expect instead of comparing with them",
    )
    group.addoption(
        "--scenegen-fixtures",
        default=None,
        metavar="DIR",
        help="folder of regression fixtures and expectations (default: <rootdir>/fixtures)",
    )
    parser.addini(
        "scenegen_fixtures",
        "folder of scenegen regression fixtures, relative to the rootdir",
        default="fixtures",
    )


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers", "scenegen: the test uses scenegen fixtures (added automatically)"
    )
    config.addinivalue_line(
        "markers",
        "scenegen_tolerance(atol=0.0, rtol=0.0): default tolerances of scenegen_expect",
    )
    config.pluginmanager.register(_RegenSummary(), _SUMMARY_NAME)


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        if set(getattr(item, "fixturenames", ())) & set(FIXTURE_NAMES):
            item.add_marker(pytest.mark.scenegen)


class _RegenSummary:
    """Collects the expectations written under ``--scenegen-regen`` from the tests'
    reports and lists them at the end of the run."""

    def __init__(self) -> None:
        self.written: list[str] = []

    def pytest_runtest_logreport(self, report: pytest.TestReport) -> None:
        # The teardown report carries every property the test recorded, once.
        if report.when == "teardown":
            self.written += [str(value) for name, value in report.user_properties
                             if name == _WROTE]  # fmt: skip

    def pytest_terminal_summary(self, terminalreporter: Any) -> None:
        if not self.written:
            return
        terminalreporter.section("scenegen --scenegen-regen")
        for path in self.written:
            terminalreporter.write_line(f"wrote: {path}")


@lru_cache(maxsize=1)
def generator_fingerprint() -> str:
    """SHA-256 (hex, 16 chars) of the scenegen version and the source of the modules that
    decide a generated sequence's contents; it changes whenever the generator may."""
    import scenegen

    h = hashlib.sha256(scenegen.__version__.encode())
    folder = Path(scenegen.__file__).parent
    for path in _generator_sources(folder):
        h.update(path.relative_to(folder).as_posix().encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def _generator_sources(folder: Path) -> list[Path]:
    """The source files of ``folder`` (scenegen's package folder) that
    :func:`generator_fingerprint` hashes, in a fixed order."""
    found: list[Path] = []
    for pattern in _GENERATOR_MODULES:
        matches = sorted(folder.glob(pattern))
        if not matches:  # a renamed module must not silently leave the fingerprint
            raise FileNotFoundError(f"no generator source matches {pattern!r} in {folder}")
        found.extend(matches)
    return found


def cache_key(config: Any, seed: int, frames: int | None = None) -> str:
    """Stable key (hex, 20 chars) of (generator fingerprint, resolved config, seed, frames).

    Parameters
    ----------
    config : SceneConfig
        The resolved config (a preset already looked up).
    seed : int
    frames : int, optional
        A frame-count override applied on top of ``config``.

    Returns
    -------
    str
        The first 20 hex characters of the SHA-256 of those four, as sorted-key JSON.
    """
    from scenegen.config import to_dict

    doc = json.dumps(
        {
            "generator": generator_fingerprint(),
            "config": to_dict(config),
            "seed": int(seed),
            "frames": frames,
        },
        sort_keys=True,
    )
    return hashlib.sha256(doc.encode()).hexdigest()[:20]


def frozen(seq: Any) -> Any:
    """The sequence with in-memory, read-only frames, labels, ground truth and templates.

    Parameters
    ----------
    seq : Sequence
        Possibly with lazy (file-backed) arrays; those are read and their file closed.

    Returns
    -------
    Sequence
        A copy of ``seq`` whose arrays are read-only in-memory copies.
    """
    from scenegen.sequence import GroundTruth

    def ro(a: Any) -> NDArray[Any]:
        arr = np.array(a, copy=True)
        arr.setflags(write=False)
        return arr

    frames, labels = ro(seq.frames), ro(seq.labels)
    for lazy in (seq.frames, seq.labels):
        if hasattr(lazy, "close"):
            lazy.close()
    gt = GroundTruth(**{k: ro(v) for k, v in seq.gt.as_dict().items()})
    return replace(
        seq,
        frames=frames,
        labels=labels,
        gt=gt,
        templates={k: ro(v) for k, v in seq.templates.items()},
    )


def _fixtures_dir(config: pytest.Config) -> Path:
    opt = config.getoption("--scenegen-fixtures")
    if opt:
        return Path(opt)
    return Path(config.rootpath) / str(config.getini("scenegen_fixtures"))


@pytest.fixture(scope="session")
def scenegen_sequence(request: pytest.FixtureRequest) -> Callable[..., Any]:
    """Factory: ``(preset name | SceneConfig | dict, seed=0, frames=None) -> Sequence``."""
    from scenegen.errors import ConfigError, DataError
    from scenegen.io import read, write
    from scenegen.render.plan import _resolve, generate

    # No disk cache when pytest runs without its cache plugin (-p no:cacheprovider).
    cache = getattr(request.config, "cache", None)
    folder = Path(cache.mkdir("scenegen")) if cache is not None else None
    memo: dict[str, Any] = {}

    def factory(source: Any, seed: int = 0, frames: int | None = None) -> Any:
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
            raise ConfigError(f"seed must be a non-negative integer, got {seed!r}")
        cfg, preset = _resolve(source)
        if frames is not None:
            if isinstance(frames, bool) or not isinstance(frames, (int, np.integer)):
                raise ConfigError(f"frames must be an integer, got {frames!r}")
            if frames < 1:
                raise ConfigError(f"frames must be >= 1, got {frames}")
            cfg = replace(cfg, n_frames=int(frames))
        # The preset name is recorded in the sequence, so it is part of the key.
        key = cache_key(cfg, int(seed)) + (f"-{preset}" if preset else "")
        if key in memo:
            return memo[key]
        path = folder / f"{key}.h5" if folder is not None else None
        seq = None
        if path is not None and path.exists():
            try:
                seq = frozen(read(path))
            except DataError:
                seq = None  # a damaged cache entry is regenerated and rewritten
        if seq is None:
            seq = frozen(generate(source, seed=int(seed), frames=frames))
            if path is not None:
                write(path, seq, compression="lzf")
        memo[key] = seq
        return seq

    return factory


@pytest.fixture(scope="session")
def scenegen_fixture(request: pytest.FixtureRequest) -> Callable[[str], Any]:
    """Factory: ``(name) -> Sequence`` of the committed fixture ``<fixtures>/<name>.h5``,
    else of the built-in fixture ``name`` (:mod:`scenegen.testing.builtin`)."""
    from scenegen.io import read
    from scenegen.testing.builtin import builtin_fixture, builtin_names

    folder = _fixtures_dir(request.config)
    cache = getattr(request.config, "cache", None)
    builtin_cache = Path(cache.mkdir("scenegen")) / "fixtures" if cache is not None else None
    memo: dict[str, Any] = {}

    def factory(name: str) -> Any:
        if name in memo:
            return memo[name]
        path = folder / f"{name}.h5"
        if not path.exists():
            if name in builtin_names():
                memo[name] = frozen(builtin_fixture(name, cache=builtin_cache))
                return memo[name]
            known = sorted(p.stem for p in folder.glob("*.h5")) if folder.is_dir() else []
            known += [n for n in builtin_names() if n not in known]
            raise FileNotFoundError(
                f"no scenegen fixture {name!r} in {folder} nor built in; known: {', '.join(known)}"
            )
        seq = frozen(read(path))
        registry = folder / "registry.json"
        if registry.exists():
            _check_digests(registry, name, seq)
        memo[name] = seq
        return seq

    return factory


def _check_digests(registry: Path, name: str, seq: Any) -> None:
    from scenegen.io.atomic import SpecialFile, read_regular_text
    from scenegen.testing.fixtures import digests

    try:
        doc = json.loads(read_regular_text(registry))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, SpecialFile) as err:
        raise AssertionError(f"{registry}: not a readable JSON registry: {err}") from None
    fixtures = doc.get("fixtures", {}) if isinstance(doc, dict) else None
    if not isinstance(fixtures, dict):
        raise AssertionError(f"{registry}: not a registry (no 'fixtures' mapping)")
    entry = fixtures.get(name)
    if entry is None:
        return
    if not isinstance(entry, dict) or not isinstance(entry.get("digests", {}), dict):
        raise AssertionError(f"{registry}: the entry of fixture {name!r} is malformed")
    stored, actual = entry.get("digests", {}), digests(seq)
    bad = sorted(k for k in set(stored) | set(actual) if stored.get(k) != actual.get(k))
    if bad:
        raise AssertionError(
            f"fixture {name!r}: {', '.join(bad)} differ from the digests in {registry}; "
            "run `scenegen fixtures verify`"
        )


def assert_close_to_expected(
    path: Path, actual: Any, *, atol: float = 0.0, rtol: float = 0.0, regen: bool = False
) -> bool:
    """Compare ``actual`` with the array stored at ``path`` (``.npy``).

    Shapes must agree, NaN must match NaN, and every other element must satisfy
    ``|actual - expected| <= atol + rtol * |expected|``. With ``regen`` the file is written
    instead (atomically, and only if its contents change).

    Parameters
    ----------
    path : Path
        The ``.npy`` file.
    actual : array_like
        The new values.
    atol, rtol : float, default 0.0
        Absolute and relative tolerances, >= 0.
    regen : bool, default False
        Write ``actual`` (creating the folders) instead of comparing.

    Returns
    -------
    bool
        True if the file was written.

    Raises
    ------
    AssertionError
        Naming the file, how many elements differ, the largest difference, the first
        differing element and the tolerances; or a missing or unreadable file (run
        pytest with ``--scenegen-regen``).
    ValueError
        If a tolerance is negative.
    """
    from scenegen.io.atomic import write_npy
    from scenegen.testing.compare import difference, load_expected

    if atol < 0 or rtol < 0:
        raise ValueError(f"tolerances must be >= 0, got atol={atol}, rtol={rtol}")
    arr = np.asarray(actual)
    if regen:
        old = load_expected(path) if path.exists() else None  # a damaged file is rewritten
        if old is not None and old.dtype == arr.dtype and np.array_equal(
            old, arr, equal_nan=arr.dtype.kind in "fc"
        ):
            return False
        write_npy(path, arr, parents=True)
        return True
    if not path.exists():
        raise AssertionError(f"no stored expectation {path}; run pytest with --scenegen-regen")
    expected = load_expected(path)
    if expected is None:
        raise AssertionError(
            f"{path}: not a readable .npy file; run pytest with --scenegen-regen to rewrite it"
        )
    what = difference(arr, expected, atol=atol, rtol=rtol)
    if what is not None:
        raise AssertionError(f"{path}: {what}")
    return False


def _check_key(key: Any) -> PurePosixPath:
    if not isinstance(key, str) or not key:
        raise ValueError(f"expectation key must be a non-empty string, got {key!r}")
    p = PurePosixPath(key)
    if p.is_absolute() or any(part in ("", ".", "..") for part in p.parts) or "\\" in key:
        raise ValueError(f"expectation key {key!r} must be a relative path without '..'")
    return p


def _marker_tolerance(marker: pytest.Mark) -> tuple[float, float]:
    """``(atol, rtol)`` of a ``scenegen_tolerance(atol=0.0, rtol=0.0)`` marker, whose
    arguments bind like a function's (``scenegen_tolerance(0.5)`` is ``atol=0.5``).

    Raises
    ------
    ValueError
        One line naming the marker and the argument at fault (an unknown or extra one,
        or a value that is not a number >= 0).
    """
    import inspect

    def signature(atol: Any = 0.0, rtol: Any = 0.0) -> None:
        """The marker's arguments."""

    try:
        bound = inspect.signature(signature).bind(*marker.args, **marker.kwargs)
    except TypeError as err:
        raise ValueError(f"scenegen_tolerance marker (atol=0.0, rtol=0.0): {err}") from None
    bound.apply_defaults()
    out = []
    for name, value in bound.arguments.items():
        number = value if isinstance(value, (int, float, np.integer, np.floating)) else None
        if isinstance(value, (bool, np.bool_)) or number is None or not number >= 0:
            raise ValueError(
                f"scenegen_tolerance marker: {name} must be a number >= 0, got {value!r}"
            )
        out.append(float(number))
    return out[0], out[1]


@pytest.fixture
def scenegen_expect(request: pytest.FixtureRequest) -> Callable[..., None]:
    """``scenegen_expect(key, array, atol=None, rtol=None)``: compare with (or, under
    ``--scenegen-regen``, write) ``<fixtures>/expected/<key>.npy``."""
    folder = _fixtures_dir(request.config) / "expected"
    regen = bool(request.config.getoption("--scenegen-regen"))
    marker = request.node.get_closest_marker("scenegen_tolerance")
    default_atol, default_rtol = _marker_tolerance(marker) if marker else (0.0, 0.0)

    def check(key: str, actual: Any, atol: float | None = None, rtol: float | None = None) -> None:
        rel = _check_key(key)
        path = folder.joinpath(*rel.parent.parts) / f"{rel.name}.npy"
        if assert_close_to_expected(
            path,
            actual,
            atol=default_atol if atol is None else atol,
            rtol=default_rtol if rtol is None else rtol,
            regen=regen,
        ):
            request.node.user_properties.append((_WROTE, str(path)))

    return check


@pytest.fixture
def scenegen_expect_distribution(request: pytest.FixtureRequest) -> Callable[..., None]:
    """``scenegen_expect_distribution(key, samples, z=4.0, atol=0.0)``: compare the runs
    ``samples`` (R, ...) of a stochastic output with (or, under ``--scenegen-regen``, store
    them as) ``<fixtures>/expected/<key>.npy``
    (:func:`scenegen.testing.distribution.distribution_difference`)."""
    from scenegen.testing.distribution import DEFAULT_Z, assert_distribution_matches

    folder = _fixtures_dir(request.config) / "expected"
    regen = bool(request.config.getoption("--scenegen-regen"))

    def check(key: str, samples: Any, z: float = DEFAULT_Z, atol: float = 0.0) -> None:
        rel = _check_key(key)
        path = folder.joinpath(*rel.parent.parts) / f"{rel.name}.npy"
        if assert_distribution_matches(path, samples, z=z, atol=atol, regen=regen):
            request.node.user_properties.append((_WROTE, str(path)))

    return check
