"""Whether a scene decides who loses the walker: paired outcomes of the methods.

Usage (on a folder written by ``scenegen experiment dps-occlusion``)::

    python tools/occlusion/independence.py DIR

For every preset it prints, from the runs in ``DIR/runs/`` (a run *succeeds* when the
walker is tracked in every frame but frame 0, the experiment's success):

- each method's success rate;
- φ, the correlation of two methods' outcomes over the same (scene, run) pairs, smallest
  and largest over the pairs of methods (near 0: each method loses the walker by its own
  chances, whatever the other did on that scene and tracker seed);
- the scenes' spread: the variance of the per-scene success (all methods and runs of a
  scene pooled) over the variance a binomial of the same mean would give (1: the scenes
  are alike; above 1: some scenes are harder), and the smallest and largest per-scene
  success;
- ``any``: the success a DPS would have if it kept the walker whenever one of its PS
  orderings did, were the orderings' outcomes independent, 1 − Π (1 − p_o); beside it
  DPS's success and the orderings' mean.

docs/experiments.md ("The re-tuned `dps-occlusion-2` on the same 30 scenes") used it.
"""

from __future__ import annotations

import argparse
import glob
from collections import defaultdict
from pathlib import Path

import numpy as np

from scenegen.lab.experiments.definitions import get
from scenegen.lab.experiments.outputs import read_record
from scenegen.lab.experiments.summary import drop_first_frame, succeeded

EXPERIMENT = "dps-occlusion"


def outcomes(folder: str | Path) -> dict[str, dict[str, dict[tuple[int, int], bool]]]:
    """Per preset and method label: the walker's success per (scene, run)."""
    exp = get(EXPERIMENT)
    labels = {m.slug: m.label for m in exp.methods}
    out: dict[str, dict[str, dict[tuple[int, int], bool]]] = defaultdict(dict)
    for path in sorted(glob.glob(str(Path(folder) / "runs" / "*.json"))):
        rec = drop_first_frame(read_record(path))  # a damaged record: one DataError line
        key = rec["key"]
        walker = next(t for t in rec["targets"] if t["name"] == exp.hard_target)
        cases = out[key["preset"]].setdefault(labels[key["method"]], {})
        cases[(key["scene"], key["run"])] = succeeded(walker)  # the experiment's success
    return dict(out)


def summary(runs: dict[str, dict[tuple[int, int], bool]]) -> dict[str, object]:
    """The printed measures of one preset (see the module docstring), from
    :func:`outcomes`' entry. Only (scene, run) pairs every method ran are used."""
    labels = list(runs)
    pairs = sorted(set.intersection(*(set(r) for r in runs.values())))
    m = np.array([[runs[lb][p] for p in pairs] for lb in labels], dtype=np.float64)
    rate = dict(zip(labels, m.mean(axis=1), strict=True))
    phis = []
    for i in range(len(labels)):
        for j in range(i + 1, len(labels)):
            if m[i].std() > 0 and m[j].std() > 0:
                phis.append(float(np.corrcoef(m[i], m[j])[0, 1]))
    scenes = sorted({s for s, _ in pairs})
    per = np.array([m[:, [k for k, p in enumerate(pairs) if p[0] == s]].mean() for s in scenes])
    n = m.shape[0] * len(pairs) / len(scenes)
    mean = float(per.mean())
    binom = mean * (1 - mean) / n
    spread = float(per.var(ddof=1) / binom) if len(scenes) > 1 and binom > 0 else float("nan")
    ps = [lb for lb in labels if lb.startswith("PS(")]
    anyone = 1 - float(np.prod([1 - rate[lb] for lb in ps])) if ps else float("nan")
    return {"rate": rate, "phi": (min(phis), max(phis)) if phis else None,
            "spread": spread, "scene_range": (float(per.min()), float(per.max())),
            "any": anyone, "dps": rate.get("DPS"),
            "ps_mean": float(np.mean([rate[lb] for lb in ps])) if ps else None,
            "pairs": len(pairs), "scenes": len(scenes)}  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", help="a folder of `scenegen experiment dps-occlusion`")
    args = ap.parse_args()
    order = [m.label for m in get(EXPERIMENT).methods]
    for preset, runs in sorted(outcomes(args.folder).items()):
        runs = {lb: runs[lb] for lb in order if lb in runs}
        s = summary(runs)
        rates = ", ".join(f"{lb} {100 * r:.0f} %" for lb, r in s["rate"].items())
        print(f"{preset}: {s['scenes']} scenes, {s['pairs']} (scene, run) pairs; {rates}")
        if s["phi"] is not None:
            print(f"  phi between two methods: {s['phi'][0]:+.2f} to {s['phi'][1]:+.2f}")
        lo, hi = s["scene_range"]
        spread = (f"variance {s['spread']:.1f} x the binomial's" if np.isfinite(s["spread"])
                  else "no variance to compare (one scene, or every run alike)")
        print(f"  per-scene success {100 * lo:.0f}-{100 * hi:.0f} %, {spread}")
        if s["dps"] is not None and s["ps_mean"] is not None:
            print(f"  any ordering keeps it: {100 * s['any']:.1f} %; DPS {100 * s['dps']:.0f} %;"
                  f" orderings' mean {100 * s['ps_mean']:.0f} %")  # fmt: skip


if __name__ == "__main__":
    main()
