"""The demo report: every experiment at a reduced run count, and ``index.html`` linking it all.

``make demo`` runs ``scenegen demo -o report``, which generates the presets and their
previews into ``report/presets/``, then calls :func:`run_demo_experiments` (every
experiment into ``report/experiments/<name>/``) and :func:`build_report`, which writes
``report/index.html`` (every table and figure, every preset preview, and a "Fidelity"
section comparing with the papers plainly) and ``report/results.json`` (every
experiment's results in one deterministic document).
"""

from __future__ import annotations

import html
import json
import re
import sys
from pathlib import Path
from typing import Any

from scenegen.lab.experiments import get, names, run_experiment

__all__ = ["DEMO_PLAN", "build_report", "markdown_to_html", "run_demo_experiments"]

# Per experiment: (cap on runs, quick mode). Chosen so that the whole demo (presets,
# previews, experiments, report) stays within 10 minutes on 2 cores with runs=3. The
# full-size experiments are run with `scenegen experiment NAME` (see the README).
DEMO_PLAN: dict[str, tuple[int, bool]] = {
    "dps-synthetic": (3, False),
    "dps-occlusion": (3, False),
    "kams-accuracy": (2, False),
    "kams-robustness": (20, False),
    "shm-depth": (3, False),
}


def run_demo_experiments(
    out_dir: str | Path, runs: int = 3, jobs: int | None = None, *, seed: int = 0
) -> list[Path]:
    """Run every experiment at a reduced run count into ``out_dir/experiments/<name>/``.

    Parameters
    ----------
    out_dir : str or Path
        The report folder.
    runs : int
        Runs per method; each experiment uses at most its :data:`DEMO_PLAN` cap, except
        ``kams-robustness``, whose McNemar test needs cases: it uses ``max(runs, cap)``.
    jobs : int, optional
        Local worker processes (default all cores).
    seed : int
        Base seed of the experiments.

    Returns
    -------
    list of Path
        The experiment folders written.
    """
    out = Path(out_dir) / "experiments"
    folders = []
    for name in names():
        cap, quick = DEMO_PLAN[name]
        r = max(runs, cap) if name == "kams-robustness" else max(1, min(runs, cap))
        folder = out / name
        print(f"  experiment {name}: {r} runs per method", file=sys.stderr, flush=True)
        run_experiment(
            name, folder, runs=r, jobs=jobs, seed=seed, quick=quick,
            progress=sys.stderr.isatty(),
        )
        folders.append(folder)
    return folders


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
    """The small Markdown subset of ``table.md`` as HTML: headings, pipe tables, bullet
    lists, paragraphs, ``**bold**`` and ```code```."""
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
                rows.append([c.strip() for c in lines[i].strip().strip("|").split("|")])
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
body { font-family: sans-serif; max-width: 1100px; margin: 2em auto; padding: 0 1em; }
table { border-collapse: collapse; margin: 0.5em 0 1em; font-size: 0.9em; }
th, td { border: 1px solid #bbb; padding: 3px 7px; text-align: left; }
th { background: #eee; }
img { max-width: 100%; border: 1px solid #ddd; margin: 4px 0; }
.previews img { max-width: 48%; }
.no { color: #b00; font-weight: bold; }
.yes { color: #070; }
"""


def _rel(path: Path, root: Path) -> str:
    return html.escape(path.relative_to(root).as_posix())


def _write_atomic(path: Path, text: str) -> None:
    from scenegen.io.atomic import write_text

    write_text(path, text)


def _fidelity(all_results: dict[str, dict[str, Any]]) -> list[str]:
    parts = [
        "<h2 id='fidelity'>Fidelity: our results against the papers</h2>",
        "<p>Each paper's qualitative claims, checked on our runs, then every number the "
        "paper prints that ours does not match (within 10 points for percentages, 3 px or "
        "25% for errors, the same side of z = 2.576 for z scores). Demo runs are few, so "
        "rates move in steps of 100/R %.</p>",
    ]
    for name, res in all_results.items():
        claims = res.get("fidelity", [])
        held = sum(1 for c in claims if c["holds"])
        parts.append(f"<h3>{html.escape(name)} — {held} of {len(claims)} claims hold "
                     f"(R = {res['runs']}{', quick' if res['quick'] else ''})</h3>")
        if claims:
            parts.append("<table><tr><th>paper's claim</th><th>ours</th><th>holds</th></tr>")
            for c in claims:
                cls, word = ("yes", "yes") if c["holds"] else ("no", "NO")
                parts.append(
                    f"<tr><td>{html.escape(c['claim'])}</td><td>{html.escape(c['ours'])}</td>"
                    f"<td class='{cls}'>{word}</td></tr>"
                )
            parts.append("</table>")
        differ = [c for c in res.get("comparisons", []) if not c["agree"]]
        total = len(res.get("comparisons", []))
        if differ:
            parts.append(f"<p>{len(differ)} of {total} printed numbers differ:</p><ul>")
            for c in differ:
                parts.append(
                    f"<li>{html.escape(c['what'])}: paper {html.escape(_num(c['paper']))}, "
                    f"ours {html.escape(_num(c['ours']))}</li>"
                )
            parts.append("</ul>")
        elif total:
            parts.append(f"<p>All {total} printed numbers agree.</p>")
        else:
            parts.append("<p>The paper prints no numbers for this experiment.</p>")
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
    preview (``presets/*.png``, ``*.gif``); adds the Fidelity section. Missing pieces are
    listed as missing rather than failing.

    Returns
    -------
    Path
        The ``index.html`` written.
    """
    root = Path(out_dir)
    root.mkdir(parents=True, exist_ok=True)
    parts = [
        "<!DOCTYPE html>",
        "<html><head><meta charset='utf-8'><title>scenegen report</title>",
        f"<style>{_CSS}</style></head><body>",
        "<h1>scenegen report</h1>",
        "<p>Synthetic scenarios reproducing the DPS, KAMS and SHM papers' test sequences, "
        "the papers' trackers run on them, and the papers' tables with their figures beside "
        "ours. Jump to <a href='#fidelity'>Fidelity</a>.</p>",
    ]
    all_results: dict[str, dict[str, Any]] = {}
    for name in names():
        folder = root / "experiments" / name
        parts.append(f"<h2 id='{name}'>{html.escape(name)}: {html.escape(get(name).title)}</h2>")
        res_path = folder / "results.json"
        if not res_path.exists():
            parts.append("<p class='no'>not run (no results.json)</p>")
            continue
        all_results[name] = json.loads(res_path.read_text(encoding="utf-8"))
        links = [f"<a href='{_rel(res_path, root)}'>results.json</a>"]
        table = folder / "table.md"
        if table.exists():
            links.append(f"<a href='{_rel(table, root)}'>table.md</a>")
            md = table.read_text(encoding="utf-8")
            if md.startswith("# "):
                md = md.split("\n", 1)[1] if "\n" in md else ""
            parts.append(markdown_to_html(md))
        parts.append("<p>" + " · ".join(links) + "</p>")
        for png in sorted(folder.glob("*.png")):
            parts.append(f"<p><a href='{_rel(png, root)}'><img src='{_rel(png, root)}' "
                         f"alt='{html.escape(png.stem)}'></a></p>")
    parts += _fidelity(all_results)
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
    index = root / "index.html"
    _write_atomic(index, "\n".join(parts) + "\n")
    _write_atomic(
        root / "results.json",
        json.dumps({"experiments": all_results}, sort_keys=True, indent=1) + "\n",
    )
    return index
