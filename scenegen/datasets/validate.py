"""Validating a whole dataset folder: manifest, every shard file, every digest."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from scenegen.datasets.build import read_manifest, shard_name
from scenegen.errors import DataError

__all__ = ["validate_dataset"]


def validate_dataset(
    root: str | Path, *, deep: bool = False, progress: Callable[[int], None] | None = None
) -> list[str]:
    """Problems of the dataset folder ``root``, one line each (empty if valid).

    Checks that the manifest is readable and complete (one entry per index 0..count-1,
    in the shard its index belongs to), that every shard file passes
    :func:`scenegen.io.validate.check_file`, holds exactly its sequences, and that each
    sequence's seed and contents match the manifest's seed and digests; shard files the
    manifest does not list are reported too.

    Parameters
    ----------
    root : str or Path
    deep : bool
        Also generate every sequence again from its stored config and seed and compare
        with the manifest's digests (as long as making the dataset).
    progress : callable, optional
        Called with the number of shard files checked so far.
    """
    from scenegen.io import read, sequence_names
    from scenegen.io.validate import check_file
    from scenegen.testing.fixtures import digests

    p = Path(root)
    try:
        man = read_manifest(p)
    except DataError as err:
        return [str(err)]
    problems: list[str] = []
    count, size = man.get("count"), man.get("shard_size")
    if not isinstance(count, int) or not isinstance(size, int) or size < 1:
        return [f"{p / 'manifest.json'}: count and shard_size must be integers"]
    if not man.get("complete"):
        problems.append(f"{p}: incomplete dataset (the build was interrupted); rerun it")
    by_file: dict[str, list[dict]] = {}
    seen: set[int] = set()
    for e in man["sequences"]:
        i = e.get("index") if isinstance(e, dict) else None
        if not isinstance(i, int) or not 0 <= i < count or i in seen:
            problems.append(f"{p / 'manifest.json'}: bad or duplicate entry index {i!r}")
            continue
        seen.add(i)
        if e.get("file") != shard_name(i // size):
            problems.append(f"{p / 'manifest.json'}: sequence {i} listed in {e.get('file')!r}, "
                            f"expected {shard_name(i // size)!r}")  # fmt: skip
            continue
        by_file.setdefault(e["file"], []).append(e)
    missing = sorted(set(range(count)) - seen)
    if missing:
        shown = ", ".join(map(str, missing[:5])) + (" ..." if len(missing) > 5 else "")
        problems.append(f"{p}: {len(missing)} of {count} sequences not in the manifest: {shown}")
    listed = set(by_file)
    for extra in sorted(f.name for f in p.glob("shard-*.h5") if f.name not in listed):
        problems.append(f"{p / extra}: shard file not listed in the manifest")
    for n, (file, entries) in enumerate(sorted(by_file.items())):
        path = p / file
        if not path.is_file():
            problems.append(f"{path}: missing shard file ({len(entries)} sequences)")
            continue
        found = check_file(path, isolate=True)
        if found:
            problems += found
            continue
        names = [e["name"] for e in sorted(entries, key=lambda e: e["index"])]
        try:
            have = sequence_names(path)
            if have != names:
                problems.append(f"{path}: holds {have}, the manifest lists {names}")
                continue
            for e in entries:
                seq = read(path, e["name"])
                if seq.seed != e.get("seed"):
                    problems.append(
                        f"{path}: {e['name']}: seed {seq.seed}, manifest {e.get('seed')}"
                    )
                got = digests(seq)
                bad = sorted(k for k, v in (e.get("digests") or {}).items() if got.get(k) != v)
                if bad or not e.get("digests"):
                    what = ", ".join(bad) if bad else "no digests in the manifest"
                    problems.append(
                        f"{path}: {e['name']}: contents differ from the manifest: {what}"
                    )
                elif deep:
                    again = digests(_regenerate(seq))
                    off = sorted(k for k, v in e["digests"].items() if again.get(k) != v)
                    if off:
                        problems.append(
                            f"{path}: {e['name']}: generating it again from its config and "
                            f"seed gives other {', '.join(off)}"
                        )
        except DataError as err:
            problems.append(str(err))
        if progress is not None:
            progress(n + 1)
    return problems


def _regenerate(seq: Any) -> Any:
    """The sequence generated again from its stored config, seed and preset."""
    from scenegen.config import to_dict
    from scenegen.datasets.build import _generate
    from scenegen.datasets.family import Draw

    return _generate(Draw(0, seq.name, seq.seed, seq.preset, {}, to_dict(seq.config)))
