"""``table.md`` of an experiment: our tables beside the paper's, the claims and their tests,
the paper's numbers that differ from ours, and one paragraph on where and why we differ."""

from __future__ import annotations

from typing import Any

from scenegen.lab.experiments.definitions import Experiment
from scenegen.lab.experiments.outputs import WRITTEN_BY, versions_text
from scenegen.lab.experiments.stats import ALPHA, LEVEL, MIN_RUNS
from scenegen.lab.experiments.summary import AGREE_POINTS, AGREE_PX, table_lines

__all__ = ["VERDICT_RULE", "render_table", "verdict_counts"]

VERDICT_RULE = (
    f"Each claim is tested one-sided in the paper's direction at α = {ALPHA:g}: "
    "**reproduced** if p < α; **not reproduced** if not, and our "
    f"{LEVEL:.0%} interval for the effect lies below the effect of interest (an effect that "
    f"large is ruled out) or below 0, with at least {MIN_RUNS} runs per compared arm; "
    "**inconclusive** otherwise (too few runs to tell)."
)


def verdict_counts(results: dict[str, Any]) -> dict[str, int]:
    """How many claims got each verdict.

    Parameters
    ----------
    results : dict
        The content of ``results.json`` (its ``claims``; none: every count 0).

    Returns
    -------
    dict of str to int
        Counts keyed by ``"reproduced"``, ``"not reproduced"`` and ``"inconclusive"``.

    Examples
    --------
    >>> verdict_counts({"claims": [{"verdict": "reproduced"}]})
    {'reproduced': 1, 'not reproduced': 0, 'inconclusive': 0}
    """
    out = {"reproduced": 0, "not reproduced": 0, "inconclusive": 0}
    for c in results.get("claims", []):
        out[c["verdict"]] += 1
    return out


def _num(v: Any, digits: int = 1) -> str:
    if v is None:
        return "–"
    if isinstance(v, float):
        return f"{v:.3f}" if abs(v) < 1 and v != 0 else f"{v:.{digits}f}"
    return str(v)


def _p(p: float) -> str:
    return "< 0.001" if p < 1e-3 else f"{p:.3f}"


def claims_table(results: dict[str, Any]) -> list[str]:
    """The claims as a Markdown table."""
    claims = results.get("claims", [])
    if not claims:
        return ["No claim could be tested (methods missing)."]
    lines = ["| claim | ours | test | p | effect [95% interval] | of interest | verdict |",
             "|---|---|---|---|---|---|---|"]
    for c in claims:
        lo, hi = c["interval"]
        v = c["verdict"]
        lines.append(
            f"| {_cell(c['claim'])} | {_cell(c['ours'])} | {_cell(c['test'])} | "
            f"{_p(c['p_value'])} | "
            f"{_num(c['effect'])} [{_num(lo)}, {_num(hi)}] | {_num(c['delta'])} "
            f"({c['delta_source']}) | {'**' + v + '**' if v != 'reproduced' else v} |")
    return lines


def _cell(text: Any) -> str:
    """Text for a Markdown table cell: a ``|`` in it (``|P − 1/L|``) escaped, so that it
    does not split the cell."""
    return str(text).replace("|", "\\|")


def render_table(exp: Experiment, results: dict[str, Any], why: str = "") -> str:
    """``table.md``: our tables beside the paper's, the claims, the numbers that differ.

    Parameters
    ----------
    exp : Experiment
        The experiment the results belong to.
    results : dict
        The content of ``results.json``.
    why : str, default ""
        The "where we differ and why" paragraph (empty: none is printed).

    Returns
    -------
    str
        The Markdown text, ending with a newline.
    """
    s, r = results["scenes"], results["runs"]
    per = "method, λ and preset" if exp.sweep else "method and preset"
    lines = [
        f"# {exp.name}: {exp.title}",
        "",
        f"S = {s} scenes x R = {r} tracker runs per scene ({s * r} runs per {per}); base "
        f"seed {results['seed']}; "
        + ("QUICK mode (fewer frames or particles: not comparable with the paper)."
           if results["quick"] else "full settings."),
    ]
    if results.get("indicative"):
        lines += ["", "**Indicative only**: fewer runs than the experiment's defaults "
                  f"(S = {exp.scenes}, R = {exp.runs}); the verdicts below may change with "
                  "the full run, `scenegen experiment all -o out/`."]
    lines += ["", "Intervals: Wilson for rates, seeded percentile bootstrap for means; frame 0 "
              "is excluded from every measure.", ""]
    who = results.get(WRITTEN_BY)
    if who:  # provenance (absent in results written by older versions)
        lines[-1:-1] = ["", f"Computed with {versions_text(who)}."]
    lines += table_lines(exp, results)
    lines += ["", "## The paper's claims", "", VERDICT_RULE, ""]
    lines += claims_table(results)
    comps = results.get("comparisons", [])
    lines += ["", "## The paper's numbers", ""]
    if comps:
        inside = sum(c["inside_interval"] for c in comps)
        agree = sum(c["agree"] for c in comps)
        lines.append(
            f"{agree} of {len(comps)} numbers the paper prints agree with ours ({inside} inside "
            f"our 95% interval, {agree - inside} more within the tolerance: {AGREE_POINTS:g} "
            f"points for rates, {AGREE_PX:g} px or 25% for errors).")
        differ = [c for c in comps if not c["agree"]]
        if differ:
            lines += ["", "| differs | paper | ours [95% interval] |", "|---|---|---|"]
            for c in differ:
                lo, hi = c["interval"]
                lines.append(f"| {c['what']} | {_num(c['paper'])} | {_num(c['ours'])} "
                             f"[{_num(lo)}, {_num(hi)}] |")
    else:
        lines.append("The paper prints no numbers for this experiment; only its claims are "
                     "tested.")
    if why:
        lines += ["", "## Where we differ and why", "",
                  "(Numbers of the full run, `scenegen experiment all`, base seed 0, default "
                  "S x R.) " + why]
    return "\n".join(lines) + "\n"
