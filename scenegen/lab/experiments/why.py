"""The "where we differ and why" paragraph of each experiment's ``table.md``.

Written from the measured results of the full run (``scenegen experiment all``, base seed
0, default S x R); each paragraph names the numbers it explains, so a rerun that changes
them shows up in review.
"""

from __future__ import annotations

__all__ = ["WHY"]

WHY: dict[str, str] = {
    "dps-synthetic": (
        "With the papers' weighted resampling (each stage weighted by its own object's "
        "likelihood, ρ ∝ π g: the `stage` weighting) the ordering matters as in the paper: "
        "object 1 is recovered in 46–88 % of runs by ordering (Cochran's Q p ≤ 0.001 at "
        "every λ), 53–65 % when sampled in the first four stages and 76–83 % in the last "
        "three. DPS recovers it in 76–92 %, above the PS orderings pooled (64–75 %) at "
        "λ = 30, 40, 50 (scene-paired bootstrap p = 0.040, 0.005, 0.001; λ = 20: p = 0.053). "
        "Our levels are higher than the paper's (PS 18–21 %, DPS 34–42 %) and Non-PS is "
        "not below PS (64–80 %, paper 0–2 %): our distractor takes object 1 less often. "
        "The weighting's cost is objects 2–7: the final weights keep six of seven "
        "likelihoods, so PS keeps them in 63–75 % of cases and DPS in 73–93 % (paper "
        "100 %), though DPS's precision on them stays 5–20 points above Non-PS's; the "
        "former `placed` weighting keeps them in 94–99 % but removes the "
        "ordering effect (χ² p 0.42–0.97). The first-stage object ends a step with 9 % "
        "distinct states against 100 % for the last. Replicated on base seed 7: orderings "
        "differ at every λ (Q p 0.001–0.034), DPS above PS at λ = 20 and 40."
    ),
    "dps-occlusion": (
        "On the RealSeq2 analogue DPS keeps the walker more often than Non-PS, as in the "
        "paper (78 % against 56 %, paired McNemar p = 0.026; so on 30 scenes of base seeds 0 "
        "and 19, not of seeds 23 and 29: 73 % against 70 %, 74 % against 75 %), but on "
        "neither scene far more "
        "often than the PS orderings, where the paper's lead is 60–82 points: 78 % against "
        "76–94 % there, and on the RealSeq1 analogue 66 % against 54–78 % (scene-paired "
        "bootstrap p = 0.43) and 64 % for Non-PS (p = 0.50). On 30 scenes DPS − PS is −3 "
        "points [−10, +3] on both (RealSeq1 analogue: DPS 64 %, PS 65–69 %, Non-PS 63 %), "
        "on 30 fresh scenes of base seed 23 −3 [−10, +3] and −5 [−12, +2], and of base seed "
        "29 −9 [−19, +1] and −3 [−11, +5]; over the 90 scenes of seeds 0, 23 and 29 "
        "together −5.0 [−9.2, −0.7] and −3.6 [−8.0, +0.5]: DPS is below its orderings, "
        "and any lead is ruled out. The RealSeq1 analogue meets "
        "all three of the paper's conditions (slow total occlusions, an attractor beside the "
        "hidden walker, failures that a wider cloud prevents: +17.5 points from σ = 1 to 4 "
        "on tuning seeds); the half-red attractor stands on the first person since round "
        "12, which lost the earlier scene's DPS > Non-PS (68 % against 46 % there). The "
        "orderings differ on the RealSeq2 analogue (Cochran's Q p = 0.036, the walker "
        "sampled last best, as in the paper; not on base seeds 7, 13, 19, 23 and 29) and not "
        "significantly on the RealSeq1 analogue (p = 0.065, sampled second best; on 30 "
        "scenes p = 0.84). Half of the paper's mechanism is there: the walker ends a step "
        "with 39 / 46 / 100 % distinct states by its place in PS(1,2,3) and 62 % under DPS, "
        "as in its Fig. 8; but it moves with the same spread, 6.6–7.1 px, under every "
        "ordering and DPS (tuning seeds), because the next step's stages select among the "
        "last object's fresh states before it moves again. Each method loses the walker "
        "by its own chances, behind the half-red person (φ from −0.03 to +0.14 between two "
        "methods' outcomes on the same scene and run, 90 scenes): a DPS that kept the "
        "walker whenever one of its orderings did would reach 96.3 % and 99.0 %; ours "
        "reaches 62 % and 75 % (the orderings' mean: 67 % and 78 %), since each step "
        "re-divides the set and a hidden walker's good hypotheses weigh no more than the "
        "rest. The paper's own Fig. 8 puts PS(2,3,1) on par with DPS, yet its Table 3 "
        "gives them 40 % and 100 %. Over tracked frames our precision is higher than the "
        "paper's (81–89 % against 55–72 %) and our recall lower (68–78 % against "
        "86–100 %) because the paper's estimated boxes were larger than its ground truth "
        "and ours are not: by the definitions recall / precision = |E| / |G|, 1.2–1.7 "
        "in the paper's Table 3 and 0.8–1.0 here (median per run, seed 0). Every judged "
        "set, the readings and scenes tried: docs/experiments.md, \"DPS Table 3 in one "
        "page\"."
    ),
    "kams-accuracy": (
        "Measured against the noise-free path (`gt/path_center`) as in the paper, KAMS's "
        "mean errors are 5.0 / 9.9 / 15.1 / 18.5 px on a–d against the paper's 6.9 / 18.2 / "
        "14.7 / 17.3 px: within the tolerance on a, c and d, and half the paper's on b, "
        "where our σ = 8 jitter is the only difficulty (our clutter discs are smaller than "
        "the target, so it adds no large false maxima). Who completes what matches the "
        "paper: Hybrid only a, SOK a and, in 53 % of runs, b, KAMS all four (100 / 97 / 93 "
        "/ 87 % of 30 runs, each a significant majority, p < 0.001). The 30 runs per "
        "sequence (15 scenes x 2) were chosen by power: with the paper's 10, a 75 % "
        "completion rate is decided in only a quarter of repetitions, and round 4's 8 of "
        "10 on d was inconclusive (p = 0.055)."
    ),
    "kams-robustness": (
        "Over 36 paired cases (9 scenes of each of kams-a…d) KAMS completes 35 (97 %) and "
        "every other tracker at most 23 (64 %, Annealing); no case has KAMS failing where "
        "the other tracker completes, so every exact McNemar test is significant "
        "(p < 0.001) and our z (3.2–5.0) is of the paper's size (2.9–5.1). The order "
        "differs in one place: the paper finds Condensation the closest to KAMS "
        "(z = 2.9), we find Annealing (z = 3.2), whose annealing layers give it KAMS's "
        "reach on our σ = 4–14 jumps."
    ),
    "shm-depth": (
        "On the plain crossing (`shm-crossing`) Kalman keeps both hands in 90 % of 40 "
        "scenes and SHM in all, a lead of 10 points (paired McNemar p = 0.062, 4 discordant "
        "scenes; interval −0.6 to +23), so the tracking claim stays inconclusive there and "
        "only the error claim (1.0 px lower for SHM) is decided. On `shm-clutter`, with hand "
        "look-alike patches behind the crossing (the paper's Fig. 5c), Kalman keeps both "
        "hands in 48 % of scenes, SHM in 72 % and fast SHM in 75 % (paired McNemar p = 0.003 "
        "and 0.002), with 3.6–3.7 px lower mean error; the true ordering dominates during "
        "overlap (depth-order accuracy 92–95 %) and the probabilities stay near 1/L while "
        "the hands are apart. The paper prints no numbers, so nothing is compared beyond "
        "these claims. The 40 scenes (20 until round 5) were set so that the plain-crossing "
        "claim could be ruled out if Kalman failed in 5 % of scenes; it failed in 10 %."
    ),
    "dps-dancers": (
        "DPS keeps dancer 4 far more often than Non-PS (78 % against 14 %, paired McNemar "
        "p < 0.001), as in the paper (36 % against 4 %), but the paper's limitation — DPS, "
        "with 50 particles per component, below the PS orderings (36 % against 65.5 % on "
        "average and 70–84 % for PS(2,3,4,1), PS(3,4,1,2), PS(4,1,2,3)) — does not "
        "appear: every PS ordering keeps dancer 4 in 76–80 % of runs and DPS in 78 %, "
        "with one or two discordant pairs (pooled, scene-paired bootstrap p = 0.65). On "
        "our scenes the scene decides, not the sampling: DPS and each ordering agree on all "
        "but one or two of the 50 paired runs. The scene was reworked for the "
        "limitation (erratic sway, dancer 4 partly hidden, λ = 150 so that the stage "
        "placing dancer 4 rests on ~5 effective particles of 50 in a DPS component), and "
        "on the tuning seeds DPS fell 12 points below the PS orderings (67 % against "
        "79 %, with the former `placed` weighting); the judged scenes do not confirm it. "
        "DPS's components propose dancer 4 with 50 particles each, but the reassembly "
        "pools the four, so DPS weighs 200 proposals of dancer 4 per frame, as PS does."
    ),
}
