"""Fixture verification and regeneration: runs every tracker on the committed fixtures.

The fixtures themselves (definitions, digests, the registry) are defined in
:mod:`scenegen.testing.fixtures`; this module is the part that needs :mod:`trackers`, so
it lives in the lab. ``scenegen fixtures verify`` and ``scenegen fixtures regen`` call it.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from scenegen.config import from_dict, to_dict
from scenegen.errors import ConfigError, DataError
from scenegen.lab.run import run_tracker
from scenegen.testing.fixtures import (
    EXPECTED_ATOL,
    FAST_PARTICLES,
    SCHEMA,
    TRACKER_SEED,
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
    """The parameters fixtures run tracker ``name`` with: few particles where it has any."""
    from trackers.registry import parameters

    return {"n_particles": FAST_PARTICLES} if "n_particles" in parameters(name) else {}


def _run(seq: Any, tracker: str, params: dict[str, Any], seed: int) -> NDArray[np.float32]:
    return np.asarray(run_tracker(seq, tracker, params, seed).boxes, dtype=np.float32)


def _error_line(err: BaseException) -> str:
    text = str(err).strip().splitlines()
    return f"{type(err).__name__}: {text[0] if text else ''}"


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

    Raises
    ------
    DataError
        If the registry is missing or unreadable.
    ConfigError
        For an unknown fixture or tracker name.
    """
    import trackers
    from scenegen.io import read
    from scenegen.render.plan import generate

    root = default_dir() if folder is None else Path(folder)
    reg = load_registry(root, missing_ok=False)
    defs = definitions()
    names = select_names(fixtures, "fixture", defs)
    tnames = select_names(tracker_names, "tracker", trackers.names())
    entries = reg.get("fixtures", {})
    problems: list[str] = []
    if fixtures is None:
        problems += [
            f"fixture {n}: in the registry but no longer defined (run `scenegen fixtures regen`)"
            for n in sorted(set(entries) - set(defs))
        ]
    for name in names:
        d = defs[name]
        if progress is not None:
            progress(name)
        entry = entries.get(name)
        if entry is None:
            problems.append(f"fixture {name}: not in the registry (run `scenegen fixtures regen`)")
            continue
        if entry.get("config") != to_dict(d.config) or entry.get("seed") != d.seed:
            problems.append(
                f"fixture {name}: its definition (config or seed) differs from the registry"
            )
        stored = entry.get("digests", {})
        seq = generate(from_dict(entry["config"]), seed=int(entry["seed"]))
        regenerated = digests(seq)
        bad = sorted(
            k for k in set(stored) | set(regenerated) if stored.get(k) != regenerated.get(k)
        )
        if bad:
            problems.append(f"fixture {name}: regenerating gives different {', '.join(bad)}")
        path = root / entry.get("file", f"{name}.h5")
        try:
            on_disk = digests(read(path))
        except DataError as err:
            problems.append(f"fixture {name}: {err}")
        else:
            bad = sorted(k for k in set(stored) | set(on_disk) if stored.get(k) != on_disk.get(k))
            if bad:
                problems.append(f"fixture {name}: {path} holds different {', '.join(bad)}")
        runs = entry.get("trackers", {})
        for tname in tnames:
            run = runs.get(tname)
            if run is None:
                problems.append(
                    f"fixture {name}, tracker {tname}: no expected output "
                    "(run `scenegen fixtures regen`)"
                )
                continue
            if progress is not None:
                progress(f"{name} {tname}")
            refusal = run.get("raises")
            exp_path = root / run.get("expected", "")
            if refusal is None and not exp_path.is_file():
                problems.append(f"fixture {name}, tracker {tname}: {exp_path} is missing")
                continue
            try:
                boxes = _run(seq, tname, run["params"], int(run["seed"]))
            except Exception as err:  # any tracker failure is a mismatch to report
                if refusal is None or _error_line(err) != refusal:
                    problems.append(
                        f"fixture {name}, tracker {tname}: raised {_error_line(err)}"
                        + (f" (expected {refusal})" if refusal else "")
                    )
                continue
            if refusal is not None:
                problems.append(f"fixture {name}, tracker {tname}: expected {refusal}, ran")
                continue
            diff = compare_boxes(boxes, np.load(exp_path))
            if diff is not None:
                problems.append(f"fixture {name}, tracker {tname}: boxes {diff}")
    return problems


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
    fixtures are regenerated.

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
    from scenegen import __version__
    from scenegen.io import write
    from scenegen.io.atomic import write_npy, write_text
    from scenegen.render.plan import generate

    root = default_dir() if folder is None else Path(folder)
    root.mkdir(parents=True, exist_ok=True)
    reg = load_registry(root, missing_ok=True)
    defs = definitions()
    names = select_names(fixtures, "fixture", defs)
    tnames = select_names(tracker_names, "tracker", trackers.names())
    entries: dict[str, Any] = dict(reg.get("fixtures", {}))
    changes: list[str] = []
    errors: list[str] = []
    if fixtures is None:
        for gone in sorted(set(entries) - set(defs)):
            old = entries.pop(gone)
            (root / old.get("file", f"{gone}.h5")).unlink(missing_ok=True)
            shutil.rmtree(root / "expected" / gone, ignore_errors=True)
            changes.append(f"fixture {gone}: removed")
    for name in names:
        d = defs[name]
        if progress is not None:
            progress(name)
        seq = generate(d.config, seed=d.seed)
        new = digests(seq)
        old_entry = entries.get(name, {})
        old = old_entry.get("digests", {})
        path = root / f"{name}.h5"
        if old != new or not path.exists():
            write(path, seq, compression="gzip")
            if not old:
                changes.append(f"fixture {name}: new")
            else:
                bad = sorted(k for k in set(old) | set(new) if old.get(k) != new.get(k))
                changes.append(f"fixture {name}: rewritten ({', '.join(bad) or 'file missing'})")
        runs: dict[str, Any] = dict(old_entry.get("trackers", {}))
        for tname in tnames:
            if progress is not None:
                progress(f"{name} {tname}")
            params = tracker_params(tname)
            rel = f"expected/{name}/{tname}.npy"
            try:
                boxes = _run(seq, tname, params, TRACKER_SEED)
            except ConfigError as err:
                # A documented refusal (e.g. too many targets for exhaustive orderings) is
                # the expected outcome, and verify checks that it stays the same.
                refusal = _error_line(err)
                if runs.get(tname, {}).get("raises") != refusal:
                    changes.append(f"fixture {name}, tracker {tname}: refuses: {refusal}")
                (root / rel).unlink(missing_ok=True)
                runs[tname] = {"params": params, "seed": TRACKER_SEED, "raises": refusal}
                continue
            except Exception as err:  # reported; the other trackers still get written
                runs.pop(tname, None)
                errors.append(f"fixture {name}, tracker {tname}: raised {_error_line(err)}")
                continue
            exp_path = root / rel
            previous = np.load(exp_path) if exp_path.exists() else None
            if previous is None or not np.array_equal(previous, boxes, equal_nan=True):
                write_npy(exp_path, boxes, parents=True)
                if previous is None:
                    changes.append(f"fixture {name}, tracker {tname}: new expected output")
                else:
                    what = compare_boxes(boxes, previous) or "changed within tolerance"
                    changes.append(f"fixture {name}, tracker {tname}: boxes {what}")
            runs[tname] = {
                "params": params,
                "seed": TRACKER_SEED,
                "expected": rel,
                "sha256": digest_array(boxes),
            }
        entries[name] = {
            "file": path.name,
            "description": d.description,
            "preset": d.preset,
            "seed": d.seed,
            "config": to_dict(d.config),
            "digests": new,
            "trackers": dict(sorted(runs.items())),
        }
    out = {
        "schema": SCHEMA,
        "generator_version": __version__,
        "tolerance": {"atol": EXPECTED_ATOL, "rtol": 0.0},
        "fixtures": {n: entries[n] for n in defs if n in entries},
    }
    text = json.dumps(out, indent=1, sort_keys=False) + "\n"
    reg_path = root / "registry.json"
    if not reg_path.exists() or reg_path.read_text(encoding="utf-8") != text:
        write_text(reg_path, text)
    return changes, errors
