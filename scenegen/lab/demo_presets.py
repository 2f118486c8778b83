"""The preset files of a demo report (``report/presets/``) and the sealed list of their digests.

``scenegen demo`` generates every preset into ``OUT/presets/``: the sequence file
(``NAME.h5``), a contact sheet (``NAME.png``) and an animated preview (``NAME.gif``), then
writes :data:`LISTING`, a sealed JSON document that gives the SHA-256 of each of those
files. ``scenegen validate OUT`` checks the files against it (:func:`presets_problems`), so
any change of a preset file after it was written is found: a GIF has no checksum of its
own, and a flipped bit in its compressed pixels can still decode.
"""

from __future__ import annotations

import hashlib
import sys
import time
from collections.abc import Iterable
from pathlib import Path

from scenegen.errors import DataError

__all__ = ["LISTING", "SUFFIXES", "generate_presets", "presets_problems", "write_listing"]

LISTING = "presets.json"
"""The sealed listing of ``OUT/presets/``: ``{"files": ["NAME SHA256", ...]}``."""

SUFFIXES = (".h5", ".png", ".gif")
"""The kinds of preset file, in the order they are written and listed."""


def _write_sheet(seq: object, path: Path) -> None:
    """A contact sheet of 9 frames, 3 per row (each tile at full resolution)."""
    import cv2

    from scenegen.io.atomic import atomic_path
    from scenegen.io.preview import contact_sheet

    sheet = contact_sheet(seq, n=9, cols=3)  # type: ignore[arg-type]
    ok, data = cv2.imencode(".png", cv2.cvtColor(sheet, cv2.COLOR_RGB2BGR))
    if not ok:
        raise OSError(f"{path}: could not encode PNG")
    with atomic_path(path, ".png") as tmp:
        tmp.write_bytes(data.tobytes())


def _digest(path: Path) -> str:
    """SHA-256 of a file the caller just wrote (a regular file)."""
    from scenegen.io.atomic import read_regular

    return hashlib.sha256(read_regular(path)).hexdigest()


def write_listing(folder: Path, files: Iterable[Path]) -> None:
    """Write ``folder/`` :data:`LISTING`: the name and SHA-256 of each file, sealed.

    Parameters
    ----------
    folder : pathlib.Path
        The presets folder.
    files : iterable of pathlib.Path
        Its files, in the order to list them.
    """
    from scenegen.io.sealed import write_sealed_json

    write_sealed_json(folder / LISTING, {"files": [f"{p.name} {_digest(p)}" for p in files]},
                      indent=1)


def generate_presets(out: Path, seed: int, names: Iterable[str] | None = None) -> list[Path]:
    """Generate presets into ``out/presets/`` with a contact sheet and a GIF each, then
    the listing of their digests (:data:`LISTING`), written last.

    Parameters
    ----------
    out : pathlib.Path
        The report folder.
    seed : int
        Seed of every preset's sequence.
    names : iterable of str, optional
        The presets (default: every preset, :func:`scenegen.presets.all_names`).

    Returns
    -------
    list of pathlib.Path
        The sequence files written, one per preset.
    """
    from scenegen import presets
    from scenegen.io import write
    from scenegen.io.preview import write_preview
    from scenegen.render.plan import generate

    folder = out / "presets"
    folder.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    for name in presets.all_names() if names is None else names:
        t0 = time.perf_counter()
        seq = generate(name, seed=seed)
        write(folder / f"{name}.h5", seq)
        _write_sheet(seq, folder / f"{name}.png")
        write_preview(seq, folder / f"{name}.gif", max_frames=80)
        written.append(folder / f"{name}.h5")
        print(f"  preset {name}: {seq.n_frames} frames ({time.perf_counter() - t0:.1f} s)",
              file=sys.stderr, flush=True)
    write_listing(folder, [h5.with_suffix(s) for h5 in written for s in SUFFIXES])
    return written


def _listed(folder: Path, again: str) -> tuple[dict[str, str] | None, list[str]]:
    """The listing as {name: digest}, or None and the one line saying why it is not there
    or not sound."""
    from scenegen.io.atomic import SpecialFile
    from scenegen.io.sealed import Unsealed, read_sealed_json
    from scenegen.lab.experiments.outputs import parse_listing

    path = folder / LISTING
    if not path.exists() and not path.is_symlink():
        return None, [f"{path}: missing: it lists the preset files' digests ({again})"]
    try:
        doc = read_sealed_json(path)
    except SpecialFile as err:
        return None, [f"{err} (remove it, then {again})"]
    except (DataError, Unsealed) as err:
        return None, [f"{err} ({again})"]
    entries = parse_listing(doc.get("files"))
    if entries is None or len(doc) != 1:
        return None, [f"{path}: not a listing of preset files (damaged or edited: {again})"]
    return dict(entries), []


def presets_problems(out_dir: str | Path) -> list[str]:
    """What is wrong with the preset files of a demo report (``out_dir/presets/``, from
    ``scenegen demo``).

    Every ``.h5``, ``.png`` and ``.gif`` file there must be listed in :data:`LISTING`
    (sealed) with its SHA-256, and every listed file there with that digest; each
    sequence file must also be valid (:func:`scenegen.io.validate.check_file`, read in a
    time-boxed child process), each contact sheet a whole PNG image and each preview a
    whole GIF (:mod:`scenegen.io.images`). Which previews the page shows is the page's
    business (:func:`scenegen.lab.report.index_problem`).

    Parameters
    ----------
    out_dir : str or pathlib.Path
        The report folder.

    Returns
    -------
    list of str
        One line per problem, naming the file and the command that writes it again; empty
        when every preset file is sound or there is no ``presets/`` folder (a report of
        ``scenegen experiment all``).
    """
    from scenegen.io.atomic import SpecialFile, describe_special_file, read_regular
    from scenegen.io.images import gif_problem, png_problem
    from scenegen.io.validate import check_file

    folder = Path(out_dir) / "presets"
    if not folder.is_dir():
        return []
    again = f"`scenegen demo -o {out_dir}` with the report's --seed writes it again"
    images = {".png": png_problem, ".gif": gif_problem}
    listed, problems = _listed(folder, again)
    present = sorted(p for p in folder.iterdir() if p.suffix in SUFFIXES)
    for path in present:
        special = describe_special_file(path)  # never opened: it could block
        if special is not None:
            problems.append(f"{special} (remove it, then {again})")
            continue
        if listed is not None and path.name not in listed:
            problems.append(f"{path}: not a file {LISTING} lists (remove it, or {again})")
            continue
        try:
            data = read_regular(path)
        except SpecialFile as err:  # replaced since the check above
            problems.append(f"{err} (remove it, then {again})")
            continue
        except OSError as err:
            problems.append(f"{path}: unreadable ({type(err).__name__}) ({again})")
            continue
        if path.suffix == ".h5":
            lines = check_file(path, isolate=True)
            if lines:
                problems += [f"{line} ({again})" for line in lines]
                continue
        else:
            problem = images[path.suffix](data)
            if problem is not None:
                problems.append(f"{path}: {problem} (damaged: {again})")
                continue
        if listed is not None and hashlib.sha256(data).hexdigest() != listed[path.name]:
            problems.append(f"{path}: is not the file {LISTING} lists (damaged or edited: "
                            f"{again})")  # fmt: skip
    names = {p.name for p in present}
    problems += [f"{folder / name}: missing ({again})" for name in (listed or {})
                 if name not in names]  # fmt: skip
    return problems
