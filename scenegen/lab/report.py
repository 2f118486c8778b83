"""The demo report: every experiment at a reduced run count, and ``index.html`` linking it all.

``make demo`` runs ``scenegen demo -o report``, which generates the presets and their
previews into ``report/presets/``, then calls :func:`run_demo_experiments` (every
experiment at reduced counts into ``report/experiments/<name>/``) and :func:`build_report`,
which writes ``report/index.html`` (an overview of the verdicts, then per experiment our
tables beside the paper's, the claims with their tests, the figures, and the preset contact
sheets) and ``report/results.json`` (every experiment's results in one deterministic
document). ``scenegen experiment all -o DIR`` (:func:`run_all`) does the same at the
experiments' full counts.
"""

from __future__ import annotations

import html
import json
import re
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from scenegen.datasets.build import holds_report, make_output_folder
from scenegen.errors import ConfigError, DataError
from scenegen.io.atomic import refuse_special_files
from scenegen.io.sealed import write_sealed_json
from scenegen.lab.experiments import (
    get,
    names,
    refuse_special_outputs,
    run_experiment,
    verdict_counts,
)
from scenegen.lab.experiments.definitions import DEMO_PLAN
from scenegen.lab.experiments.outputs import (
    WRITTEN_BY,
    read_results,
    report_entry,
    versions_text,
)
from scenegen.lab.experiments.tables import render_table
from scenegen.lab.experiments.why import WHY

__all__ = ["DEMO_PLAN", "FULL_COMMAND", "build_report", "check_report_folder", "index_problem",
           "markdown_to_html", "render_report", "run_all",
           "run_demo_experiments"]

FULL_COMMAND = "scenegen experiment all -o out/"
"""The command of the full reproduction (every experiment at its default S x R)."""


def check_report_folder(out_dir: str | Path) -> None:
    """Refuse a report folder (``scenegen experiment all -o``, ``scenegen demo -o``) that
    holds what another verb wrote: a dataset, a benchmark's outputs or one experiment's
    results, whose ``results.json`` and ``index.html`` the report would replace.

    A report folder of an earlier run, an empty folder or a missing one pass.

    Parameters
    ----------
    out_dir : str or pathlib.Path
        The report folder.

    Raises
    ------
    ConfigError
        One line naming the folder and what it holds.
    """
    from scenegen.datasets.build import holds_benchmark_outputs, holds_experiment_outputs

    out = Path(out_dir)
    if (out / "manifest.json").exists():
        what = "is a dataset folder (manifest.json)"
    elif holds_benchmark_outputs(out):
        what = "holds the outputs of `scenegen benchmark`"
    elif holds_experiment_outputs(out) and not holds_report(out):
        what = "holds the results of `scenegen experiment`"
    else:
        return
    raise ConfigError(f"-o {out}: {what}; write the report into another folder")


def run_all(
    out_dir: str | Path,
    *,
    runs: int | None = None,
    scenes: int | None = None,
    jobs: int | None = None,
    scheduler: str | None = None,
    seed: int = 0,
    quick: bool = False,
    progress: bool = False,
    say: Callable[[str, dict[str, Any], Path], None] | None = None,
    plan: dict[str, tuple[int, int, bool]] | None = None,
) -> Path:
    """Run every experiment into ``out_dir/experiments/<name>/`` and build the report.

    Parameters
    ----------
    out_dir : str or Path
        The report folder (``index.html``, ``results.json``, ``experiments/``).
    runs, scenes : int, optional
        R and S for every experiment (default each experiment's own).
    jobs : int, optional
        Local worker processes (default all cores), started once for every experiment.
    scheduler : str, optional
        Address of a ``dask.distributed`` scheduler to run the tasks on.
    seed : int, default 0
        Base seed, as :func:`scenegen.lab.experiments.run_experiment`.
    quick : bool, default False
        Scaled-down settings, as :func:`scenegen.lab.experiments.run_experiment`.
    progress : bool, default False
        Print each experiment's name on stderr and show progress bars.
    say : callable, optional
        Called with (name, results, table path) after each experiment.
    plan : dict, optional
        Per experiment (S, R, quick), overriding ``runs``/``scenes``/``quick`` (the demo's
        :data:`DEMO_PLAN`).

    Returns
    -------
    Path
        The ``index.html`` written.

    Raises
    ------
    ConfigError
        As :func:`scenegen.lab.experiments.run_experiment`; ``out_dir`` holding a dataset,
        a benchmark's outputs or one experiment's results (:func:`check_report_folder`); a
        FIFO, a device or a socket where a file of the report or of an experiment is
        written, before any run.
    """
    from scenegen.lab.experiments.runner import plan_tasks, workers

    check_report_folder(out_dir)
    out = Path(out_dir) / "experiments"
    refuse_special_files(Path(out_dir) / page for page in ("index.html", "results.json"))
    for name in names():  # before any run, not after the experiments before it
        refuse_special_outputs(out / name)
    # One set of workers for every experiment, given every experiment's tasks at once: they
    # run the next experiment's tasks while this process summarises the previous one.
    with workers(jobs=jobs, scheduler=scheduler) as pool:
        for name in names():
            s, r, q = plan[name] if plan else (scenes, runs, quick)
            exp = get(name)
            tasks = plan_tasks(exp, runs=exp.runs if r is None else r,
                               scenes=exp.scenes if s is None else s, seed=seed, quick=q)
            pool.start(tasks, out / name / "runs")
        for name in names():
            s, r, q = plan[name] if plan else (scenes, runs, quick)
            folder = out / name
            if progress:
                print(f"  experiment {name}", file=sys.stderr, flush=True)
            res = run_experiment(name, folder, runs=r, scenes=s, jobs=jobs,
                                 scheduler=scheduler, seed=seed, quick=q, progress=progress)
            if say is not None:
                say(name, res, folder / "table.md")
    return build_report(out_dir)


def run_demo_experiments(
    out_dir: str | Path, jobs: int | None = None, *, seed: int = 0
) -> Path:
    """Every experiment at the reduced counts of :data:`DEMO_PLAN`, then the report.

    One line per experiment (its S x R) is printed on stderr; progress bars show when
    stderr is a terminal.

    Parameters
    ----------
    out_dir : str or Path
        The report folder.
    jobs : int, optional
        Local worker processes (default all cores).
    seed : int, default 0
        Base seed.

    Returns
    -------
    Path
        The ``index.html`` written.

    Raises
    ------
    ConfigError
        As :func:`run_all`.
    """
    def say(name: str, res: dict[str, Any], table: Path) -> None:
        print(f"  experiment {name}: S = {res['scenes']} x R = {res['runs']}", file=sys.stderr,
              flush=True)

    return run_all(out_dir, jobs=jobs, seed=seed, plan=DEMO_PLAN,
                   progress=sys.stderr.isatty(), say=say)


_INLINE = [
    (re.compile(r"\*\*(.+?)\*\*"), r"<strong>\1</strong>"),
    (re.compile(r"`(.+?)`"), r"<code>\1</code>"),
]


def _inline(text: str) -> str:
    out = html.escape(text, quote=False)
    for pattern, repl in _INLINE:
        out = pattern.sub(repl, out)
    return out


def markdown_to_html(md: str) -> str:
    r"""The small Markdown subset of ``table.md`` as HTML: headings, pipe tables, bullet
    lists, paragraphs, ``**bold**`` and ```code```.

    Parameters
    ----------
    md : str
        The Markdown text (``\|`` in a table cell is a literal ``|``).

    Returns
    -------
    str
        The HTML fragment, one element per line; headings are shifted one level down
        (``#`` gives ``<h2>``, at most ``<h6>``) and text is HTML-escaped.

    Examples
    --------
    >>> print(markdown_to_html("# Title\n\n| a | b |\n|---|---|\n| 1 | **2** |"))
    <h2>Title</h2>
    <table>
    <tr><th>a</th><th>b</th></tr>
    <tr><td>1</td><td><strong>2</strong></td></tr>
    </table>
    """
    lines = md.splitlines()
    out: list[str] = []
    i = 0
    while i < len(lines):
        line = lines[i].rstrip()
        if not line:
            i += 1
            continue
        m = re.match(r"^(#{1,6})\s+(.*)$", line)
        if m:
            level = min(len(m.group(1)) + 1, 6)
            out.append(f"<h{level}>{_inline(m.group(2))}</h{level}>")
            i += 1
        elif line.startswith("|"):
            rows = []
            while i < len(lines) and lines[i].startswith("|"):
                cells = re.split(r"(?<!\\)\|", lines[i].strip()[1:-1])  # "\|" is no border
                rows.append([c.strip().replace("\\|", "|") for c in cells])
                i += 1
            body = [r for r in rows[1:] if not all(set(c) <= {"-", ":"} for c in r)]
            out.append("<table>")
            out.append("<tr>" + "".join(f"<th>{_inline(c)}</th>" for c in rows[0]) + "</tr>")
            for r in body:
                out.append("<tr>" + "".join(f"<td>{_inline(c)}</td>" for c in r) + "</tr>")
            out.append("</table>")
        elif line.startswith("- "):
            out.append("<ul>")
            while i < len(lines) and lines[i].startswith("- "):
                out.append(f"<li>{_inline(lines[i][2:])}</li>")
                i += 1
            out.append("</ul>")
        else:
            para = []
            while i < len(lines) and lines[i].strip() and not re.match(r"^(#|\||- )", lines[i]):
                para.append(lines[i].strip())
                i += 1
            out.append(f"<p>{_inline(' '.join(para))}</p>")
    return "\n".join(out)


_CSS = """
body { font-family: sans-serif; max-width: 1400px; margin: 2em auto; padding: 0 1em; }
table { border-collapse: collapse; margin: 0.5em 0 1em; font-size: 0.9em; }
th, td { border: 1px solid #bbb; padding: 3px 7px; text-align: left; }
th { background: #eee; }
img { max-width: 100%; border: 1px solid #ddd; margin: 4px 0; }
.previews img { max-width: 100%; }
.no { color: #b00; font-weight: bold; }
.yes { color: #070; }
"""


def _rel(path: Path, root: Path) -> str:
    return html.escape(path.relative_to(root).as_posix())


def _write_atomic(path: Path, text: str) -> None:
    from scenegen.io.atomic import write_text

    write_text(path, text)


def _overview(all_results: dict[str, dict[str, Any]]) -> list[str]:
    parts = ["<h2 id='overview'>Overview: the papers' claims on our runs</h2>"]
    if any(r.get("indicative") for r in all_results.values()):
        parts.append(
            "<p class='no'>Indicative only: some experiments ran fewer scenes or runs than "
            "their defaults (see S x R below), so their verdicts may change. The full "
            f"reproduction is <code>{html.escape(FULL_COMMAND)}</code>.</p>")
    parts.append("<table><tr><th>experiment</th><th>S x R</th><th>reproduced</th>"
                 "<th>not reproduced</th><th>inconclusive</th><th>paper's numbers that agree"
                 "</th></tr>")
    for name, res in all_results.items():
        c = verdict_counts(res)
        comps = res.get("comparisons", [])
        agree = f"{sum(x['agree'] for x in comps)} of {len(comps)}" if comps else "none printed"
        parts.append(
            f"<tr><td><a href='#{name}'>{html.escape(name)}</a></td>"
            f"<td>{res['scenes']} x {res['runs']}{' (quick)' if res['quick'] else ''}</td>"
            f"<td class='yes'>{c['reproduced']}</td><td class='no'>{c['not reproduced']}</td>"
            f"<td>{c['inconclusive']}</td><td>{agree}</td></tr>")
    parts.append("</table>")
    who = {name: res.get(WRITTEN_BY) for name, res in all_results.items()}
    if len({json.dumps(w, sort_keys=True) for w in who.values()}) == 1:
        versions = next(iter(who.values()))
        if versions:
            parts.append(f"<p>Computed with {html.escape(versions_text(versions))}.</p>")
    else:  # experiments computed by different installations: say which by which
        lines = [f"{html.escape(name)}: " + (html.escape(versions_text(w)) if w
                                             else "no versions recorded (an older scenegen)")
                 for name, w in who.items()]  # fmt: skip
        parts.append("<p>Computed with different software: " + "; ".join(lines) + ".</p>")
    return parts


def _num(v: Any) -> str:
    if v is None:
        return "none (not reached)"
    if isinstance(v, float):
        return f"{v:.2f}".rstrip("0").rstrip(".")
    return str(v)


def build_report(out_dir: str | Path) -> Path:
    """Write ``out_dir/index.html`` and ``out_dir/results.json`` from what the folder holds.

    Links every ``experiments/<name>/`` table (rendered) and figure, and every preset
    preview (``presets/*.png``, ``*.gif``). Missing pieces are listed as missing rather
    than failing. Both files are written atomically.

    Parameters
    ----------
    out_dir : str or Path
        The report folder (created if missing).

    Returns
    -------
    Path
        The ``index.html`` written.

    Raises
    ------
    DataError
        An experiment's ``results.json`` that is damaged, edited, unsealed or not its
        results (:func:`scenegen.lab.experiments.outputs.read_results`).

    See Also
    --------
    render_report : the same page and results, without writing them.
    """
    root = Path(out_dir)
    make_output_folder(root)
    page, all_results = render_report(root)
    index = root / "index.html"
    _write_atomic(index, page)
    write_sealed_json(root / "results.json", {"experiments": all_results}, indent=1)
    return index


def index_problem(out_dir: str | Path) -> str | None:
    """What is wrong with ``out_dir/index.html``: ``"missing"``, ``"unreadable (...)"``,
    ``"is not a regular file (a FIFO): remove it"`` (or a device, a socket: never waited on),
    ``"stale"`` (not the page :func:`build_report` writes from the folder as it is: edited,
    damaged, or written from other results), or None (``scenegen validate``).

    Parameters
    ----------
    out_dir : str or pathlib.Path
        The report folder.

    Returns
    -------
    str or None
        The problem, or None when the page is the one :func:`render_report` gives.

    Raises
    ------
    DataError
        As :func:`render_report`, when the page exists.
    """
    from scenegen.io.atomic import SpecialFile, read_regular_text

    index = Path(out_dir) / "index.html"
    try:
        text = read_regular_text(index)
    except FileNotFoundError:
        return "missing"
    except SpecialFile as err:  # "PATH: is not a regular file (a FIFO)"
        return f"{str(err).removeprefix(f'{index}: ')}: remove it"
    except (OSError, UnicodeDecodeError) as err:
        return f"unreadable ({type(err).__name__})"
    if text != render_report(out_dir)[0]:
        return "stale"
    return None


def render_report(out_dir: str | Path) -> tuple[str, dict[str, dict[str, Any]]]:
    """The text of ``index.html`` and the experiments' entries of the report's
    ``results.json``, from what ``out_dir`` holds (nothing is written).

    Parameters
    ----------
    out_dir : str or pathlib.Path
        The report folder: ``experiments/<name>/`` (``results.json``, ``table.md``,
        PNGs) and ``presets/`` (previews, HDF5 files).

    Returns
    -------
    page : str
        The text of ``index.html``.
    results : dict of str to dict
        Per experiment that has a ``results.json``, in :func:`names` order, its entry
        (:func:`~scenegen.lab.experiments.outputs.report_entry`).

    Raises
    ------
    DataError
        An experiment's ``results.json`` that is damaged, edited, unsealed, not its
        results, or whose contents no table can be made of.
    """
    root = Path(out_dir)
    parts = [
        "<!DOCTYPE html>",
        "<html><head><meta charset='utf-8'><title>scenegen report</title>",
        f"<style>{_CSS}</style></head><body>",
        "<h1>scenegen report</h1>",
        "<p>Synthetic scenarios reproducing the DPS, KAMS and SHM papers' test sequences, "
        "the papers' trackers run on them, and the papers' tables with their figures beside "
        "ours, each claim judged by a stated test. Jump to the "
        "<a href='#overview'>overview</a>.</p>",
    ]
    all_results: dict[str, dict[str, Any]] = {}
    body: list[str] = []
    for name in names():
        folder = root / "experiments" / name
        body.append(f"<h2 id='{name}'>{html.escape(name)}: {html.escape(get(name).title)}</h2>")
        res_path = folder / "results.json"
        if not res_path.exists():
            body.append("<p class='no'>not run (no results.json)</p>")
            continue
        loaded = read_results(res_path, name)
        all_results[name] = report_entry(loaded)
        links = [f"<a href='{_rel(res_path, root)}'>results.json</a>"]
        table = folder / "table.md"
        if table.exists():
            links.append(f"<a href='{_rel(table, root)}'>table.md</a>")
        try:  # the table of the sealed results, not the unsealed table.md
            md = render_table(get(name), loaded, WHY.get(name, ""))
            _overview({name: loaded})
        except Exception as err:  # noqa: BLE001 - a sealed file with contents no table expects
            raise DataError(f"{res_path}: not an experiment's results ({type(err).__name__}: "
                            f"{str(err)[:80]})") from None  # fmt: skip
        body.append(markdown_to_html(md.split("\n", 1)[1] if "\n" in md else ""))
        body.append("<p>" + " · ".join(links) + "</p>")
        for png in sorted(folder.glob("*.png")):
            body.append(f"<p><a href='{_rel(png, root)}'><img src='{_rel(png, root)}' "
                         f"alt='{html.escape(png.stem)}'></a></p>")
    parts += _overview(all_results) + body
    parts.append("<h2>Presets</h2>")
    previews = sorted((root / "presets").glob("*.png")) + sorted((root / "presets").glob("*.gif"))
    if not previews:
        parts.append("<p class='no'>no preset previews found in presets/</p>")
    by_stem: dict[str, list[Path]] = {}
    for p in previews:
        by_stem.setdefault(p.stem, []).append(p)
    for stem in sorted(by_stem):
        parts.append(f"<h3>{html.escape(stem)}</h3><div class='previews'>")
        for p in by_stem[stem]:
            parts.append(f"<a href='{_rel(p, root)}'><img src='{_rel(p, root)}' "
                         f"alt='{html.escape(p.name)}'></a>")
        h5 = root / "presets" / f"{stem}.h5"
        if h5.exists():
            parts.append(f"<p><a href='{_rel(h5, root)}'>{html.escape(h5.name)}</a></p>")
        parts.append("</div>")
    parts.append("</body></html>")
    return "\n".join(parts) + "\n", all_results
