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

__all__ = ["write_figures"]


def _save(fig: Figure, path: Path) -> str:
    from scenegen.io import atomic_path

    FigureCanvasAgg(fig)
    with atomic_path(path, ".png") as tmp:
        fig.savefig(tmp, dpi=100, format="png", metadata={"Software": None})
    return path.name


def _bars(ax: Any, groups: list[str], series: dict[str, list[float | None]], ylabel: str) -> None:
    n = max(len(series), 1)
    width = 0.8 / n
    x = np.arange(len(groups))
    for i, (label, vals) in enumerate(series.items()):
        v = np.array([np.nan if a is None else a for a in vals], dtype=float)
        ax.bar(x + (i - (n - 1) / 2) * width, v, width, label=label)
    ax.set_xticks(x, groups)
    ax.set_ylabel(ylabel)
    ax.grid(axis="y", alpha=0.3)


def _dps_synthetic(res: dict[str, Any], out: Path) -> list[str]:
    by = res["summary"]["by_value"]
    files = []
    v0 = next(iter(by))
    methods = by[v0]["methods"]
    shown = [s for s in methods if s in ("nonps", "ps-1234567", "ps-2345671", "dps")]
    if shown and "uniqueness" in methods[shown[0]]:
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
    fig = Figure(figsize=(10, 4))
    ax1, ax2 = fig.subplots(1, 2)
    lams = list(by)
    labels = {"nonps": "Non-PS", "ps_mean": "PS mean", "ps_worst": "PS worst", "dps": "DPS"}
    rec: dict[str, list[float | None]] = {lab: [] for lab in labels.values()}
    succ: dict[str, list[float | None]] = {"Non-PS": [], "PS mean": [], "DPS": []}
    for v in lams:
        row = by[v]
        m = row["methods"]
        rec["Non-PS"].append(m["nonps"]["hard"]["recovery"] if "nonps" in m else None)
        rec["PS mean"].append(row["ps_mean"]["hard"]["recovery"] if "ps_mean" in row else None)
        rec["PS worst"].append(row["ps_worst"]["recovery"] if "ps_worst" in row else None)
        rec["DPS"].append(m["dps"]["hard"]["recovery"] if "dps" in m else None)
        succ["Non-PS"].append(m["nonps"]["others"]["success"] if "nonps" in m else None)
        succ["PS mean"].append(row["ps_mean"]["others"]["success"] if "ps_mean" in row else None)
        succ["DPS"].append(m["dps"]["others"]["success"] if "dps" in m else None)
    groups = [f"λ={v}" for v in lams]
    _bars(ax1, groups, rec, "recovery rate %")
    ax1.set_title("object 1 (distracted): recovery")
    _bars(ax2, groups, succ, "success rate %")
    ax2.set_title("objects 2–7: success")
    for ax in (ax1, ax2):
        ax.set_ylim(0, 122)
        ax.legend(fontsize=8, ncol=4, loc="upper center")
    fig.tight_layout()
    files.append(_save(fig, out / "success_recovery.png"))
    return files


def _dps_occlusion(res: dict[str, Any], out: Path) -> list[str]:
    rows = res["summary"]["methods"]
    labels = list(rows)
    fig = Figure(figsize=(9, 4))
    ax = fig.subplots()
    _bars(ax, labels, {
        "success": [rows[m]["hard"]["success"] for m in labels],
        "recovery": [rows[m]["hard"]["recovery"] for m in labels],
    }, "% of runs")
    ax.set_title(f"occluded object ({res['summary']['hard_target']}): success and recovery")
    ax.set_ylim(0, 115)
    ax.legend(fontsize=8, ncol=2, loc="upper center")
    fig.tight_layout()
    files = [_save(fig, out / "success_recovery.png")]
    if labels and "uniqueness" in rows[labels[0]]:
        fig = Figure(figsize=(9, 4))
        ax = fig.subplots()
        k = len(rows[labels[0]]["uniqueness"])
        _bars(ax, [str(i + 1) for i in range(k)],
              {m: rows[m]["uniqueness"] for m in labels if "uniqueness" in rows[m]},
              "uniqueness %")
        ax.set_xlabel("object")
        ax.set_title("uniqueness per object (DPS Fig. 8)")
        ax.set_ylim(0, 122)
        ax.legend(fontsize=8, ncol=len(labels), loc="upper center")
        fig.tight_layout()
        files.append(_save(fig, out / "uniqueness.png"))
    return files


def _kams_accuracy(res: dict[str, Any], out: Path) -> list[str]:
    methods = res["summary"]["methods"]
    presets = sorted({p for v in methods.values() for p in v})
    if not presets:
        return []
    fig = Figure(figsize=(11, 7))
    axes = fig.subplots(2, 2, squeeze=False).ravel()
    for ax, preset in zip(axes, presets, strict=False):
        threshold = None
        for label, per in methods.items():
            if preset in per:
                e = np.array([np.nan if x is None else x for x in per[preset]["error_per_frame"]])
                ax.plot(np.arange(e.size), e, label=label, lw=1.2)
                threshold = per[preset]["failure_threshold"]
        if threshold is not None:
            ax.axhline(threshold, color="k", ls=":", lw=1, label="failure threshold")
        ax.set_title(preset)
        ax.set_xlabel("frame")
        ax.set_ylabel("centre error px (mean over runs)")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    return [_save(fig, out / "centre_error.png")]


def _kams_robustness(res: dict[str, Any], out: Path) -> list[str]:
    from scenegen.lab.experiments.definitions import PAPER

    pairs = res["summary"]["pairs"]
    if not pairs:
        return []
    labels = list(pairs)
    fig = Figure(figsize=(8, 4))
    ax = fig.subplots()
    _bars(ax, labels, {
        "ours": [pairs[m]["z"] for m in labels],
        "paper": [PAPER["kams-robustness"].get(m) for m in labels],
    }, "McNemar z (KAMS vs …)")
    ax.axhline(2.576, color="k", ls=":", lw=1, label="99.5%")
    ax.legend(fontsize=8)
    ax.set_title("robustness of KAMS against each tracker")
    fig.tight_layout()
    return [_save(fig, out / "robustness_z.png")]


def _shm_depth(res: dict[str, Any], out: Path, records: list[dict[str, Any]]) -> list[str]:
    shm = [r for r in records if "order_prob" in r]
    if not shm:
        return []
    slugs = sorted({r["key"]["method"] for r in shm})
    fig = Figure(figsize=(10, 2.8 * len(slugs)))
    axes = fig.subplots(len(slugs), 1, squeeze=False)[:, 0]
    for ax, slug in zip(axes, slugs, strict=True):
        rec = min((r for r in shm if r["key"]["method"] == slug), key=lambda r: r["key"]["run"])
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
        ax.set_title(f"{slug}: ordering probability over time (run {rec['key']['run']})")
        ax.legend(fontsize=7, loc="upper right")
    axes[-1].set_xlabel("frame")
    fig.tight_layout()
    return [_save(fig, out / "ordering_probability.png")]


def write_figures(name: str, results: dict[str, Any], records: list[dict[str, Any]],
                  out: Path) -> list[str]:
    """Write the PNG figures of experiment ``name`` into ``out``; return their file names."""
    if name == "dps-synthetic":
        return _dps_synthetic(results, out)
    if name == "dps-occlusion":
        return _dps_occlusion(results, out)
    if name == "kams-accuracy":
        return _kams_accuracy(results, out)
    if name == "kams-robustness":
        return _kams_robustness(results, out)
    return _shm_depth(results, out, records)
