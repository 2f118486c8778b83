"""PNG figures of an experiment's summary (matplotlib, Agg canvas, no pyplot state).

Each function takes the ``results`` dict written to ``results.json`` and the output folder,
writes its figure atomically and returns the file names written.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

__all__ = ["figure_names", "write_figures"]


def _save(fig: Figure, path: Path) -> str:
    from scenegen.io import atomic_path

    FigureCanvasAgg(fig)
    with atomic_path(path, ".png") as tmp:
        fig.savefig(tmp, dpi=100, format="png", metadata={"Software": None})
    return path.name


def _v(x: Any) -> tuple[float, float, float]:
    """(value, lo, hi) of a number or a rate/mean dict with ``ci``; NaN where missing."""
    if x is None:
        return (np.nan, np.nan, np.nan)
    if isinstance(x, dict):
        v = x.get("pct", x.get("mean"))
        lo, hi = x.get("ci", (None, None))
        f = [np.nan if a is None else float(a) for a in (v, lo, hi)]
        return (f[0], f[1], f[2])
    return (float(x), np.nan, np.nan)


def _bars(ax: Any, groups: list[str], series: dict[str, list[Any]], ylabel: str,
          paper: dict[str, list[float | None]] | None = None) -> None:
    """Grouped bars with 95% intervals; the paper's values as black diamonds."""
    n = max(len(series), 1)
    width = 0.8 / n
    x = np.arange(len(groups))
    marked = False
    for i, (label, vals) in enumerate(series.items()):
        v = np.array([_v(a) for a in vals], dtype=float).reshape(-1, 3)
        pos = x + (i - (n - 1) / 2) * width
        err = np.vstack([v[:, 0] - v[:, 1], v[:, 2] - v[:, 0]])
        ax.bar(pos, v[:, 0], width, label=label,
               yerr=np.where(np.isfinite(err), err, 0.0), capsize=2, ecolor="0.3")
        pv = (paper or {}).get(label)
        if pv is not None:
            pp = np.array([np.nan if a is None else a for a in pv], dtype=float)
            ax.plot(pos, pp, "kD", ms=5, label=None if marked else "paper")
            marked = True
    ax.set_xticks(x, groups)
    ax.set_ylabel(ylabel)
    ax.grid(axis="y", alpha=0.3)


def _fig4_methods(res: dict[str, Any]) -> list[str]:
    """The methods of ``dps-synthetic``'s Fig. 4 (first λ), none when it is not drawn."""
    methods = next(iter(res["summary"]["by_value"].values()))["methods"]
    shown = [s for s in methods if s in ("nonps", "ps-1234567", "ps-2345671", "dps")]
    return shown if shown and "uniqueness" in methods[shown[0]] else []


def _uniqueness_drawn(res: dict[str, Any]) -> bool:
    """Whether the RealSeq experiments' uniqueness figure is drawn (its first preset's
    first method has uniqueness)."""
    first = next(iter(res["summary"]["presets"].values()), {})
    labels = list(first)
    return bool(labels) and "uniqueness" in first[labels[0]]


def _dps_synthetic(res: dict[str, Any], out: Path) -> list[str]:
    from scenegen.lab.experiments.definitions import PAPER

    by = res["summary"]["by_value"]
    files = []
    v0 = next(iter(by))
    methods = by[v0]["methods"]
    shown = _fig4_methods(res)
    if shown:
        k = len(methods[shown[0]]["uniqueness"])
        objs = [str(i + 1) for i in range(k)]
        ed0 = np.asarray(methods[shown[0]].get("effective_dynamics", []), dtype=float)
        n_comp = ed0.shape[1] if ed0.ndim == 2 else (1 if ed0.size else 0)
        fig = Figure(figsize=(10, 2.6 * (1 + min(n_comp, 2))))
        axes = fig.subplots(1 + min(n_comp, 2), 1, squeeze=False)[:, 0]
        _bars(axes[0], objs, {s: methods[s]["uniqueness"] for s in shown}, "uniqueness %")
        axes[0].set_title(f"DPS Fig. 4 on our sequence (λ={v0}): per object")
        axes[0].set_ylim(0, 122)
        for c in range(min(n_comp, 2)):
            series = {}
            for s in shown:
                ed = np.asarray(methods[s]["effective_dynamics"], dtype=float)
                series[s] = (ed[:, c] if ed.ndim == 2 else ed).tolist()
            name = f"eff. dynamics {'uv'[c]} %" if n_comp > 1 else "eff. dynamics (u, v mean) %"
            _bars(axes[1 + c], objs, series, name)
        axes[-1].set_xlabel("object")
        axes[0].legend(fontsize=8, ncol=4, loc="upper center")
        fig.tight_layout()
        files.append(_save(fig, out / "fig4_uniqueness_effective_dynamics.png"))
    fig = Figure(figsize=(11, 4.5))
    ax1, ax2 = fig.subplots(1, 2)
    lams = list(by)
    t1, t2 = PAPER["dps-synthetic"]["table1"], PAPER["dps-synthetic"]["table2"]
    rec: dict[str, list[Any]] = {k: [] for k in ("Non-PS", "PS mean", "PS worst", "DPS")}
    succ: dict[str, list[Any]] = {"Non-PS": [], "PS mean": [], "DPS": []}
    prec = {k: [] for k in rec}
    psucc = {k: [] for k in succ}
    for v in lams:
        row = by[v]
        m = row["methods"]
        p2, p1 = t2.get(float(v)), t1.get(float(v))
        rec["Non-PS"].append(m["nonps"]["hard"]["recovery"] if "nonps" in m else None)
        rec["PS mean"].append(row["ps_mean"]["hard"]["recovery"] if "ps_mean" in row else None)
        rec["PS worst"].append(row["ps_worst"]["recovery"] if "ps_worst" in row else None)
        rec["DPS"].append(m["dps"]["hard"]["recovery"] if "dps" in m else None)
        succ["Non-PS"].append(m["nonps"]["others"]["success"] if "nonps" in m else None)
        succ["PS mean"].append(row["ps_mean"]["others"]["success"] if "ps_mean" in row else None)
        succ["DPS"].append(m["dps"]["others"]["success"] if "dps" in m else None)
        for i, k in enumerate(prec):
            prec[k].append(p2["recovery"][i] if p2 else None)
        for i, k in enumerate(psucc):
            psucc[k].append(p1["success"][i] if p1 else None)
    groups = [f"λ={v}" for v in lams]
    _bars(ax1, groups, rec, "recovery rate %", prec)
    ax1.set_title("object 1 (distracted): recovery")
    _bars(ax2, groups, succ, "success rate %", psucc)
    ax2.set_title("objects 2–7: success")
    for ax in (ax1, ax2):
        ax.set_ylim(0, 122)
        ax.legend(fontsize=8, ncol=5, loc="upper center")
    fig.tight_layout()
    files.append(_save(fig, out / "success_recovery.png"))
    return files


def _dps_real(res: dict[str, Any], out: Path) -> list[str]:
    from scenegen.lab.experiments.definitions import PAPER

    presets = res["summary"]["presets"]
    paper_all = PAPER[res["experiment"]]
    fig = Figure(figsize=(11, 4 * len(presets)))
    axes = fig.subplots(len(presets), 1, squeeze=False)[:, 0]
    for ax, (preset, rows) in zip(axes, presets.items(), strict=True):
        labels = list(rows)
        paper = paper_all.get(preset, {})
        _bars(ax, labels, {
            "success": [rows[m]["hard"]["success"] for m in labels],
            "recovery": [rows[m]["hard"]["recovery"] for m in labels],
        }, "% of runs", {
            "success": [paper[m][0] if m in paper else None for m in labels],
            "recovery": [paper[m][1] if m in paper else None for m in labels],
        })
        ax.set_title(f"{preset}: occluded object ({res['summary']['hard_target']}) — success "
                     "and recovery, 95% intervals; ◆ paper")
        ax.set_ylim(0, 118)
        ax.legend(fontsize=8, ncol=3, loc="upper center")
    fig.tight_layout()
    files = [_save(fig, out / "success_recovery.png")]
    first = next(iter(presets.values()), {})
    labels = list(first)
    if _uniqueness_drawn(res):
        fig = Figure(figsize=(10, 4))
        ax = fig.subplots()
        k = len(first[labels[0]]["uniqueness"])
        _bars(ax, [str(i + 1) for i in range(k)],
              {m: first[m]["uniqueness"] for m in labels if "uniqueness" in first[m]},
              "uniqueness %")
        ax.set_xlabel("object")
        ax.set_title(f"{next(iter(presets))}: uniqueness per object (DPS Fig. 8)")
        ax.set_ylim(0, 122)
        ax.legend(fontsize=8, ncol=len(labels), loc="upper center")
        fig.tight_layout()
        files.append(_save(fig, out / "uniqueness.png"))
    return files


def _kams_accuracy(res: dict[str, Any], out: Path) -> list[str]:
    from scenegen.lab.experiments.definitions import PAPER

    methods = res["summary"]["methods"]
    presets = _kams_presets(res)
    if not presets:
        return []
    fig = Figure(figsize=(12, 8))
    axes = fig.subplots(2, 2, squeeze=False).ravel()
    for ax, preset in zip(axes, presets, strict=False):
        threshold = None
        for label, per in methods.items():
            if preset in per:
                e = np.array([np.nan if x is None else x for x in per[preset]["error_per_frame"]])
                line = ax.plot(np.arange(1, e.size + 1), e, label=label, lw=1.2)
                threshold = per[preset]["failure_threshold"]
                pv = PAPER["kams-accuracy"].get(label)
                if pv is not None and pv[presets.index(preset)] is not None:
                    ax.axhline(pv[presets.index(preset)], color=line[0].get_color(), ls="--",
                               lw=0.8, label=f"{label} paper mean")
        if threshold is not None:
            ax.axhline(threshold, color="k", ls=":", lw=1, label="failure threshold")
        ax.set_title(preset)
        ax.set_xlabel("frame")
        ax.set_ylabel(f"error px vs {res['summary']['error_against']} (mean of runs)")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    return [_save(fig, out / "centre_error.png")]


def _kams_presets(res: dict[str, Any]) -> list[str]:
    """The presets of ``kams-accuracy``'s error figure (one panel each), sorted."""
    return sorted({p for v in res["summary"]["methods"].values() for p in v})


def _shm_records(records: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The SHM runs the ordering-probability figure draws from (none: not drawn)."""
    return [r for r in records if "order_prob" in r]


def _kams_robustness(res: dict[str, Any], out: Path) -> list[str]:
    from scenegen.lab.experiments.definitions import PAPER

    pairs = res["summary"]["pairs"]
    if not pairs:
        return []
    labels = list(pairs)
    fig = Figure(figsize=(8, 4))
    ax = fig.subplots()
    _bars(ax, labels, {"ours": [pairs[m]["z"] for m in labels]}, "McNemar z (KAMS vs …)",
          {"ours": [PAPER["kams-robustness"].get(m) for m in labels]})
    ax.axhline(2.576, color="k", ls=":", lw=1, label="99.5%")
    ax.legend(fontsize=8)
    ax.set_title("robustness of KAMS against each tracker")
    fig.tight_layout()
    return [_save(fig, out / "robustness_z.png")]


def _shm_depth(res: dict[str, Any], out: Path, records: list[dict[str, Any]]) -> list[str]:
    shm = _shm_records(records)
    if not shm:
        return []
    slugs = sorted({r["key"]["method"] for r in shm})
    fig = Figure(figsize=(10, 2.8 * len(slugs)))
    axes = fig.subplots(len(slugs), 1, squeeze=False)[:, 0]
    for ax, slug in zip(axes, slugs, strict=True):
        rec = min((r for r in shm if r["key"]["method"] == slug),
                  key=lambda r: (r["key"]["preset"] != "shm-clutter", r["key"]["scene"]))
        p = np.array([[np.nan if x is None else x for x in row] for row in rec["order_prob"]])
        t = np.arange(p.shape[0])
        for j in range(p.shape[1]):
            order = "-".join(str(i + 1) for i in rec["orderings"][j])
            ax.plot(t, p[:, j], lw=1.2, label=f"P(order {order})")
        true = np.array(rec["true_order"])
        overlap = np.array(rec["overlap"], dtype=bool)
        ax.fill_between(t, 0, 1, where=overlap, color="grey", alpha=0.2, step="mid",
                        label="targets overlap")
        ax.step(t, np.where(true == 0, 1.02, -0.02), where="mid", color="k", lw=0.8,
                label="true order 1 (top) / other (bottom)")
        ax.set_ylim(-0.05, 1.05)
        ax.set_ylabel("probability")
        ax.set_title(f"{slug} on {rec['key']['preset']}: ordering probability over time "
                     f"(scene {rec['key']['scene']})")
        ax.legend(fontsize=7, loc="upper right")
    axes[-1].set_xlabel("frame")
    fig.tight_layout()
    return [_save(fig, out / "ordering_probability.png")]


def figure_names(name: str, results: dict[str, Any], records: list[dict[str, Any]]
                 ) -> list[str]:  # fmt: skip
    """The file names :func:`write_figures` writes for these results, without drawing
    (``scenegen validate`` checks that each is there and a whole PNG image).

    Parameters
    ----------
    name : str
        The experiment.
    results : dict
        Its summary, as written to ``results.json``.
    records : list of dict
        The run records.

    Returns
    -------
    list of str
        File names relative to the experiment folder, in the order they are written.
    """
    if name == "dps-synthetic":
        return (["fig4_uniqueness_effective_dynamics.png"] if _fig4_methods(results)
                else []) + ["success_recovery.png"]  # fmt: skip
    if name in ("dps-occlusion", "dps-dancers"):
        return ["success_recovery.png"] + (["uniqueness.png"] if _uniqueness_drawn(results)
                                           else [])  # fmt: skip
    if name == "kams-accuracy":
        return ["centre_error.png"] if _kams_presets(results) else []
    if name == "kams-robustness":
        return ["robustness_z.png"] if results["summary"]["pairs"] else []
    return ["ordering_probability.png"] if _shm_records(records) else []


def write_figures(name: str, results: dict[str, Any], records: list[dict[str, Any]],
                  out: Path) -> list[str]:
    """Write the PNG figures of experiment ``name`` into ``out``; return their file names.

    Parameters
    ----------
    name : str
        The experiment (:func:`scenegen.lab.experiments.definitions.names`); a name other
        than the DPS and KAMS ones gets the SHM depth-ordering figure.
    results : dict
        The experiment's summary, as written to ``results.json``.
    records : list of dict
        The run records (used by the SHM figure only).
    out : pathlib.Path
        The output folder; each figure is written atomically.

    Returns
    -------
    list of str
        The file names written (e.g. ``"success_recovery.png"``), relative to ``out``.
    """
    if name == "dps-synthetic":
        return _dps_synthetic(results, out)
    if name in ("dps-occlusion", "dps-dancers"):
        return _dps_real(results, out)
    if name == "kams-accuracy":
        return _kams_accuracy(results, out)
    if name == "kams-robustness":
        return _kams_robustness(results, out)
    return _shm_depth(results, out, records)
