"""pytest plugin (entry point ``pytest11: scenegen``): generated scenes as fixtures.

Fixtures
--------
scenegen_sequence
    A factory ``scenegen_sequence(preset_or_config, seed=0, frames=None) -> Sequence``.
    Sequences are cached on disk across the session (and across sessions, in pytest's
    cache folder) keyed by the generator version, the resolved config and the seed.
scenegen_fixture
    A factory ``scenegen_fixture(name) -> Sequence`` reading a committed regression fixture
    ``<fixtures dir>/<name>.h5`` (``--scenegen-fixtures``, default ``<rootdir>/fixtures``).
scenegen_expect
    ``scenegen_expect(key, array, atol=0.0, rtol=0.0)`` compares ``array`` with the stored
    expectation ``<fixtures dir>/expected/<key>.npy`` under the stated tolerances; with
    ``--scenegen-regen`` it (re)writes the expectation instead.

Markers
-------
scenegen
    The test uses generated scenes (select with ``-m scenegen``).
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest

__all__ = ["assert_close_to_expected", "cache_key"]


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("scenegen", "scenegen generated scenes")
    group.addoption(
        "--scenegen-regen",
        action="store_true",
        default=False,
        help="rewrite stored tracker expectations instead of comparing with them",
    )
    group.addoption(
        "--scenegen-fixtures",
        default=None,
        help="folder of committed regression fixtures (default: <rootdir>/fixtures)",
    )


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "scenegen: the test uses scenegen-generated scenes")


def cache_key(config: Any, seed: int, frames: int | None = None) -> str:
    """Stable key of (generator version, resolved config, seed, frame override)."""
    from scenegen import __version__
    from scenegen.config import to_dict

    doc = json.dumps(
        {"v": __version__, "config": to_dict(config), "seed": int(seed), "frames": frames},
        sort_keys=True,
    )
    return hashlib.sha256(doc.encode()).hexdigest()[:20]


def _fixtures_dir(config: pytest.Config) -> Path:
    opt = config.getoption("--scenegen-fixtures")
    return Path(opt) if opt else Path(config.rootpath) / "fixtures"


@pytest.fixture(scope="session")
def scenegen_sequence(request: pytest.FixtureRequest) -> Callable[..., Any]:
    """Factory: ``(preset name | SceneConfig | dict, seed=0, frames=None) -> Sequence``."""
    from scenegen.generator import _resolve, generate
    from scenegen.io import read, write

    cache = request.config.cache
    folder = Path(cache.mkdir("scenegen")) if cache is not None else None
    memo: dict[str, Any] = {}

    def factory(source: Any, seed: int = 0, frames: int | None = None) -> Any:
        cfg, _ = _resolve(source)
        if frames is not None:
            cfg = replace(cfg, n_frames=int(frames))
        key = cache_key(cfg, seed)
        if key in memo:
            return memo[key]
        path = folder / f"{key}.h5" if folder is not None else None
        if path is not None and path.exists():
            seq = read(path)
        else:
            seq = generate(source, seed=seed, frames=frames)
            if path is not None:
                write(path, seq, compression="lzf")
        memo[key] = seq
        return seq

    return factory


@pytest.fixture(scope="session")
def scenegen_fixture(request: pytest.FixtureRequest) -> Callable[[str], Any]:
    """Factory: ``(name) -> Sequence`` of the committed fixture ``<fixtures>/<name>.h5``."""
    from scenegen.io import read

    folder = _fixtures_dir(request.config)

    def factory(name: str) -> Any:
        path = folder / f"{name}.h5"
        if not path.exists():
            known = sorted(p.stem for p in folder.glob("*.h5")) if folder.is_dir() else []
            raise FileNotFoundError(
                f"no scenegen fixture {name!r} in {folder}; known: {', '.join(known) or 'none'}"
            )
        return read(path)

    return factory


def assert_close_to_expected(
    path: Path, actual: Any, *, atol: float = 0.0, rtol: float = 0.0, regen: bool = False
) -> None:
    """Compare ``actual`` with the array stored at ``path`` (``.npy``); NaNs must match.

    With ``regen`` the file is (re)written instead. Raises ``AssertionError`` naming the
    first differing element and the tolerance.
    """
    arr = np.asarray(actual)
    if regen:
        path.parent.mkdir(parents=True, exist_ok=True)
        np.save(path, arr)
        return
    if not path.exists():
        raise AssertionError(f"no stored expectation {path}; run pytest with --scenegen-regen")
    expected = np.load(path)
    if expected.shape != arr.shape:
        raise AssertionError(f"{path.name}: shape {arr.shape}, expected {expected.shape}")
    nan_a, nan_e = np.isnan(arr), np.isnan(expected)
    if np.any(nan_a != nan_e):
        idx = tuple(int(i) for i in np.argwhere(nan_a != nan_e)[0])
        raise AssertionError(f"{path.name}: NaN pattern differs first at {idx}")
    ok = np.isclose(arr, expected, atol=atol, rtol=rtol) | nan_a
    if not ok.all():
        idx = tuple(int(i) for i in np.argwhere(~ok)[0])
        raise AssertionError(
            f"{path.name}: {int((~ok).sum())} values differ beyond atol={atol}, rtol={rtol}; "
            f"first at {idx}: got {arr[idx]!r}, expected {expected[idx]!r}"
        )


@pytest.fixture
def scenegen_expect(request: pytest.FixtureRequest) -> Callable[..., None]:
    """``scenegen_expect(key, array, atol=0.0, rtol=0.0)``: compare with (or, under
    ``--scenegen-regen``, rewrite) ``<fixtures>/expected/<key>.npy``."""
    folder = _fixtures_dir(request.config) / "expected"
    regen = bool(request.config.getoption("--scenegen-regen"))

    def check(key: str, actual: Any, atol: float = 0.0, rtol: float = 0.0) -> None:
        assert_close_to_expected(folder / f"{key}.npy", actual, atol=atol, rtol=rtol, regen=regen)

    return check
