"""Fixture verification and regeneration: runs every tracker on the committed fixtures.

The fixtures themselves (definitions, digests, the registry) are defined in
:mod:`scenegen.testing.fixtures`; this module is the part that needs :mod:`trackers`, so
it lives in the lab. ``scenegen fixtures verify`` and ``scenegen fixtures regen`` call it.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from scenegen.config import from_dict, to_dict
from scenegen.datasets.build import make_output_folder
from scenegen.errors import ConfigError, DataError
from scenegen.lab.run import run_tracker
from scenegen.testing.compare import load_expected
from scenegen.testing.fixtures import (
    EXPECTED_ATOL,
    FAST_PARTICLES,
    SCHEMA,
    TRACKER_SEED,
    FixtureDef,
    compare_boxes,
    default_dir,
    definitions,
    digest_array,
    digests,
    load_registry,
    select_names,
)

__all__ = ["EXPECTED_ATOL", "regen", "tracker_params", "verify"]


def tracker_params(name: str) -> dict[str, Any]:
    """The parameters fixtures run tracker ``name`` with: few particles where it has any.

    Parameters
    ----------
    name : str
        A registered tracker name.

    Returns
    -------
    dict
        ``{"n_particles": FAST_PARTICLES}`` (32) for a tracker with that parameter, else
        ``{}``.

    Raises
    ------
    ValueError
        For an unknown tracker name (from :func:`trackers.registry.parameters`).
    """
    from trackers.registry import parameters

    return {"n_particles": FAST_PARTICLES} if "n_particles" in parameters(name) else {}


def _run(seq: Any, tracker: str, params: dict[str, Any], seed: int) -> NDArray[np.float32]:
    return np.asarray(run_tracker(seq, tracker, params, seed).boxes, dtype=np.float32)


def _error_line(err: BaseException) -> str:
    text = str(err).strip().splitlines()
    return f"{type(err).__name__}: {text[0] if text else ''}"


def _differing(a: dict[str, Any], b: dict[str, Any]) -> list[str]:
    """The keys whose values differ between two digest tables (missing counts)."""
    return sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k))


def verify(
    folder: str | Path | None = None,
    *,
    fixtures: Iterable[str] | None = None,
    tracker_names: Iterable[str] | None = None,
    progress: Callable[[str], None] | None = None,
) -> list[str]:
    """Check the committed fixtures; returns one line per mismatch (empty: all good).

    For each fixture: its definition matches the registry (config, seed); regenerating
    it gives the registered digests; the file holds them; and each tracker still gives
    its expected boxes within :data:`EXPECTED_ATOL` pixels.

    Parameters
    ----------
    folder : str or Path, optional
        Default :func:`default_dir`.
    fixtures, tracker_names : iterable of str, optional
        Restrict the check (default: every fixture, every tracker in ``trackers.names()``).
    progress : callable, optional
        Called with a short label before each fixture and tracker run.

    Returns
    -------
    list of str
        One line per mismatch, naming the fixture (and tracker); empty when every
        fixture is sound.

    Raises
    ------
    DataError
        If the registry is missing or unreadable.
    ConfigError
        For an unknown fixture or tracker name.
    """
    import trackers

    root = default_dir() if folder is None else Path(folder)
    reg = load_registry(root, missing_ok=False)
    defs = definitions()
    names = select_names(fixtures, "fixture", defs)
    tnames = select_names(tracker_names, "tracker", trackers.names())
    entries = reg.get("fixtures", {})
    if not isinstance(entries, dict):
        raise DataError(f"{root / 'registry.json'}: 'fixtures' is not a mapping")
    problems: list[str] = []
    if fixtures is None:
        problems += [
            f"fixture {n}: in the registry but no longer defined (run `scenegen fixtures regen`)"
            for n in sorted(set(entries) - set(defs))
        ]
    for name in names:
        if progress is not None:
            progress(name)
        entry = entries.get(name)
        if entry is None:
            problems.append(f"fixture {name}: not in the registry (run `scenegen fixtures regen`)")
            continue
        try:
            seq, found = _verify_sequence(root, name, defs[name], entry)
        except (AttributeError, KeyError, TypeError, ValueError) as err:  # ConfigError too
            problems.append(f"fixture {name}: its registry entry is damaged ({_error_line(err)})")
            continue
        problems += found
        runs = entry.get("trackers", {})
        if not isinstance(runs, dict):
            problems.append(f"fixture {name}: its registry entry's trackers are damaged")
            continue
        for tname in tnames:
            if tname in runs and progress is not None:
                progress(f"{name} {tname}")
            problem = _verify_run(root, seq, tname, runs.get(tname))
            if problem is not None:
                problems.append(f"fixture {name}, tracker {tname}: {problem}")
    return problems


def _verify_sequence(
    root: Path, name: str, d: FixtureDef, entry: dict[str, Any]
) -> tuple[Any, list[str]]:
    """Regenerate fixture ``name`` from its registry entry and check definition, digests
    and file; returns the regenerated sequence and the problems found."""
    from scenegen.io import read
    from scenegen.render.plan import generate

    problems = []
    if entry.get("config") != to_dict(d.config) or entry.get("seed") != d.seed:
        problems.append(
            f"fixture {name}: its definition (config or seed) differs from the registry"
        )
    stored = entry.get("digests", {})
    seq = generate(from_dict(entry["config"]), seed=int(entry["seed"]))
    bad = _differing(stored, digests(seq))
    if bad:
        problems.append(f"fixture {name}: regenerating gives different {', '.join(bad)}")
    path = root / entry.get("file", f"{name}.h5")
    try:
        on_disk = digests(read(path))
    except DataError as err:
        problems.append(f"fixture {name}: {err}")
    else:
        bad = _differing(stored, on_disk)
        if bad:
            problems.append(f"fixture {name}: {path} holds different {', '.join(bad)}")
    return seq, problems


def _verify_run(root: Path, seq: Any, tname: str, run: dict[str, Any] | None) -> str | None:
    """What is wrong with tracker ``tname``'s run on ``seq`` against its registry entry
    ``run`` (its expected boxes, or the refusal it is expected to raise), or None."""
    if run is None:
        return "no expected output (run `scenegen fixtures regen`)"
    refusal = run.get("raises")
    exp_path = root / run.get("expected", "")
    if refusal is None and not exp_path.is_file():
        return f"{exp_path} is missing"
    if not isinstance(run, dict) or "params" not in run or "seed" not in run:
        return "its registry entry is damaged (run `scenegen fixtures regen`)"
    try:
        boxes = _run(seq, tname, run["params"], int(run["seed"]))
    except Exception as err:  # any tracker failure is a mismatch to report
        if refusal is None or _error_line(err) != refusal:
            return f"raised {_error_line(err)}" + (f" (expected {refusal})" if refusal else "")
        return None
    if refusal is not None:
        return f"expected {refusal}, ran"
    expected = load_expected(exp_path)
    if expected is None:
        return f"{exp_path} is not a readable .npy file (run `scenegen fixtures regen`)"
    diff = compare_boxes(boxes, expected)
    return None if diff is None else f"boxes {diff}"


def regen(
    folder: str | Path | None = None,
    *,
    fixtures: Iterable[str] | None = None,
    tracker_names: Iterable[str] | None = None,
    progress: Callable[[str], None] | None = None,
) -> tuple[list[str], list[str]]:
    """Rewrite fixtures, expected outputs and the registry; report what changed.

    Files are rewritten only when their contents change (HDF5 files carry timestamps, so
    an unchanged fixture keeps its file). Fixtures no longer defined are removed when all
    fixtures are regenerated (their file and the expected outputs regen wrote; other
    files a user stored under ``expected/<name>/`` are kept and reported).

    Parameters
    ----------
    folder : str or Path, optional
        Default :func:`default_dir`; created if missing.
    fixtures, tracker_names : iterable of str, optional
        Restrict the work (others keep their registry entries).
    progress : callable, optional
        Called with a short label before each fixture and tracker run.

    Returns
    -------
    changes : list of str
        One line per change (empty: nothing changed).
    errors : list of str
        One line per tracker that raised (its expectation is left out of the registry).
    """
    import trackers

    root = default_dir() if folder is None else Path(folder)
    defs = definitions()
    names = select_names(fixtures, "fixture", defs)
    tnames = select_names(tracker_names, "tracker", trackers.names())
    make_output_folder(root)  # only once the names are known good: no empty folder left
    reg = load_registry(root, missing_ok=True)
    held = reg.get("fixtures", {})
    # A damaged registry is rebuilt: its entries are only what the files are checked by.
    entries: dict[str, Any] = {
        n: e for n, e in (held.items() if isinstance(held, dict) else ()) if isinstance(e, dict)
    }
    changes: list[str] = []
    errors: list[str] = []
    if fixtures is None:
        changes += _remove_undefined(root, entries, defs)
    for name in names:
        d = defs[name]
        if progress is not None:
            progress(name)
        old_entry = entries.get(name, {})
        seq, new, change = _regen_sequence(root, d, old_entry.get("digests", {}))
        changes += [change] if change else []
        held_runs = old_entry.get("trackers", {})
        runs: dict[str, Any] = {
            t: r for t, r in (held_runs.items() if isinstance(held_runs, dict) else ())
            if isinstance(r, dict)
        }  # fmt: skip
        for tname in tnames:
            if progress is not None:
                progress(f"{name} {tname}")
            run, change, error = _regen_run(root, name, seq, tname, runs.get(tname, {}))
            if run is None:
                runs.pop(tname, None)
            else:
                runs[tname] = run
            changes += [f"fixture {name}, tracker {tname}: {change}"] if change else []
            errors += [f"fixture {name}, tracker {tname}: {error}"] if error else []
        entries[name] = {
            "file": f"{name}.h5",
            "description": d.description,
            "preset": d.preset,
            "seed": d.seed,
            "config": to_dict(d.config),
            "digests": new,
            "trackers": dict(sorted(runs.items())),
        }
    _write_registry(root, {n: entries[n] for n in defs if n in entries})
    if root.resolve() == default_dir().resolve():
        # The repository's fixtures are the built-in ones: ship their digests.
        from scenegen.testing.builtin import write_digests

        if write_digests({n: entries[n] for n in defs if n in entries}):
            changes.append("scenegen/testing/builtin_digests.json: rewritten")
    return changes, errors


def _remove_undefined(root: Path, entries: dict[str, Any], defs: dict[str, Any]) -> list[str]:
    """Remove (from ``entries`` and disk) the fixtures no longer defined; one line each."""
    changes = []
    for gone in sorted(set(entries) - set(defs)):
        old = entries.pop(gone)
        (root / old.get("file", f"{gone}.h5")).unlink(missing_ok=True)
        kept = _remove_expected(root / "expected" / gone, old.get("trackers"))
        note = f"; kept expected/{gone}/ ({kept} file(s) regen did not write)" if kept else ""
        changes.append(f"fixture {gone}: removed{note}")
    return changes


def _remove_expected(folder: Path, runs: Any) -> int:
    """Remove from ``folder`` the expected outputs regen writes (``<tracker>.npy`` of the
    registry's runs), then the folder if it is empty. Anything else a user stored there
    is kept; returns how many entries were kept."""
    if not folder.is_dir() or folder.is_symlink():
        return 0
    names = set(runs) if isinstance(runs, dict) else set()
    for tname in names:
        path = folder / f"{tname}.npy"
        if isinstance(tname, str) and path.parent == folder and path.is_file():
            path.unlink()
    kept = sum(1 for _ in folder.iterdir())
    if not kept:
        folder.rmdir()
    return kept


def _regen_sequence(
    root: Path, d: FixtureDef, old: dict[str, str]
) -> tuple[Any, dict[str, str], str | None]:
    """Generate fixture ``d``; write its file if its digests differ from ``old`` or it is
    missing. Returns the sequence, its digests and the change line (None: unchanged)."""
    from scenegen.io import read, write
    from scenegen.render.plan import generate

    seq = generate(d.config, seed=d.seed)
    new = digests(seq)
    path = root / f"{d.name}.h5"
    damaged = False
    if old == new and path.exists():
        try:  # the file itself, not only the registry: a damaged file is rewritten
            if digests(read(path)) == new:
                return seq, new, None
        except DataError:
            pass
        damaged = True
    write(path, seq, compression="gzip")
    if not old:
        return seq, new, f"fixture {d.name}: new"
    if damaged:
        return seq, new, f"fixture {d.name}: rewritten (its file was damaged or edited)"
    bad = _differing(old, new)
    return seq, new, f"fixture {d.name}: rewritten ({', '.join(bad) or 'file missing'})"


def _regen_run(
    root: Path, name: str, seq: Any, tname: str, old: dict[str, Any]
) -> tuple[dict[str, Any] | None, str | None, str | None]:
    """Run tracker ``tname`` on fixture ``name``; rewrite its expected boxes if they
    changed. Returns the registry entry of the run (None when the tracker failed), the
    change (None: unchanged) and the error (None: it ran or refused as documented)."""
    from scenegen.io.atomic import write_npy

    params = tracker_params(tname)
    rel = f"expected/{name}/{tname}.npy"
    exp_path = root / rel
    try:
        boxes = _run(seq, tname, params, TRACKER_SEED)
    except ConfigError as err:
        # A documented refusal (e.g. too many targets for exhaustive orderings) is the
        # expected outcome, and verify checks that it stays the same.
        refusal = _error_line(err)
        change = f"refuses: {refusal}" if old.get("raises") != refusal else None
        exp_path.unlink(missing_ok=True)
        return {"params": params, "seed": TRACKER_SEED, "raises": refusal}, change, None
    except Exception as err:  # reported; the other trackers still get written
        return None, None, f"raised {_error_line(err)}"
    previous = load_expected(exp_path) if exp_path.exists() else None  # damaged: rewritten
    change = None
    if previous is None or not np.array_equal(previous, boxes, equal_nan=True):
        write_npy(exp_path, boxes, parents=True)
        if previous is None:
            change = "new expected output"
        else:
            change = f"boxes {compare_boxes(boxes, previous) or 'changed within tolerance'}"
    run = {"params": params, "seed": TRACKER_SEED, "expected": rel, "sha256": digest_array(boxes)}
    return run, change, None


def _write_registry(root: Path, entries: dict[str, Any]) -> None:
    """Write ``registry.json`` (only if its text changes)."""
    from scenegen import __version__
    from scenegen.io.atomic import write_text

    out = {
        "schema": SCHEMA,
        "generator_version": __version__,
        "tolerance": {"atol": EXPECTED_ATOL, "rtol": 0.0},
        "fixtures": entries,
    }
    text = json.dumps(out, indent=1, sort_keys=False) + "\n"
    reg_path = root / "registry.json"
    if not reg_path.exists() or reg_path.read_text(encoding="utf-8") != text:
        write_text(reg_path, text)
