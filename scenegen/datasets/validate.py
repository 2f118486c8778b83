"""Validating a whole dataset folder: manifest, every shard file, every digest."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from scenegen.datasets.build import (
    MANIFEST,
    _entry,
    _header,
    is_drawn,
    manifest_entries,
    manifest_family,
    read_manifest,
)
from scenegen.datasets.family import Family
from scenegen.errors import ConfigError, DataError
from scenegen.io.atomic import describe_special_file

__all__ = ["validate_dataset"]


def validate_dataset(
    root: str | Path, *, deep: bool = False, progress: Callable[[int], None] | None = None
) -> list[str]:
    """Problems of the dataset folder ``root``, one line each (empty if valid).

    Checks that the manifest is readable and complete (one sound entry per index
    0..count-1, in the shard its index belongs to: :func:`manifest_entries`), that its
    header describes the family of its ``family_digest`` (:func:`manifest_family`), that
    every shard file passes :func:`scenegen.io.validate.check_file` and holds exactly its
    sequences, that each sequence is the one the family draws for its index (seed,
    preset, config) and its contents match the manifest's digests, and that each entry
    says what the builder would write for it (name, seed, preset, ``params``,
    ``n_frames``, width, height, targets); shard files the manifest does not list are
    reported too.

    Parameters
    ----------
    root : str or Path
    deep : bool, default False
        Also generate every sequence again from its stored config and seed and compare
        with the manifest's digests (as long as making the dataset).
    progress : callable, optional
        Called with the number of shard files checked so far.

    Returns
    -------
    list of str
        One line per problem, each naming the file (and entry or sequence) at fault; a
        manifest that cannot be read at all gives that one line.
    """
    from scenegen.io import read, sequence_names
    from scenegen.io.validate import check_file
    from scenegen.testing.fixtures import digests

    p = Path(root)
    mpath = p / MANIFEST
    try:
        man = read_manifest(p, check_entries=False)
        entries, problems = manifest_entries(man, mpath)
    except DataError as err:
        return [str(err)]
    count = man["count"]
    if not man.get("complete"):
        problems.insert(0, f"{p}: incomplete dataset (the build was interrupted); rerun it")
    fam: Family | None = None
    try:
        fam = manifest_family(man, mpath)
    except DataError as err:
        problems.append(str(err))
    if fam is not None:
        want = _header(fam, count, man["seed"], man["shard_size"], man.get("compression"))
        off = [k for k in ("family", "shards", "params", "axes", "vary") if man.get(k) != want[k]]
        if off:
            verb = "differs" if len(off) == 1 else "differ"
            problems.append(f"{mpath}: {', '.join(off)} {verb} from what its family gives "
                            "(edited)")  # fmt: skip
    by_file: dict[str, list[dict]] = {}
    for e in entries:
        by_file.setdefault(e["file"], []).append(e)
    missing = sorted(set(range(count)) - {e["index"] for e in entries})
    if missing:
        shown = ", ".join(map(str, missing[:5])) + (" ..." if len(missing) > 5 else "")
        problems.append(f"{p}: {len(missing)} of {count} sequences not in the manifest: {shown}")
    listed = set(by_file)
    for extra in sorted(f.name for f in p.glob("shard-*.h5") if f.name not in listed):
        problems.append(f"{p / extra}: shard file not listed in the manifest")
    for n, (file, group) in enumerate(sorted(by_file.items())):
        path = p / file
        if not path.is_file():
            special = describe_special_file(path)  # named as such, not "missing"
            problems.append(f"{special} where a shard file belongs ({len(group)} sequences)"
                            if special else  # fmt: skip
                            f"{path}: missing shard file ({len(group)} sequences)")
            continue
        found = check_file(path, isolate=True)
        if found:
            problems += found
            continue
        group = sorted(group, key=lambda e: e["index"])
        names = [e["name"] for e in group]
        try:
            have = sequence_names(path)
            if have != names:
                problems.append(f"{path}: holds {have}, the manifest lists {names}")
                continue
            for e in group:
                seq = read(path, e["name"])
                if fam is not None:
                    problems += _against_family(fam, man["seed"], e, seq, path, mpath)
                got = digests(seq)
                bad = sorted(k for k, v in e["digests"].items() if got.get(k) != v)
                if bad or not e["digests"]:
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


def _against_family(
    fam: Family, seed: int, e: dict[str, Any], seq: Any, path: Path, mpath: Path
) -> list[str]:
    """The sequence ``seq`` stored for entry ``e`` against the family's draw for its index,
    and ``e`` against the entry the builder makes of them (:func:`_entry`): one line each."""
    from scenegen.config.messages import _short

    try:
        d = fam.draw(e["index"], seed)
    except ConfigError as err:
        return [f"{mpath}: sequence {e['index']} cannot be drawn again: {err}"]
    if not is_drawn(seq, d):
        return [f"{path}: {e['name']}: is not the sequence its family draws for index "
                f"{e['index']} (seed, preset or config differ)"]  # fmt: skip
    want = _entry(d, e["file"], seq, e["digests"])
    have = e.get("params")
    if isinstance(have, dict):  # written before round 17: no grid position of a named
        # axis of one field (its field's value is there); taken as it was written then
        old = [a.name for a in fam.axes if a.named and len(a.paths) == 1 and a.name not in have]
        want["params"] = {k: v for k, v in want["params"].items() if k not in old}
    off = [k for k in want if e.get(k) != want[k]]
    if not off:
        return []
    k, have, should = off[0], e.get(off[0]), want[off[0]]
    if k == "params":  # name the first parameter that differs
        keys = [q for q in {**should, **have} if have.get(q, None) != should.get(q, None)]
        k, have, should = f"params[{keys[0]!r}]", have.get(keys[0]), should.get(keys[0])
    verb = "differs" if len(off) == 1 else "differ"
    return [f"{mpath}: entry of {e['name']}: {', '.join(off)} {verb} from its sequence "
            f"({k}: {_short(have)} in the manifest, {_short(should)} drawn)"]  # fmt: skip


def _regenerate(seq: Any) -> Any:
    """The sequence generated again from its stored config, seed and preset."""
    from scenegen.config import to_dict
    from scenegen.datasets.build import _generate
    from scenegen.datasets.family import Draw

    return _generate(Draw(0, seq.name, seq.seed, seq.preset, {}, to_dict(seq.config)))
