"""Whether a scene decides who loses the walker: paired outcomes of the methods.

Usage (on one or more folders written by ``scenegen experiment dps-occlusion``)::

    python tools/occlusion/independence.py DIR [DIR ...]

With several folders (e.g. two base seeds of the same scene version) their scenes are
pooled: a scene is then (folder, scene), and every measure below is over all of them.

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
  DPS's success and the orderings' mean;
- DPS's lead over the PS orderings pooled, with the experiment's scene-paired bootstrap
  (``stats.bootstrap_clustered_diff``, seeded with 0): the effect in points, its 95 %
  interval and the one-sided p of DPS above PS (with one folder, the experiment's own
  claim up to the bootstrap's seed);
- the scene x method interaction: DPS's lead over the PS orderings pooled, per scene,
  its variance over the scenes and its largest value, each with a permutation p-value
  (DPS's and the orderings' outcomes of a scene shuffled within that scene, 4,000
  times, seeded). A small p says that on some scenes DPS leads far more than on
  others, as the paper's one-sequence gap would need; a large p says the lead is the
  same on every scene up to chance;
- with ``--power K``: how often that test (the largest lead, p < 0.05) would flag K
  scenes planted with the paper's RealSeq1 rates (DPS keeps the walker in every run,
  each PS ordering in 31 %, the mean of its 18 / 40 / 34 %) in place of K of this
  folder's scenes chosen at random, over 200 trials.

docs/experiments.md ("The re-tuned `dps-occlusion-2` on the same 30 scenes" and "Is there
a scene on which DPS leads?") used it.
"""

from __future__ import annotations

import argparse
import glob
from collections import defaultdict
from pathlib import Path

import numpy as np

from scenegen.lab.experiments import stats
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


Runs = dict[str, dict[tuple[object, int], bool]]
"""One preset's outcomes: method label -> (scene, run) -> the walker kept."""


def pooled(folders: list[str | Path]) -> dict[str, Runs]:
    """:func:`outcomes` of several folders, each scene keyed ``(i, scene)`` by the folder's
    place ``i`` in ``folders`` (one folder: its own keys). Only presets and methods that
    every folder has are kept."""
    if len(folders) == 1:
        return outcomes(folders[0])  # type: ignore[return-value]
    each = [outcomes(f) for f in folders]
    out: dict[str, Runs] = {}
    for preset in sorted(set.intersection(*(set(e) for e in each))):
        labels = set.intersection(*(set(e[preset]) for e in each))
        out[preset] = {lb: {((i, sc), r): v for i, e in enumerate(each)
                            for (sc, r), v in e[preset][lb].items()}
                       for lb in sorted(labels)}  # fmt: skip
    return out


def lead(runs: Runs, rng: np.random.Generator | int = 0) -> tuple[float, tuple[float, float],
                                                                  float] | None:
    """DPS's success minus the PS orderings' pooled, in points, over paired scenes.

    Parameters
    ----------
    runs : dict
        One preset's outcomes (:func:`outcomes` or :func:`pooled`); labels ``DPS`` and
        ``PS(…)`` are used.
    rng : numpy.random.Generator or int, optional
        The bootstrap's randomness.

    Returns
    -------
    (float, (float, float), float) or None
        The mean over scenes of the per-scene difference, its 95 % interval and the
        one-sided p of DPS above PS (``stats.bootstrap_clustered_diff``); None without DPS
        or a PS ordering.
    """
    ps = [lb for lb in runs if lb.startswith("PS(")]
    if "DPS" not in runs or not ps:
        return None
    by_dps: dict[object, list[float]] = defaultdict(list)
    by_ps: dict[object, list[float]] = defaultdict(list)
    for (sc, _), v in sorted(runs["DPS"].items()):
        by_dps[sc].append(100.0 * v)
    for lb in ps:
        for (sc, _), v in sorted(runs[lb].items()):
            by_ps[sc].append(100.0 * v)
    mean, ci, test = stats.bootstrap_clustered_diff(by_dps, by_ps, rng)
    return float(mean), (float(ci[0]), float(ci[1])), float(test.p_value)


def summary(runs: Runs) -> dict[str, object]:
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


def interaction(runs: Runs, n_perm: int = 4000,
                rng: np.random.Generator | int | None = 0) -> dict[str, object] | None:
    """Whether DPS's lead over the PS orderings pooled differs between scenes.

    Parameters
    ----------
    runs : dict
        :func:`outcomes`' entry of one preset (label -> (scene, run) -> success); the
        labels ``DPS`` and ``PS(…)`` are used.
    n_perm : int, optional
        Permutations of the null distribution.
    rng : numpy.random.Generator, int or None, optional
        The permutations' randomness (seeded by default: the same folder, the same p).

    Returns
    -------
    dict or None
        ``lead`` (S,) per-scene DPS − PS pooled success; ``var`` and ``max`` of it, with
        ``p_var`` and ``p_max``, the share of permutations at least as large; ``argmax``,
        the scene of the largest lead. None without DPS or a PS ordering.
    """
    ps = [lb for lb in runs if lb.startswith("PS(")]
    if "DPS" not in runs or not ps:
        return None
    gen = np.random.default_rng(rng)
    scenes = sorted({s for s, _ in runs["DPS"]} & set.intersection(
        *({s for s, _ in runs[lb]} for lb in ps)))
    lead, null = [], []
    for s in scenes:
        d = np.array([v for (sc, _), v in sorted(runs["DPS"].items()) if sc == s], float)
        p = np.array([v for lb in ps for (sc, _), v in sorted(runs[lb].items()) if sc == s],
                     float)  # fmt: skip
        lead.append(d.mean() - p.mean())
        both = gen.permuted(np.tile(np.concatenate([d, p]), (n_perm, 1)), axis=1)
        null.append(both[:, :d.size].mean(axis=1) - both[:, d.size:].mean(axis=1))
    lead_a, null_a = np.array(lead), np.array(null)  # (S,), (S, n_perm)
    var, nvar = lead_a.var(), null_a.var(axis=0)
    top, ntop = lead_a.max(), null_a.max(axis=0)
    return {"lead": lead_a, "var": float(var), "p_var": float(np.mean(nvar >= var - 1e-12)),
            "max": float(top), "p_max": float(np.mean(ntop >= top - 1e-12)),
            "argmax": scenes[int(lead_a.argmax())]}  # fmt: skip


#: The paper's RealSeq1 success (Table 3): DPS, and the mean of the three PS orderings.
PAPER_DPS, PAPER_PS = 1.0, (0.18 + 0.40 + 0.34) / 3


def power(runs: Runs, k: int, trials: int = 200,
          n_perm: int = 1000, rng: np.random.Generator | int | None = 0) -> float:
    """Share of trials in which :func:`interaction` flags (``p_max`` < 0.05) ``k`` scenes
    replaced by draws at the paper's RealSeq1 rates (``PAPER_DPS``, ``PAPER_PS``).

    Parameters
    ----------
    runs : dict
        :func:`outcomes`' entry of one preset.
    k : int
        Planted scenes per trial (at most the number of scenes).
    trials, n_perm : int, optional
        Trials, and permutations of each trial's test.
    rng : numpy.random.Generator, int or None, optional
        The planting and the permutations' randomness.

    Returns
    -------
    float
        The detection rate, in [0, 1].
    """
    gen = np.random.default_rng(rng)
    ps = [lb for lb in runs if lb.startswith("PS(")]
    scenes = sorted({s for s, _ in runs["DPS"]})
    if not 0 < k <= len(scenes):
        raise ValueError(f"--power {k}: between 1 and the {len(scenes)} scenes")
    hits = 0
    for _ in range(trials):
        planted = {scenes[i] for i in gen.choice(len(scenes), k, replace=False).tolist()}
        trial = {lb: dict(v) for lb, v in runs.items()}
        for lb, rate in [("DPS", PAPER_DPS)] + [(lb, PAPER_PS) for lb in ps]:
            for key in sorted(trial[lb]):
                if key[0] in planted:
                    trial[lb][key] = bool(gen.random() < rate)
        hits += interaction(trial, n_perm=n_perm, rng=gen)["p_max"] < 0.05
    return hits / trials


def _scene(key: object, folders: list[str]) -> str:
    """A scene key as printed: ``scene 5``, or ``scene 5 of FOLDER`` when pooled."""
    if isinstance(key, tuple):
        return f"scene {key[1]} of {folders[key[0]]}"
    return f"scene {key}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", nargs="+",
                    help="folders of `scenegen experiment dps-occlusion` (several: pooled)")
    ap.add_argument("--power", type=int, metavar="K", default=0,
                    help="also print how often K planted paper-like scenes are flagged")
    args = ap.parse_args()
    order = [m.label for m in get(EXPERIMENT).methods]
    if len(args.folder) > 1:
        print(f"pooled over {len(args.folder)} folders: " + ", ".join(args.folder))
    for preset, runs in sorted(pooled(args.folder).items()):
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
        ld = lead(runs)
        if ld is not None:
            print(f"  DPS - PS pooled: {ld[0]:+.1f} points [{ld[1][0]:+.1f}, {ld[1][1]:+.1f}], "
                  f"one-sided p {ld[2]:.2f}")
        it = interaction(runs)
        if it is not None:
            print(f"  DPS's lead per scene: variance {it['var']:.4f} (permutation p "
                  f"{it['p_var']:.2f}), largest {100 * it['max']:+.0f} points on "
                  f"{_scene(it['argmax'], args.folder)} (p {it['p_max']:.2f})")
            if args.power:
                print(f"  {args.power} planted paper-like scene(s) flagged in "
                      f"{100 * power(runs, args.power):.0f} % of 200 trials")


if __name__ == "__main__":
    main()
