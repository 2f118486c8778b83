"""Tracking quality of one tracker setting against another, measured on paired runs.

The question this module answers: does a changed tracker parameter (the nested-box
kernel, ``kernel="box"``, against the particle filters' default Epanechnikov kernel)
keep every rate and mean an experiment reports inside the interval of the default's?

Lay the runs out as ``ROOT/<experiment>/base/`` (the experiment as defined) and
``ROOT/<experiment>/other/`` (the same command with ``--param``), both on the same base
seed, so that every run of one side has its paired run (same scene, same tracker seed) on
the other::

    scenegen experiment dps-occlusion --jobs 1 -o ROOT/dps-occlusion/base
    scenegen experiment dps-occlusion --jobs 1 --param kernel=box -o ROOT/dps-occlusion/other
    python -m scenegen.lab.kernel_quality ROOT -o ROOT/kernel-quality.md

Runs of methods that the parameter does not apply to (``kams`` in ``kams-robustness``,
whose pairs are taken against it) go to ``ROOT/<experiment>/shared/`` and are added to
both sides. Both sides are summarised again from their run records with the experiment's
own summary (``scenegen.lab.experiments.summary``), and every value with an interval is
compared: a rate (``k`` of ``n``, Wilson interval) or a mean (bootstrap interval).
A value is "inside" when the other side's value lies in the base side's interval.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = ["Row", "compare", "compare_root", "load_records", "main", "render", "summary_of"]

#: Side folders under ``ROOT/<experiment>/``.
BASE, OTHER, SHARED = "base", "other", "shared"


@dataclass(frozen=True)
class Row:
    """One value reported by an experiment, on both sides.

    ``path`` is its place in the experiment's summary (e.g.
    ``presets/dps-occlusion/DPS/hard/success``); ``kind`` is ``"rate"`` (percent, with
    ``k`` of ``n``) or ``"mean"``; ``inside`` is whether ``other`` lies in ``base_ci``.

    Attributes
    ----------
    experiment : str
        The experiment's name.
    path : str
        The value's place in the summary, keys joined by ``/``.
    kind : str
        ``"rate"`` or ``"mean"``.
    base, other : float
        The value on each side (a rate in percent).
    base_ci, other_ci : (float, float)
        The interval on each side (``other_ci`` (nan, nan) where undefined).
    base_n, other_n : int
        The ``n`` of each side's value (0 where the summary gives none).
    """

    experiment: str
    path: str
    kind: str
    base: float
    base_ci: tuple[float, float]
    base_n: int
    other: float
    other_ci: tuple[float, float]
    other_n: int

    @property
    def inside(self) -> bool:
        """Whether ``other`` lies in ``base_ci``, bounds included, a bool (False for NaN)."""
        lo, hi = self.base_ci
        return bool(lo <= self.other <= hi)

    @property
    def metric(self) -> str:
        """The metric's name, a str: the last part of ``path`` (e.g. ``"success"``)."""
        return self.path.rsplit("/", 1)[-1]


def load_records(folders: Iterable[Path]) -> list[dict[str, Any]]:
    """The run records (``runs/*.json``) of the experiment folders, in name order.

    Each file is read as the experiments read a run record
    (:func:`scenegen.lab.experiments.outputs.read_record`): its seal is checked and
    removed, and its fields are checked.

    Parameters
    ----------
    folders : iterable of pathlib.Path
        Experiment folders, in order (a folder without ``runs/`` adds nothing).

    Returns
    -------
    list of dict
        The records (without their digests), folder by folder, each folder's by file name.

    Raises
    ------
    DataError
        One line naming the file: damaged, edited, unsealed or not a run record.
    """
    from scenegen.lab.experiments.outputs import read_record

    out = []
    for folder in folders:
        for path in sorted((Path(folder) / "runs").glob("*.json")):
            out.append(read_record(path))
    return out


def summary_of(experiment: str, records: list[dict[str, Any]]) -> dict[str, Any]:
    """The experiment's summary (as in its ``results.json``) of these records.

    Parameters
    ----------
    experiment : str
        The experiment's name.
    records : list of dict
        Its run records.

    Returns
    -------
    dict
        The ``summary`` entry of
        :func:`~scenegen.lab.experiments.summary.summarize`.
    """
    from scenegen.lab.experiments import get
    from scenegen.lab.experiments.summary import summarize

    return summarize(get(experiment), records)["summary"]


def _leaves(tree: Any, path: tuple[str, ...] = ()) -> Iterable[tuple[str, dict[str, Any]]]:
    """(path, value) of every value with an interval in a summary tree."""
    if isinstance(tree, dict):
        if "ci" in tree and ("pct" in tree or "mean" in tree):
            yield "/".join(path), tree
            return
        for key in sorted(tree):
            yield from _leaves(tree[key], (*path, str(key)))


def _value(leaf: dict[str, Any]) -> tuple[str, float, tuple[float, float], int]:
    kind = "rate" if "pct" in leaf else "mean"
    value = leaf["pct"] if kind == "rate" else leaf["mean"]
    lo, hi = leaf["ci"]
    return kind, value, (lo, hi), int(leaf.get("n", 0))


def compare(experiment: str, base: dict[str, Any], other: dict[str, Any]) -> list[Row]:
    """Rows for every value with an interval present (and defined) in both summaries.

    A value is kept when both sides have it and the base side's interval is defined; an
    undefined interval on the other side becomes (nan, nan).

    Parameters
    ----------
    experiment : str
        The experiment's name, copied into each row.
    base, other : dict
        The two summaries (:func:`summary_of`).

    Returns
    -------
    list of Row
        In the order of the base summary's paths (keys sorted).
    """
    theirs = dict(_leaves(other))
    rows = []
    for path, leaf in _leaves(base):
        if path not in theirs:
            continue
        kind, b, b_ci, b_n = _value(leaf)
        _, o, o_ci, o_n = _value(theirs[path])
        if b is None or o is None or None in b_ci:
            continue
        rows.append(Row(experiment, path, kind, float(b), (float(b_ci[0]), float(b_ci[1])),
                        b_n, float(o), (float(o_ci[0]), float(o_ci[1])) if None not in o_ci
                        else (float("nan"), float("nan")), o_n))
    return rows


def compare_root(root: Path, experiments: Sequence[str] | None = None) -> list[Row]:
    """Rows of every experiment folder under ``root`` that has both sides.

    Parameters
    ----------
    root : pathlib.Path
        The folder of ``ROOT/<experiment>/{base,other,shared}``.
    experiments : sequence of str, optional
        The experiments to compare (default: every subfolder with ``base/`` and
        ``other/``, by name).

    Returns
    -------
    list of Row
        Experiment by experiment, :func:`compare` of both sides' summaries (the runs of
        ``shared/``, when present, added to both).

    Raises
    ------
    DataError
        As :func:`load_records`, for a damaged or edited run record.
    ConfigError
        One line: an experiment asked for is not an experiment's name, or ``root`` has no
        ``<experiment>/base`` and ``<experiment>/other`` folders for it.
    """
    from scenegen.errors import ConfigError
    from scenegen.lab.experiments import get

    root = Path(root)
    for name in experiments or []:
        get(name)  # an unknown name: one line listing the experiments
        missing = [side for side in (BASE, OTHER) if not (root / name / side).is_dir()]
        if missing:
            raise ConfigError(f"experiment {name!r}: no {root / name / missing[0]} folder "
                              f"(ROOT/<experiment>/{BASE} and {OTHER} are compared)")
    names = experiments or sorted(p.name for p in root.iterdir()
                                  if (p / BASE).is_dir() and (p / OTHER).is_dir())
    rows: list[Row] = []
    for name in names:
        shared = [root / name / SHARED] if (root / name / SHARED).is_dir() else []
        base = load_records([root / name / BASE, *shared])
        other = load_records([root / name / OTHER, *shared])
        rows += compare(name, summary_of(name, base), summary_of(name, other))
    return rows


def _fmt(x: float) -> str:
    return f"{x:.1f}"


def render(rows: list[Row], *, base: str = "base", other: str = "other",
           metrics: Iterable[str] | None = None) -> str:
    """A markdown table of the rows (only ``metrics`` when given), and the count inside.

    Parameters
    ----------
    rows : list of Row
        The rows to show.
    base, other : str, default "base", "other"
        The sides' labels in the header and the closing line.
    metrics : iterable of str, optional
        Keep only the rows whose last path component is one of these (e.g.
        ``"success"``).

    Returns
    -------
    str
        The table, a blank line, and ``"N of M values of OTHER inside BASE's
        interval."``, ending with a newline.
    """
    keep = set(metrics) if metrics else None
    rows = [r for r in rows if keep is None or r.metric in keep]
    lines = [f"| experiment | value | {base} [95% interval] (n) | {other} [95% interval] (n) "
             f"| {other} inside {base}'s interval |", "|---|---|---:|---:|---|"]
    for r in rows:
        lines.append(
            f"| {r.experiment} | {r.path} | {_fmt(r.base)} [{_fmt(r.base_ci[0])}–"
            f"{_fmt(r.base_ci[1])}] ({r.base_n}) | {_fmt(r.other)} [{_fmt(r.other_ci[0])}–"
            f"{_fmt(r.other_ci[1])}] ({r.other_n}) | {'yes' if r.inside else '**no**'} |")
    n_in = sum(r.inside for r in rows)
    lines += ["", f"{n_in} of {len(rows)} values of {other} inside {base}'s interval."]
    return "\n".join(lines) + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m scenegen.lab.kernel_quality ROOT [-o FILE]``: print (or write) the table.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments (default: ``sys.argv[1:]``): ``ROOT``, ``--experiment``,
        ``--metric`` (both repeatable), ``--base-label``, ``--other-label``, ``-o FILE``.

    Returns
    -------
    int
        The exit status: 0, or 1 (one line on stderr) for a damaged or edited run
        record; bad arguments (a ``ROOT`` that is not a folder, an ``--experiment``
        that is not an experiment or has no base and other folders), exit 2 through
        argparse.
    """
    p = argparse.ArgumentParser(prog="python -m scenegen.lab.kernel_quality",
                                description=__doc__.split("\n\n")[0])
    p.add_argument("root", type=Path, help="folder of ROOT/<experiment>/{base,other,shared}")
    p.add_argument("--experiment", action="append", default=None,
                   help="only this experiment (repeatable)")
    p.add_argument("--metric", action="append", default=None,
                   help="only values named so, e.g. success (repeatable)")
    p.add_argument("--base-label", default="base")
    p.add_argument("--other-label", default="other")
    p.add_argument("-o", "--output", type=Path, default=None, help="write the table here")
    args = p.parse_args(argv)
    if not args.root.is_dir():
        p.error(f"ROOT {args.root} is not a folder")
    from scenegen.errors import ConfigError, DataError

    try:
        rows = compare_root(args.root, args.experiment)
    except ConfigError as err:
        p.error(str(err))
    except DataError as err:
        print(f"{p.prog}: error: {err}", file=sys.stderr)
        return 1
    text = render(rows, base=args.base_label, other=args.other_label, metrics=args.metric)
    if args.output is None:
        sys.stdout.write(text)
    else:
        from scenegen.io.atomic import write_text

        write_text(args.output, text)
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
