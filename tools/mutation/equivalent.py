"""Equivalent mutants of the formula modules, read by ``mutate.py``.

EQUIVALENT[module] lists (original line, mutated line, reason[, where[, after]]), each
line stripped of surrounding spaces as it appears in cosmic-ray's diff. A surviving mutant
listed here is reported as equivalent and left out of the score.

A line can occur more than once in a module's formula scope, and the reason may hold at
one copy only. An entry whose original line occurs more than once in the scope must name
the functions it is meant for (``where``: a qualified name, or a tuple of them), and if
the line occurs more than once in one of those, the nearest non-blank line above the one
meant (``after``). ``mutate.py`` refuses to run or report a module with an entry that
breaks this (``ambiguities``); tests/test_mutation_tool.py checks every entry.
"""
# ruff: noqa: E501  (the lines are quoted as cosmic-ray prints them)

EQUIVALENT["resampling"] = [  # noqa: F821
    ("sizes = _check_sizes(sizes, w.shape[0] if w.ndim == 1 else -1)",
     "sizes = _check_sizes(sizes, w.shape[0] if w.ndim == 1 else - 0)",
     "-1 is only a size no group list can sum to; 0 is one too (sizes are >= 1)"),
    ("sizes = _check_sizes(sizes, w.shape[0] if w.ndim == 1 else -1)",
     "sizes = _check_sizes(sizes, w.shape[ -1] if w.ndim == 1 else -1)",
     "shape[-1] is shape[0] for the 1-d arrays this branch takes"),
    ("new = 1.0 / gv[idx]", "new = 2.0 / gv[idx]",
     "the new weights are normalised per group on the next line: a constant cancels"),
]

EQUIVALENT["particle"] = [  # noqa: F821
    ("np.exp(logpi - logpi.max()), np.exp(log_g - log_g.max()), sizes,",
     "np.exp(logpi + logpi.max()), np.exp(log_g - log_g.max()), sizes,",
     "a constant factor of the weights cancels in weighted resampling; the shift only "
     "keeps exp() in range, and logpi = log of weights normalised per group is >= -log N"),
    ("self._sizes_c = np.array([n // c + (i < n % c) for i in range(c)], dtype=np.int64)",
     "self._sizes_c = np.array([n / c + (i < n % c) for i in range(c)], dtype=np.int64)",
     "the int64 cast truncates the positive n / c + 0 or 1 to n // c + 0 or 1"),
    # Round 15, every mutant of the module:
    ("ll = obs.log_likelihoods(self._boxes(new.reshape(-1, 3), objects), objects)",
     "ll = obs.log_likelihoods(self._boxes(new.reshape(- 2, 3), objects), objects)",
     "numpy reads any negative size in reshape as the one unknown dimension",
     ("Condensation._step", "JointPF._step")),
    ("sizes: NDArray[np.int64], log_prior: NDArray[np.float64] | None = None,",
     "sizes: NDArray[np.int64], log_prior: NDArray[np.float64] & None = None,",
     "an annotation: never evaluated (from __future__ import annotations)"),
    ("break", "continue",
     "the module's only break ends the stage loop at its last pass (j == m - 1): "
     "continue ends it too"),
]
EQUIVALENT["resampling"] += [  # noqa: F821
    ("sizes = _check_sizes(sizes, w.shape[0] if w.ndim == 1 else -1)",
     "sizes = _check_sizes(sizes, w.shape[0] if w.ndim == 1 else - 2)",
     "-1 is only a size no group list can sum to; -2 is one too"),
    ("resid[np.repeat(totals <= 0, sizes)] = 1.0", "resid[np.repeat(totals <= 0, sizes)] = 2.0",
     "dummy mass of a group that receives no draw: any positive value"),
    # Round 15, every mutant of the module:
    ("sizes: NDArray[np.integer] | None = None,", "sizes: NDArray[np.integer] & None = None,",
     "an annotation: never evaluated (from __future__ import annotations)",
     ("resample_groups", "weighted_resample_groups")),
    *[("if (isinstance(weights, np.ndarray) and weights.dtype == np.float64 and weights.ndim == 1",
       f"if (isinstance(weights, np.ndarray) and weights.dtype {dt} np.float64 and weights.ndim {nd}",
       "only chooses which of the two normalisations runs, the compiled one or numpy's; "
       "they give the same bits for every input form (test_resampling.py::"
       "test_every_input_form_is_normalised_per_group_as_the_compiled_path)")
      for dt, nd in (("==", "!= 1"), ("==", "== 0"), ("==", "== 2"), ("!=", "== 1"))],
]

EQUIVALENT["shm"] = [  # noqa: F821
    ("e = np.where(n > 0, sse / np.maximum(n, 1), np.nan)[:, None]  # (L, 1)",
     "e = np.where(n > 0, sse / np.maximum(n, 0), np.nan)[:, None]  # (L, 1)",
     "the guarded quotient is discarded where n = 0 by the np.where"),
    ("mu = pairs.x.reshape(n_order, n_order, -1)",
     "mu = pairs.x.reshape(n_order, n_order, - 2)",
     "numpy takes any negative size as the one inferred dimension"),
    ("np.zeros((boxes.shape[0], m.dim)), m.P0, m.F, m.Q, m.H, np.eye(2) * self.r_floor",
     "np.zeros((boxes.shape[0], m.dim)), m.P0, m.F, m.Q, m.H, np.eye(2) / self.r_floor",
     "the filter's default R is never used: every update passes its own R"),
    ("logp = np.log(np.maximum(prior, 1e-300)) + log_ev",
     "logp = np.log(np.maximum(prior, -1.0)) + log_ev",
     "the prior is positive for p_stay < 1; at p_stay = 1 a zero prior gives -inf instead "
     "of -690, and both are probability 0 unless the evidence differs by 690 nats"),
    ("log_pj = top + np.log(np.exp(logw - top).sum(axis=0))",
     "log_pj = top + np.log(np.exp(logw + top).sum(axis=0))",
     "a shift common to every j, removed by the softmax; the subtraction only keeps exp() "
     "in range"),
    ("q = q / np.where(mass > 0, mass, 1.0)", "q = q / np.where(mass > 0, mass, 0.0)",
     "where mass = 0 the object is unseen: its mixed measurement is replaced by NaN and "
     "the NaN covariance only reaches the missed filter's diagnostic S"),
]

EQUIVALENT["meanshift"] = [  # noqa: F821
    ("cb = int(np.ceil(ex + half - 0.5)) + 1", "cb = int(np.ceil(ex + half - 1.5)) + 1",
     "drops the one-pixel margin of the chord; the exact per-pixel ellipse test decides, "
     "the margin only guards against a rounded sqrt at the boundary"),
    ("ca = int(np.ceil(ex - half - 0.5)) - 1", "ca = int(np.ceil(ex - half - 0.5)) - 0",
     "as above, left end of the chord"),
    ("while it < max_iter and d0 > min_distance and totals[0] > 0.0:",
     "while it < max_iter and d0 > min_distance and totals[ -1] > 0.0:",
     "totals has one element: [-1] is [0]"),
    ("if dy2 >= 1.0:", "if dy2 > 1.0:",
     "a row at dy2 = 1 has weights 1 - (dx^2 + 1) <= 0 for both kernels: skipped anyway",
     ("_window", "_shift")),
]

# Round 16, every mutant of the kernels:
_WIDER = ("widens the loop's range; every pixel it adds fails the per-pixel ellipse test "
          "(weight <= 0 in _window, r^2 >= 1 in _shift), which is what decides")
_MARGIN = ("drops the one-pixel margin of the chord; the exact per-pixel ellipse test "
           "decides, the margin only guards against a rounded sqrt at the boundary")
_ONE = "totals has one element: [-1] is [0]"
EQUIVALENT["meanshift"] += [  # noqa: F821
    ("cb = int(np.ceil(ex + half - 0.5)) + 1", "cb = int(np.ceil(ex + half - 0.5)) + 2",
     _WIDER),
    ("cb = int(np.ceil(ex + half - 0.5)) + 1", "cb = int(np.ceil(ex + half + 0.5)) + 1",
     _WIDER),
    ("cb = int(np.ceil(ex + half - 0.5)) + 1", "cb = int(np.ceil(ex + half - -0.5)) + 1",
     _WIDER),
    ("cb = int(np.ceil(ex + half - 0.5)) + 1", "cb = int(np.ceil(ex + half - 0.5)) + 0",
     _MARGIN),
    ("ca = int(np.ceil(ex - half - 0.5)) - 1", "ca = int(np.ceil(ex - half - 0.5)) - 2",
     _WIDER),
    ("ca = int(np.ceil(ex - half - 0.5)) - 1", "ca = int(np.ceil(ex - half - 1.5)) - 1",
     _WIDER),
    ("ca = int(np.ceil(ex - half - 0.5)) - 1", "ca = int(np.ceil(ex - half - -0.5)) - 1",
     _MARGIN),
    ("ca = int(np.ceil(ex - half - 0.5)) - 1", "ca = int(np.ceil(ex - half + 0.5)) - 1",
     _MARGIN),
    ("half = half_w * np.sqrt(1.0 - dy2)", "half = half_w / np.sqrt(1.0 - dy2)", _WIDER),
    ("half = half_w * np.sqrt(1.0 - dy2)", "half = half_w * np.sqrt(1.0 + dy2)", _WIDER),
    ("half = half_w * np.sqrt(1.0 - dy2)", "half = half_w * np.sqrt( 2.0 - dy2)", _WIDER),
    ("ca, cb = _chord(ex, 0.5 * w, dy2, c0, c1)", "ca, cb = _chord(ex, 1.5 * w, dy2, c0, c1)",
     _WIDER, ("_window", "_shift")),
    ("i0 = int(np.ceil(lo - 0.5))", "i0 = int(np.ceil(lo - 1.5))",
     "widens the box's pixel range by one; the ellipse lies inside the box, so the "
     "added pixels fail the per-pixel test"),
    ("i1 = int(np.ceil(lo + size - 0.5))", "i1 = int(np.ceil(lo + size - -0.5))",
     "as above, the far end of the range"),
    ("i1 = int(np.ceil(lo + size - 0.5))", "i1 = int(np.ceil(lo + size + 0.5))",
     "as above, the far end of the range"),
    ("if dy2 >= 1.0:", "if dy2 >= 2.0:",
     "rows with 1 <= dy^2 < 2 lie outside the ellipse: every pixel of them fails the "
     "per-pixel test", ("_window", "_shift")),
    ("if totals[0] > 0.0:", "if totals[ -1] > 0.0:", _ONE),
    ("scale = 1.0 / totals[0]", "scale = 1.0 / totals[ -1]", _ONE),
    ("totals[0] = total", "totals[ -1] = total", _ONE),
    ("x1, y1, sw = _shift(bin_img, x0, y0, w, h, q, hist, totals[0], touched, n,",
     "x1, y1, sw = _shift(bin_img, x0, y0, w, h, q, hist, totals[ -1], touched, n,", _ONE),
    ("totals = np.empty(1)", "totals = np.empty( 2)",
     "a second element that nothing reads"),
    ("kbuf = np.empty(bin_img.shape[1])", "kbuf = np.empty(bin_img.shape[ -1])",
     "bin_img is two-dimensional (H, W): its last axis is W"),
    ("scale = 0.0", "scale = 1.0",
     "an empty window touches no bin, so the scale multiplies nothing"),
    ("scale = 0.0", "scale = -1.0",
     "an empty window touches no bin, so the scale multiplies nothing"),
    ("return np.sqrt(one_minus) if one_minus > 0.0 else 0.0",
     "return np.sqrt(one_minus) if one_minus >= 0.0 else 0.0", "sqrt(0) is 0"),
    ("return cx, cy, 0.0", "return cx, cy, -1.0",
     "the caller only asks whether the sum of weights is <= 0"),
    ("weight[b] = np.sqrt(q[b] * total / hist[b])",
     "weight[b] = np.sqrt(q[b] / total / hist[b])",
     "scales every weight by the same 1/total: eq. 26 is a weighted mean, and the caller "
     "only asks whether their sum is <= 0 (the last bits may differ)"),
]

EQUIVALENT["kalman"] = [  # noqa: F821
    # Round 15, every mutant of the module:
    ("R: ArrayLike | None = None,", "R: ArrayLike & None = None,",
     "an annotation: never evaluated (from __future__ import annotations)"),
    ("*,", "/,", "the AR2 constructor's arguments are passed by keyword by every caller"),
    ("H: ArrayLike | None = None,", "H: ArrayLike & None = None,",
     "an annotation: never evaluated (from __future__ import annotations)"),
    ("z: ArrayLike | None,", "z: ArrayLike & None,",
     "an annotation: never evaluated (from __future__ import annotations)"),
    ("x = x + (k @ y[:, :, None])[:, :, 0]", "x = x + (k @ y[:, :, None])[:, :, -1]",
     "the product's last axis has length 1: index -1 is index 0"),
    ("cls, *, accel_std: float, position_std: float = 1.0, velocity_std: float = 5.0",
     "cls, /, accel_std: float, position_std: float = 1.0, velocity_std: float = 5.0",
     "the signature's keyword-only marker read as an operator: the mutant only also "
     "accepts the parameters by position"),
]

EQUIVALENT["metrics"] = [  # noqa: F821
    ("return np.nan_to_num(inter, nan=0.0) > 0.0",
     "return np.nan_to_num(inter, nan= -1.0) > 0.0",
     "a missing box gives False either way (-1 > 0 and 0 > 0 are both false)"),
    ("ov = np.nan_to_num(iou(g[:, :, None, :], e[:, None, :, :]), nan=0.0)",
     "ov = np.nan_to_num(iou(g[:, :, None, :], e[:, None, :, :]), nan= -1.0)",
     "missing pairs stay below any threshold in (0, 1] (idf1 does not check the "
     "threshold: at iou_threshold = 0 the original counts missing frames as matches)"),
]
# Round 16, every mutant of the module. The ratios guard a division twice: an inner
# np.where that only keeps the denominator away from zero, and an outer one that decides
# what a zero area gives. The inner guard's replacements change only values the outer one
# discards.
_INNER = ("the inner guard only keeps the division away from zero; where the area is 0 "
          "the outer np.where returns NaN or 0 anyway")
_ZERO = ("boxes have non-negative sizes, so the area is >= 0; at 0 the intersection is 0 "
         "too, and 0 / 1 is the 0 the original returns")
_SIG = "a signature detail: every caller passes these arguments as the signature allows"
_MISSING = "a missing box gives 0 either way: its intersection and area are both NaN"
EQUIVALENT["metrics"] += [  # noqa: F821
    *[(f"{name} = np.where({v} > 0, inter / np.where({v} > 0, {v}, 1.0), {out})",
       f"{name} = np.where({v} > 0, inter / np.where({v} {op}, {v}, {fill}), {out})",
       _INNER)
      for name, v, out in (("p", "ae", "np.nan"), ("r", "ag", "np.nan"))
      for op, fill in ((">= 0", "1.0"), ("> -1", "1.0"), ("> 0", "2.0"), ("> 0", "0.0"))],
    *[("out = np.where(union > 0, inter / np.where(union > 0, union, 1.0), 0.0)",
       f"out = np.where(union > 0, inter / np.where(union {op}, union, {fill}), 0.0)",
       _INNER)
      for op, fill in ((">= 0", "1.0"), ("> -1", "1.0"), ("> 0", "2.0"), ("> 0", "0.0"))],
    *[("return np.where(small > 0, inter / np.where(small > 0, small, 1.0), 0.0)",
       f"return np.where(small > 0, inter / np.where(small {op}, small, {fill}), 0.0)",
       _INNER)
      for op, fill in ((">= 0", "1.0"), ("> -1", "1.0"), ("> 0", "2.0"), ("> 0", "0.0"))],
    ("return np.where(n > 0, s / np.maximum(n, 1), np.nan)",
     "return np.where(n > 0, s / np.maximum(n, 0), np.nan)", _INNER),
    ("out = np.where(union > 0, inter / np.where(union > 0, union, 1.0), 0.0)",
     "out = np.where(union >= 0, inter / np.where(union > 0, union, 1.0), 0.0)", _ZERO),
    ("out = np.where(union > 0, inter / np.where(union > 0, union, 1.0), 0.0)",
     "out = np.where(union > -1, inter / np.where(union > 0, union, 1.0), 0.0)", _ZERO),
    ("return np.where(small > 0, inter / np.where(small > 0, small, 1.0), 0.0)",
     "return np.where(small >= 0, inter / np.where(small > 0, small, 1.0), 0.0)", _ZERO),
    ("return np.where(small > 0, inter / np.where(small > 0, small, 1.0), 0.0)",
     "return np.where(small > -1, inter / np.where(small > 0, small, 1.0), 0.0)", _ZERO),
    ("small = np.nan_to_num(np.minimum(box_area(a), box_area(b)), nan=0.0)",
     "small = np.nan_to_num(np.minimum(box_area(a), box_area(b)), nan= 1.0)", _MISSING),
    ("small = np.nan_to_num(np.minimum(box_area(a), box_area(b)), nan=0.0)",
     "small = np.nan_to_num(np.minimum(box_area(a), box_area(b)), nan= -1.0)", _MISSING),
    ("inter = np.nan_to_num(intersection_area(a, b), nan=0.0)",
     "inter = np.nan_to_num(intersection_area(a, b), nan= -1.0)", _MISSING),
    ("inter = np.nan_to_num(intersection_area(a, b), nan=0.0)",
     "inter = np.nan_to_num(intersection_area(a, b), nan= 1.0)", _MISSING),
    ("ov = np.nan_to_num(iou(est, g), nan=0.0)[has_gt]",
     "ov = np.nan_to_num(iou(est, g), nan= -1.0)[has_gt]",
     "a frame succeeds when IoU > theta with theta >= 0: false for 0 and for -1"),
    ("for j in range(i + 1, m_n):", "for j in range(i + 0, m_n):",
     "adds the pair (i, i), which overlapping_pairs marks False"),
    ("right += int((best[i] < best[j]) == (d[t, i] < d[t, j]))",
     "right += int((best[i] <= best[j]) == (d[t, i] < d[t, j]))",
     "positions within an ordering are distinct (i != j)"),
    ("right += int((best[i] < best[j]) == (d[t, i] < d[t, j]))",
     "right += int((best[i] < best[j]) == (d[t, i] <= d[t, j]))",
     "pairs of equal depth are not counted (d[t, i] != d[t, j] above)"),
    ("return 100.0 * _nanmean0(e.reshape(-1, *e.shape[e.ndim - tail:]))",
     "return 100.0 * _nanmean0(e.reshape(- 2, *e.shape[e.ndim - tail:]))",
     "numpy reads a negative size as the unknown one (-2 as -1)"),
    ("flat = u.reshape(-1, u.shape[-1])", "flat = u.reshape(- 2, u.shape[-1])",
     "numpy reads a negative size as the unknown one (-2 as -1)"),
    ("return 1.0 if f < 0 else f / e.shape[0]",
     "return 1.0 if f < 0 else f / e.shape[ -1]", "the error is one-dimensional"),
    ("def idf1(gt: ArrayLike, est: ArrayLike, *, iou_threshold: float = 0.5) -> float:",
     "def idf1(gt: ArrayLike, est: ArrayLike, /, iou_threshold: float = 0.5) -> float:",
     _SIG),
    ("def clear_mot(gt: ArrayLike, est: ArrayLike, *, iou_threshold: float = 0.5) -> "
     "ClearMot:",
     "def clear_mot(gt: ArrayLike, est: ArrayLike, /, iou_threshold: float = 0.5) -> "
     "ClearMot:", _SIG),
    ("def recovery_rate(state: ArrayLike, *, last_k: int = 5) -> float:",
     "def recovery_rate(state: ArrayLike, /, last_k: int = 5) -> float:", _SIG),
    ("def overlapping_pairs(boxes: ArrayLike, *, min_overlap: float = 0.1) -> "
     "NDArray[np.bool_]:",
     "def overlapping_pairs(boxes: ArrayLike, /, min_overlap: float = 0.1) -> "
     "NDArray[np.bool_]:", _SIG),
    ("def failure_frame(error: ArrayLike, threshold: float, *, persist: int = 10) -> int:",
     "def failure_frame(error: ArrayLike, threshold: float, /, persist: int = 10) -> int:",
     _SIG),
    ("def tracked_fraction(error: ArrayLike, threshold: float, *, persist: int = 10) -> "
     "float:",
     "def tracked_fraction(error: ArrayLike, threshold: float, /, persist: int = 10) -> "
     "float:", _SIG),
    ("effective_dynamics: ArrayLike, *, components: bool = False",
     "effective_dynamics: ArrayLike, /, components: bool = False", _SIG),
    ("*,", "/,", _SIG + " (the keyword-only markers of otb_curves and depth_order_accuracy)",
     ("otb_curves", "depth_order_accuracy")),
    ("def mean_over_tracked(values: ArrayLike, state: ArrayLike | None = None) -> float:",
     "def mean_over_tracked(values: ArrayLike, state: ArrayLike & None = None) -> float:",
     "an annotation: never evaluated (from __future__ import annotations)"),
]
EQUIVALENT["particle"] += [  # noqa: F821
    ("np.exp(logpi - logpi.max()), np.exp(log_g - log_g.max()), sizes,",
     "np.exp(logpi - logpi.max()), np.exp(log_g + log_g.max()), sizes,",
     "a constant factor of g cancels in weighted resampling; the shift only keeps exp() "
     "in range (log_g is at most 0 after the shift, at least a few hundred below)"),
    ("def _estimate(self, weights: NDArray[np.float64], extras: dict | None = None",
     "def _estimate(self, weights: NDArray[np.float64], extras: dict & None = None",
     "an annotation: never evaluated (from __future__ import annotations)"),
    ("log_prior = np.log(sizes / sizes.sum())", "log_prior = np.log(sizes * sizes.sum())",
     "every component's log prior moves by the same 2 log N, and the mixture weights are "
     "normalised over the components (persistent components carry the normalised ones)"),
]
EQUIVALENT["annealed"] = [  # noqa: F821
    ("coarse = np.broadcast_to(np.logspace(-8.0, 0.0, 65), (log_w.shape[0], 65))",
     "coarse = np.broadcast_to(np.logspace(- 7.0, 0.0, 65), (log_w.shape[0], 65))",
     "the floor of the beta grid: a beta below 1e-7 is chosen only when the "
     "log-likelihoods of one target span more than about 10^7 (lam d^2 <= lam here)"),
    ("def _layer_sigmas(sigma: float | Sequence[float], decay: float,",
     "def _layer_sigmas(sigma: float & Sequence[float], decay: float,",
     "an annotation: never evaluated (from __future__ import annotations)"),
    ("return particles.reshape(k * n, -1)[idx].reshape(particles.shape)",
     "return particles.reshape(k * n, - 2)[idx].reshape(particles.shape)",
     "numpy takes any negative size as the one inferred dimension"),
    # Round 15, every mutant of the module:
    ("ok = rate >= alpha", "ok = rate > alpha",
     "the survival rate is continuous in β: it equals alpha (in (0, 1)) exactly at a grid "
     "point with probability 0; at rate 1 (flat weights) both keep β = 1"),
    ('radius = 0.5 * self.sizes.min(axis=1) if p.estimate == "mode" else None',
     'radius = -0.5 * self.sizes.min(axis=1) if p.estimate == "mode" else None',
     "the radius is only used squared"),
    ("near = np.einsum(\"knc,knc->kn\", gap, gap) <= radius[:, None] ** 2",
     "near = np.einsum(\"knc,knc->kn\", gap, gap) < radius[:, None] ** 2",
     "a particle drawn at exactly the radius from the heaviest one has probability 0"),
    ("return Estimate(window_boxes(centres, self.sizes)[:, 0],",
     "return Estimate(window_boxes(centres, self.sizes)[:, -1],",
     "one window per object (the estimate): column -1 is column 0"),
    ("confidence = 1.0 - set_distances(obs, centres, self.sizes)[:, 0]",
     "confidence = 1.0 - set_distances(obs, centres, self.sizes)[:, -1]",
     "one window per object (the estimate): column -1 is column 0"),
    ("self.sizes = boxes[:, 2:4].copy()", "self.sizes = boxes[:, 2: 5].copy()",
     "boxes have 4 columns: 2:5 is 2:4"),
    ("centres = boxes[:, :2] + 0.5 * boxes[:, 2:4]",
     "centres = boxes[:, :2] + 0.5 * boxes[:, 2: 5]", "boxes have 4 columns: 2:5 is 2:4"),
    ("radius: NDArray[np.float64] | None = None) -> NDArray[np.float64]:",
     "radius: NDArray[np.float64] & None = None) -> NDArray[np.float64]:",
     "an annotation: never evaluated (from __future__ import annotations)"),
]
EQUIVALENT["shm"] += [  # noqa: F821
    ("np.zeros((boxes.shape[0], m.dim)), m.P0, m.F, m.Q, m.H, np.eye(2) * self.params.r_floor",
     "np.zeros((boxes.shape[0], m.dim)), m.P0, m.F, m.Q, m.H, np.eye(2) / self.params.r_floor",
     "the filter's default R is never used: every update passes its own R"),
    # Round 15, every mutant of the module:
    ("self.joint.H, np.eye(2 * n_obj) * self.params.r_floor,",
     "self.joint.H, np.eye(2 * n_obj) / self.params.r_floor,",
     "the filter's default R is never used: every update passes its own R"),
    ("q = q / np.where(mass > 0, mass, 1.0)", "q = q / np.where(mass > 0, mass, 2.0)",
     "where mass = 0 every q of the object is 0: any positive divisor gives 0"),
    ("q = q / np.where(mass > 0, mass, 1.0)", "q = q / np.where(mass >= 0, mass, 1.0)",
     "mass = 0 only for an object missed under every ordering: it is not seen, its y is "
     "set to NaN and the Kalman update skips it, whatever its (then NaN) R"),
    ("+ np.log(np.maximum(self.order_prob, 1e-300))[ii]",
     "+ np.log(np.maximum(self.order_prob, -1.0))[ii]",
     "differs only for an ordering whose probability underflowed to exactly 0: both "
     "keep it at 0 unless the evidence favours it by more than e^690"),
    ("self.log_pi = np.log(np.maximum(self.pi, 1e-300))",
     "self.log_pi = np.log(np.maximum(self.pi, -1.0))",
     "Π has zeros only off the diagonal at p_stay = 1; every column keeps its diagonal "
     "log 1 = 0, next to which e^-690 vanishes in double precision as exp(-inf) does"),
    ("q = q / np.where(mass > 0, mass, 1.0)", "q = q / np.where(mass > -1, mass, 1.0)",
     "mass = 0 only for an object missed under every ordering: it is not seen, its y is "
     "set to NaN and the Kalman update skips it, whatever its (then NaN) R"),
]

# The statistics of the experiments' claims. Annotations are never evaluated (``from
# __future__ import annotations``), and every caller passes the arguments after ``*`` by
# keyword, so ``/`` there changes nothing either.
_SIGNATURES = [
    ("rng: int | np.random.Generator, *, n_boot: int = N_BOOT,",
     "rng: int | np.random.Generator, /, n_boot: int = N_BOOT,"),
    ("rng: int | np.random.Generator, *, n_boot: int = N_BOOT,",
     "rng: int & np.random.Generator, *, n_boot: int = N_BOOT,"),
    ("alpha: float = ALPHA, *, min_n: int = 0) -> str:",
     "alpha: float = ALPHA, /, min_n: int = 0) -> str:"),
    ("def bootstrap_mean(values: ArrayLike, rng: int | np.random.Generator, *,",
     "def bootstrap_mean(values: ArrayLike, rng: int & np.random.Generator, *,"),
    ("def bootstrap_mean(values: ArrayLike, rng: int | np.random.Generator, *,",
     "def bootstrap_mean(values: ArrayLike, rng: int | np.random.Generator, /,"),
    ("def bootstrap_paired_diff(a: ArrayLike, b: ArrayLike, rng: int | np.random.Generator, *,",
     "def bootstrap_paired_diff(a: ArrayLike, b: ArrayLike, rng: int & np.random.Generator, *,"),
    ("def bootstrap_paired_diff(a: ArrayLike, b: ArrayLike, rng: int | np.random.Generator, *,",
     "def bootstrap_paired_diff(a: ArrayLike, b: ArrayLike, rng: int | np.random.Generator, /,"),
    ("def _rng(seed: int | np.random.Generator) -> np.random.Generator:",
     "def _rng(seed: int & np.random.Generator) -> np.random.Generator:"),
]
_CLAMPS = [  # the exact closed forms are in [0, 1]; the clamps only absorb rounding
    ('return Test(f"exact binomial (rate > {p0:g}, one-sided)", float(k), min(1.0, p))',
     'return Test(f"exact binomial (rate > {p0:g}, one-sided)", float(k), min( 2.0, p))'),
    ('return Test("paired McNemar (exact binomial, one-sided)", float(n_sf), min(1.0, p))',
     'return Test("paired McNemar (exact binomial, one-sided)", float(n_sf), min( 2.0, p))'),
    ("return min(1.0, math.exp(-h) * total)", "return min( 2.0, math.exp(-h) * total)"),
    ("return min(1.0, total)", "return min( 2.0, total)"),
    ("return (max(0.0, centre - half), min(1.0, centre + half))",
     "return (max(0.0, centre - half), min( 2.0, centre + half))"),
    ("return (max(0.0, centre - half), min(1.0, centre + half))",
     "return (max( -1.0, centre - half), min(1.0, centre + half))"),
    ("return (d - math.sqrt(max(0.0, dl1 ** 2 + du2 ** 2 - 2 * phi * dl1 * du2)),",
     "return (d - math.sqrt(max( -1.0, dl1 ** 2 + du2 ** 2 - 2 * phi * dl1 * du2)),"),
    ("d + math.sqrt(max(0.0, dl2 ** 2 + du1 ** 2 - 2 * phi * dl2 * du1)))",
     "d + math.sqrt(max( -1.0, dl2 ** 2 + du1 ** 2 - 2 * phi * dl2 * du1)))"),
]
_BISECTION = [  # the standard normal quantile lies within ±9 for every q a double can hold
    ("lo, hi = -40.0, 40.0", "lo, hi = - 41.0, 40.0"),
    ("lo, hi = -40.0, 40.0", "lo, hi = - 39.0, 40.0"),
    ("lo, hi = -40.0, 40.0", "lo, hi = -40.0, 41.0"),
    ("lo, hi = -40.0, 40.0", "lo, hi = -40.0, 39.0"),
    ("while hi - lo > 1e-12:", "while hi - lo >= 1e-12:"),
    ("if 1.0 - norm_sf(mid) < q:", "if 1.0 - norm_sf(mid) <= q:"),
]
EQUIVALENT["stats"] = [  # noqa: F821
    *[(a, b, "a signature detail no caller depends on") for a, b in _SIGNATURES],
    *[(a, b, "a clamp the exact value never reaches") for a, b in _CLAMPS],
    *[(a, b, "the bisection's start and stop, far outside any difference a test sees")
      for a, b in _BISECTION],
    ("p = sum(math.comb(n, i) for i in range(n_sf, n + 1)) / 2.0**n if n else 1.0",
     "p = sum(math.comb(n, i) for i in range(n_sf, n + 1)) / 2.0**n if n else 2.0",
     "clamped to 1.0 on the next line"),
    ("p = sum(math.comb(n, i) for i in range(n_sf, n + 1)) / 2.0**n if n else 1.0",
     "p = sum(math.comb(n, i) for i in range(n_sf, n + 2)) / 2.0**n if n else 1.0",
     "comb(n, n + 1) = 0"),
    ("p = sum(math.comb(n, i) * p0**i * (1 - p0) ** (n - i) for i in range(k, n + 1))",
     "p = sum(math.comb(n, i) * p0**i * (1 - p0) ** (n - i) for i in range(k, n + 2))",
     "comb(n, n + 1) = 0"),
    ("for k in range(1, (df - 1) // 2 + 1):", "for k in range(1, (df - 0) // 2 + 1):",
     "the branch is taken for odd df only, where (df - 1) // 2 = df // 2"),
    ("if x <= 0:", "if x < 0:", "at x = 0 both closed forms give exactly 1"),
    ("if margins > 0:", "if margins > -1:",
     "with an empty margin the cross-product is 0, so φ stays 0 on either path"),
    ("if margins > 0:", "if margins >= 0:",
     "with an empty margin the cross-product is 0, so φ stays 0 on either path"),
    ("if cross > n / 2:", "if cross >= n / 2:", "at cross = n / 2 the formula gives φ = 0"),
    ("elif cross < 0:", "elif cross <= 0:", "at cross = 0 the formula gives φ = 0"),
    ("elif cross < 0:", "elif cross < 1:", "the cross-product is an integer: 0 gives φ = 0"),
    ("if n >= MIN_RUNS and math.isfinite(hi) and (hi < delta or hi < 0):",
     "if n >= MIN_RUNS and math.isfinite(hi) and (hi < delta or hi < -1):",
     "delta > 0 for every claim, so hi < 0 implies hi < delta"),
    ("if n >= MIN_RUNS and math.isfinite(hi) and (hi < delta or hi < 0):",
     "if n >= MIN_RUNS and math.isfinite(hi) and (hi < delta or hi <= 0):",
     "delta > 0 for every claim, so hi <= 0 implies hi < delta"),
    ("alpha: float = ALPHA, *, min_n: int = 0) -> str:",
     "alpha: float = ALPHA, *, min_n: int = 1) -> str:",
     "a claim is only made with cases (n >= 1), so min_n 0 and 1 are the same floor"),
    ("alpha: float = ALPHA, *, min_n: int = 0) -> str:",
     "alpha: float = ALPHA, *, min_n: int = -1) -> str:",
     "n >= 0: min_n 0 and -1 are the same floor"),
    ("if v.size == 0:", "if v.size == -1:",
     "an empty sample gives (nan, nan) on the other path too (numpy's mean of no values)"),
]

# The experiments' summaries (claims, pairings, comparisons); round 14.
EQUIVALENT["summary"] = [  # noqa: F821
    ('def _run_mean(target: dict[str, Any], field: str, *, tracked_only: bool) -> float:',
     'def _run_mean(target: dict[str, Any], field: str, /, tracked_only: bool) -> float:',
     'a signature detail no caller depends on (annotations are not evaluated; the arguments after * are passed by keyword)'),
    ('def _mean(values: list[float] | np.ndarray, key: tuple[Any, ...]) -> dict[str, Any]:',
     'def _mean(values: list[float] & np.ndarray, key: tuple[Any, ...]) -> dict[str, Any]:',
     'a signature detail no caller depends on (annotations are not evaluated; the arguments after * are passed by keyword)'),
    ('def _val(x: dict[str, Any] | None) -> float | None:',
     'def _val(x: dict[str, Any] & None) -> float | None:',
     'a signature detail no caller depends on (annotations are not evaluated; the arguments after * are passed by keyword)'),
    ('def _val(x: dict[str, Any] | None) -> float | None:',
     'def _val(x: dict[str, Any] | None) -> float & None:',
     'a signature detail no caller depends on (annotations are not evaluated; the arguments after * are passed by keyword)'),
    ('names = [t["name"] for t in records[0]["targets"]]',
     'names = [t["name"] for t in records[ -1]["targets"]]',
     'every record of a sweep names the same targets, and the hard target is among them'),
    ('names = [t["name"] for t in records[0]["targets"]]',
     'names = [t["name"] for t in records[ 1]["targets"]]',
     'every record of a sweep names the same targets, and the hard target is among them'),
    ('return names.index(name) if name in names else 0',
     'return names.index(name) if name in names else -1',
     'every record of a sweep names the same targets, and the hard target is among them'),
    ('return names.index(name) if name in names else 0',
     'return names.index(name) if name in names else 1',
     'every record of a sweep names the same targets, and the hard target is among them'),
    ('def _compare(out: list[dict[str, Any]], what: str, paper: float | None,',
     'def _compare(out: list[dict[str, Any]], what: str, paper: float & None,',
     'a signature detail no caller depends on (annotations are not evaluated; the arguments after * are passed by keyword)'),
    ('ours: dict[str, Any] | None, *, kind: str = "pct") -> None:',
     'ours: dict[str, Any] & None, *, kind: str = "pct") -> None:',
     'a signature detail no caller depends on (annotations are not evaluated; the arguments after * are passed by keyword)'),
    ('ours: dict[str, Any] | None, *, kind: str = "pct") -> None:',
     'ours: dict[str, Any] | None, /, kind: str = "pct") -> None:',
     'a signature detail no caller depends on (annotations are not evaluated; the arguments after * are passed by keyword)'),
    ('inside = v is not None and ci[0] is not None and ci[0] <= paper <= ci[1]',
     'inside = v is not None and ci[ -1] is not None and ci[0] <= paper <= ci[1]',
     "the interval's bounds are both None or both numbers"),
    ('inside = v is not None and ci[0] is not None and ci[0] <= paper <= ci[1]',
     'inside = v is not None and ci[ 1] is not None and ci[0] <= paper <= ci[1]',
     "the interval's bounds are both None or both numbers"),
    ('interval: tuple[float, float], delta: float, ours: str, *,',
     'interval: tuple[float, float], delta: float, ours: str, /,',
     'a signature detail no caller depends on (annotations are not evaluated; the arguments after * are passed by keyword)'),
    ('n_ss = sum(x and y for x, y in zip(fa, fb, strict=True))',
     'n_ss = sum(x and y for x, y in zip(fa, fb, strict=False))',
     'the two lists are built from the same cases: equal lengths'),
    ('n_sf = sum(x and not y for x, y in zip(fa, fb, strict=True))',
     'n_sf = sum(x and not y for x, y in zip(fa, fb, strict=False))',
     'the two lists are built from the same cases: equal lengths'),
    ('n_fs = sum(y and not x for x, y in zip(fa, fb, strict=True))',
     'n_fs = sum(y and not x for x, y in zip(fa, fb, strict=False))',
     'the two lists are built from the same cases: equal lengths'),
    ('delta: float, label_a: str, label_b: str, *, delta_source: str) -> None:',
     'delta: float, label_a: str, label_b: str, /, delta_source: str) -> None:',
     'a signature detail no caller depends on (annotations are not evaluated; the arguments after * are passed by keyword)'),
    ('delta: float, label_a: str, label_b: str, key: tuple[Any, ...], *,',
     'delta: float, label_a: str, label_b: str, key: tuple[Any, ...], /,',
     'a signature detail no caller depends on (annotations are not evaluated; the arguments after * are passed by keyword)'),
    ('rates: dict[str, dict[str, Any]], ok: Any, delta: float, *,',
     'rates: dict[str, dict[str, Any]], ok: Any, delta: float, /,',
     'a signature detail no caller depends on (annotations are not evaluated; the arguments after * are passed by keyword)'),
    ('if len(recs) < 2 or not cases:',
     'if len(recs) < 1 or not cases:',
     'guarded twice: one PS ordering has no spread, and _orderings_claim returns for fewer than two'),
    ('b: dict[Any, float], delta: float, ours: str, key: tuple[Any, ...], *,',
     'b: dict[Any, float], delta: float, ours: str, key: tuple[Any, ...], /,',
     'a signature detail no caller depends on (annotations are not evaluated; the arguments after * are passed by keyword)'),
    ('preset = exp.presets[0]',
     'preset = exp.presets[ -1]',
     'dps-synthetic has one preset'),
    ('if ps and t2:',
     'if ps or t2:',
     "every λ the experiment sweeps is a column of the paper's Table 2"),
    ('if len(ps) > 1:',
     'if len(ps) > 0:',
     'guarded twice: one PS ordering has no spread, and _orderings_claim returns for fewer than two'),
    ('if len(ps) > 1:',
     'if len(ps) >= 1:',
     'guarded twice: one PS ordering has no spread, and _orderings_claim returns for fewer than two'),
    ('continue',
     'break',
     'PS is the last of the two columns', "_dps_synthetic", "if not ps:"),
    ('if first is not None and ps:',
     'if first is not None or ps:',
     'with no λ or no PS ordering there is no run to take a uniqueness gap from'),
    ('if label == "DPS" or label not in paper:',
     'if label == "DPS" and label not in paper:',
     "DPS's gap to itself is 0, below 10 points: skipped on either path"),
    ('a, b = ("DPS", label) if gap > 0 else (label, "DPS")',
     'a, b = ("DPS", label) if gap > -1 else (label, "DPS")',
     'the claim is only made for |gap| >= 10 points'),
    ('a, b = ("DPS", label) if gap > 0 else (label, "DPS")',
     'a, b = ("DPS", label) if gap > 1 else (label, "DPS")',
     'the claim is only made for |gap| >= 10 points'),
    ('a, b = ("DPS", label) if gap > 0 else (label, "DPS")',
     'a, b = ("DPS", label) if gap >= 0 else (label, "DPS")',
     'the claim is only made for |gap| >= 10 points'),
    ('if len(ps) > 1 and spread >= _CLAIM_GAP:',
     'if len(ps) > 0 and spread >= _CLAIM_GAP:',
     'guarded twice: one PS ordering has no spread, and _orderings_claim returns for fewer than two'),
    ('if len(ps) > 1 and spread >= _CLAIM_GAP:',
     'if len(ps) >= 1 and spread >= _CLAIM_GAP:',
     'guarded twice: one PS ordering has no spread, and _orderings_claim returns for fewer than two'),
    ('err = _error(rec["targets"][0])',
     'err = _error(rec["targets"][ -1])',
     'a KAMS record holds one target, of the same size (hence threshold) in every scene of a preset'),
    ('return metrics.failure_frame(np.nan_to_num(err, nan=np.inf), rec["failure_threshold"][0],',
     'return metrics.failure_frame(np.nan_to_num(err, nan=np.inf), rec["failure_threshold"][ -1],',
     'a KAMS record holds one target, of the same size (hence threshold) in every scene of a preset'),
    ('measured = "path centre" if all("path_error" in r["targets"][0] for r in records) else \\',
     'measured = "path centre" if all("path_error" in r["targets"][ -1] for r in records) else \\',
     'a KAMS record holds one target, of the same size (hence threshold) in every scene of a preset'),
    ('errs = [float(np.nanmean(_error(r["targets"][0]))) for r in recs]',
     'errs = [float(np.nanmean(_error(r["targets"][ -1]))) for r in recs]',
     'a KAMS record holds one target, of the same size (hence threshold) in every scene of a preset'),
    ('per_frame = np.nanmean(np.array([_error(r["targets"][0]) for r in recs]), axis=0)',
     'per_frame = np.nanmean(np.array([_error(r["targets"][ -1]) for r in recs]), axis=0)',
     'a KAMS record holds one target, of the same size (hence threshold) in every scene of a preset'),
    ('"mean_error_completed": _mean([e for e, d in zip(errs, done, strict=True) if d],',
     '"mean_error_completed": _mean([e for e, d in zip(errs, done, strict=False) if d],',
     'the two lists are built from the same cases: equal lengths'),
    ('"failure_threshold": recs[0]["failure_threshold"][0],',
     '"failure_threshold": recs[ -1]["failure_threshold"][0],',
     'a KAMS record holds one target, of the same size (hence threshold) in every scene of a preset'),
    ('"failure_threshold": recs[0]["failure_threshold"][0],',
     '"failure_threshold": recs[ 1]["failure_threshold"][0],',
     'a KAMS record holds one target, of the same size (hence threshold) in every scene of a preset'),
    ('"failure_threshold": recs[0]["failure_threshold"][0],',
     '"failure_threshold": recs[0]["failure_threshold"][ -1],',
     'a KAMS record holds one target, of the same size (hence threshold) in every scene of a preset'),
    ('if m.label in paper and paper[m.label][pi] is not None:',
     'if m.label in paper or paper[m.label][pi] is not None:',
     "every method of kams-accuracy is in the paper's table"),
    ('if m.label == "KAMS" or m.label not in paper or paper[m.label][pi] is not None:',
     'if m.label == "KAMS" and m.label not in paper or paper[m.label][pi] is not None:',
     "KAMS is in the paper's table with a number on every sequence"),
    ('if m.slug == "kams" or m.slug not in by_method or not ref:',
     'if m.slug == "kams" and m.slug not in by_method or not ref:',
     "KAMS's runs are always there (ref), and every other method ran"),
    ('if m.slug == "kams" or m.slug not in by_method or not ref:',
     'if m.slug == "kams" or m.slug not in by_method and not ref:',
     "KAMS's runs are always there (ref), and every other method ran"),
]

# The runs an experiment plans and what each run records (round 15).
EQUIVALENT["runner"] = [  # noqa: F821
    *[(f"{arg}: {ann} | None = None,", f"{arg}: {ann} & None = None,",
       "an annotation: never evaluated (from __future__ import annotations)")
      for arg, ann in (("scenes", "int"), ("methods", "Iterable[str]"),
                       ("values", "Iterable[float]"), ("overrides", "dict[str, Any]"))],
    ("state: list[int | None] = [", "state: list[int & None] = [",
     "a local variable's annotation: never evaluated"),
    ('int(s) if p else None for s, p in zip(fm["state"][:, m], present[:, m], strict=True)',
     'int(s) if p else None for s, p in zip(fm["state"][:, m], present[:, m], strict=False)',
     "both columns come from the same (T, M) ground truth: their lengths are equal"),
    ("done = run(seq, method.tracker, params, task.tracker_seed(), single_thread=True)",
     "done = run(seq, method.tracker, params, task.tracker_seed(), single_thread=False)",
     "the kernels give the same bits on any thread count (tests/trackers/models/"
     "test_box_kernel.py::test_results_do_not_depend_on_the_thread_count); "
     "one thread per worker is for speed on a shared machine"),
    ("return int(np.random.SeedSequence(words).generate_state(1, dtype=np.uint64)[0] >> 1)",
     "return int(np.random.SeedSequence(words).generate_state( 2, dtype=np.uint64)[0] >> 1)",
     "SeedSequence.generate_state(n) is a prefix of the same stream: its first word "
     "does not depend on n"),
    ("return int(np.random.SeedSequence(words).generate_state(1, dtype=np.uint64)[0] >> 1)",
     "return int(np.random.SeedSequence(words).generate_state(1, dtype=np.uint64)[ -1] >> 1)",
     "the state has one word: [-1] is [0]"),
    ("ed, components=ed.ndim == 3", "ed, components=ed.ndim == 4",
     "every tracker of the experiments reports effective dynamics of shape (T, K), "
     "never (T, K, C) or (T, K, C, D): both tests are False"),
    ('if "order_prob" in extras and orderings is not None:',
     'if "order_prob" in extras or orderings is not None:',
     "only the SHM trackers have orderings, and every one of them reports order_prob"),
]

# The mean-shift family's trackers around the kernels (round 15, every mutant).
EQUIVALENT["ms-trackers"] = [  # noqa: F821
    ("self.centres = res.centres[:, 0]", "self.centres = res.centres[:, -1]",
     "the tracker's set has one start per object: column -1 is column 0"),
    ('{"confidence": 1.0 - res.distances[:, 0], "n_iter": res.n_iter[:, 0]})',
     '{"confidence": 1.0 - res.distances[:, 0], "n_iter": res.n_iter[:, -1]})',
     "the tracker's set has one start per object: column -1 is column 0"),
    ('{"confidence": 1.0 - res.distances[:, 0], "n_iter": res.n_iter[:, 0]})',
     '{"confidence": 1.0 - res.distances[:, -1], "n_iter": res.n_iter[:, 0]})',
     "the tracker's set has one start per object: column -1 is column 0"),
    ("return Estimate(window_boxes(self.centres[:, None, :], self.sizes)[:, 0],",
     "return Estimate(window_boxes(self.centres[:, None, :], self.sizes)[:, -1],",
     "one window per object: column -1 is column 0"),
    ("self.centres = boxes[:, :2] + 0.5 * boxes[:, 2:4]",
     "self.centres = boxes[:, :2] + 0.5 * boxes[:, 2: 5]",
     "boxes have 4 columns: 2:5 is 2:4"),
    ("self.sizes = boxes[:, 2:4].copy()", "self.sizes = boxes[:, 2: 5].copy()",
     "boxes have 4 columns: 2:5 is 2:4"),
    ("which: NDArray[np.integer] | None = None) -> MeanShiftResult:",
     "which: NDArray[np.integer] & None = None) -> MeanShiftResult:",
     "an annotation: never evaluated (from __future__ import annotations)"),
    ("sizes: NDArray[np.float64], *, max_iter: int, eps: float,",
     "sizes: NDArray[np.float64], /, max_iter: int, eps: float,",
     "a signature detail no caller depends on: every caller passes max_iter and eps by "
     "keyword"),
]
_ONE_COLUMN = "the primary tracker is one start per object: column -1 is column 0"
_FOUR_COLUMNS = "boxes have 4 columns: 2:5 is 2:4"
EQUIVALENT["sok"] = [  # noqa: F821
    ("centres = res.centres[:, 0]", "centres = res.centres[:, -1]", _ONE_COLUMN),
    ("confidence = 1.0 - res.distances[:, 0]", "confidence = 1.0 - res.distances[:, -1]",
     _ONE_COLUMN),
    ("return Estimate(window_boxes(centres[:, None, :], self.sizes)[:, 0],",
     "return Estimate(window_boxes(centres[:, None, :], self.sizes)[:, -1],",
     "one window per object: column -1 is column 0"),
    ("self.sizes = boxes[:, 2:4].copy()", "self.sizes = boxes[:, 2: 5].copy()", _FOUR_COLUMNS),
    ("self.centres = boxes[:, :2] + 0.5 * boxes[:, 2:4]",
     "self.centres = boxes[:, :2] + 0.5 * boxes[:, 2: 5]", _FOUR_COLUMNS),
    ("tied = cand_conf >= cand_conf.max(axis=1, keepdims=True) - _TIE",
     "tied = cand_conf > cand_conf.max(axis=1, keepdims=True) - _TIE",
     "differs only for a candidate exactly 1e-9 below the best: the tolerance is a "
     "rounding allowance, not a decision"),
    *[("gap = np.round(np.hypot(*(cand - centres[low, None, :]).transpose(2, 0, 1)), 6)",
       f"gap = np.round(np.hypot(*(cand - centres[low, None, :]).transpose(2, 0, 1)), {d})",
       "the rounding only makes distances that differ by rounding equal; 5 or 7 decimals "
       "decide differently only for tied candidates within 1e-5 px of the same distance")
      for d in (5, 7)],
    ("starts = centres[low, None, :] + grid", "starts = centres[low, None, :] - grid",
     "the eight offsets are symmetric: -grid is the same starts in another order, which "
     "could matter only for two candidates equally confident and equally near the "
     "primary window"),
]
EQUIVALENT["hybrid"] = [  # noqa: F821
    ("self.sizes = boxes[:, 2:4].copy()", "self.sizes = boxes[:, 2: 5].copy()", _FOUR_COLUMNS),
    ("centres = boxes[:, :2] + 0.5 * boxes[:, 2:4]",
     "centres = boxes[:, :2] + 0.5 * boxes[:, 2: 5]", _FOUR_COLUMNS),
    ('return Estimate(window_boxes(centres, self.sizes)[:, 0], {"confidence": confidence})',
     'return Estimate(window_boxes(centres, self.sizes)[:, -1], {"confidence": confidence})',
     "one window per object (the weighted mean): column -1 is column 0"),
    ("confidence = 1.0 - set_distances(obs, centres, self.sizes)[:, 0]",
     "confidence = 1.0 - set_distances(obs, centres, self.sizes)[:, -1]",
     "one window per object (the weighted mean): column -1 is column 0"),
    ("pred = x + v + p.sigma * self.rng.standard_normal(x.shape)",
     "pred = x + v - p.sigma * self.rng.standard_normal(x.shape)",
     "the noise is a zero-mean normal draw: its negative has the same law (another "
     "sample of the same filter, as another seed would give)"),
]

# CLEAR MOT, identity and HOTA as TrackEval computes them (every mutant). A MotFrames
# holds ids 0..n-1 that each appear in some frame (mot_frames relabels the columns
# present; the class documents n_gt_ids / n_tracker_ids as the distinct ids), so every
# id's frame count is >= 1, and past the early returns both sides have detections.
_ANNOTATION = "an annotation: never evaluated (from __future__ import annotations)"
_EVERY_ID = ("every id of a MotFrames appears in some frame: its count is >= 1, so the "
             "mask keeps every id and the guard never reaches 0")
_EMPTY_LSA = ("the shortcut only skips an empty assignment: linear_sum_assignment of an "
              "(n, 0) or (0, m) matrix matches nothing, and the counts come out the same")
_SHORTCUT = ("an early return that is a shortcut: with no detections on that side the "
             "loops give the same scores (TrackEval's values) field for field")
_BONUS = ("any continuity bonus above 2 gives the same matchings: forcing an object's "
          "previous track (IoU >= threshold) into a matching removes at most two other "
          "pairs of IoU <= 1 and no other continuing pair (the previous tracks are one to "
          "one), so every best matching holds all continuing pairs for 999, 1000 or 1001")
_FORBIDDEN = ("the 1e10 cost only forbids an assignment; a full assignment avoiding it "
              "always exists at a cost of at most the detection count, far below 1e10 +- 1")
# (2026-12-03: the four max(1, ...) guards of _clear_final and _hota_final are no longer
# listed: combine's from_counts calls them without clear's and hota's early returns, so a
# count can be 0 there; test_mot.py::test_combine_of_sequences_without_objects_or_tracks_
# divides_by_at_least_one kills them.)
EQUIVALENT["mot"] = [  # noqa: F821
    *[(f"b{i} = np.array({x}, dtype=np.float64).reshape(-1, 4)",
       f"b{i} = np.array({x}, dtype=np.float64).reshape(- 2, 4)",
       "numpy reads any negative size in reshape as the one unknown dimension")
      for i, x in ((1, "a"), (2, "b"))],
    ("inter[union <= _EPS] = 0", "inter[union < _EPS] = 0",
     "a union <= eps needs both areas <= eps (else it exceeds the larger area): the area "
     "guards have already zeroed that intersection"),
    ("union[union <= _EPS] = 1", "union[union < _EPS] = 1",
     "a union of exactly eps has both areas <= eps, so its intersection is already 0: "
     "0 / eps and 0 / 1 are both 0"),
    ("union[union <= _EPS] = 1", "union[union <= _EPS] = 2",
     "the replaced unions only divide intersections already set to 0: 0 / 2 is 0 / 1"),
    ("label = np.full(present.shape[1], -1, dtype=np.intp)",
     "label = np.full(present.shape[1], - 2, dtype=np.intp)",
     "the labels of columns never present are never read but by the max, taken with "
     "initial=-1: any negative fill gives the same count"),
    *[(f"{arg}: ArrayLike | None = None,", f"{arg}: ArrayLike & None = None,", _ANNOTATION)
      for arg in ("gt_keep", "est_keep", "est_rank")],
    ("def _in_order(present: NDArray[np.bool_], rank: ArrayLike | None, t: int) -> NDArray[np.intp]:",
     "def _in_order(present: NDArray[np.bool_], rank: ArrayLike & None, t: int) -> NDArray[np.intp]:",
     _ANNOTATION),
    ("gt: ArrayLike, distractor: ArrayLike, est: ArrayLike, est_rank: ArrayLike | None = None",
     "gt: ArrayLike, distractor: ArrayLike, est: ArrayLike, est_rank: ArrayLike & None = None",
     _ANNOTATION),
    *[("if gi.size == 0 or ej.size == 0:", f"if {m}:", _EMPTY_LSA)
      for m in ("gi.size == -1 or ej.size == 0", "gi.size == 0 and ej.size == 0",
                "gi.size == 0 or ej.size == -1")],
    ("ok = score[rows, cols] > _EPS", "ok = score[rows, cols] >= _EPS",
     "(remove_distractor_matches) a score is 0 or >= 0.5 - eps, never eps: the test "
     "decides the same (CLEAR's copy of the line is not equivalent: its scores can be eps)",
     "remove_distractor_matches"),
    ("if data.n_tracker_dets == 0:", "if data.n_tracker_dets == -1:", _SHORTCUT, "clear"),
    ("score = 1000.0 * (trk_ids[None, :] == prev_step_id[gt_ids[:, None]]) + sim",
     "score = 1001.0 * (trk_ids[None, :] == prev_step_id[gt_ids[:, None]]) + sim", _BONUS),
    ("score = 1000.0 * (trk_ids[None, :] == prev_step_id[gt_ids[:, None]]) + sim",
     "score = 999.0 * (trk_ids[None, :] == prev_step_id[gt_ids[:, None]]) + sim", _BONUS),
    *[("ratio = matched_count[id_count > 0] / id_count[id_count > 0]",
       f"ratio = {m}", _EVERY_ID)
      for m in ("matched_count[id_count > -1] / id_count[id_count > 0]",
                "matched_count[id_count >= 0] / id_count[id_count > 0]",
                "matched_count[id_count > 0] / id_count[id_count > -1]",
                "matched_count[id_count > 0] / id_count[id_count >= 0]")],
    ("frag = int(np.sum(frag_count[frag_count > 0] - 1))",
     "frag = int(np.sum(frag_count[frag_count > 1] - 1))",
     "an object whose track started once adds 1 - 1 = 0 either way"),
    ("idf1=idtp / max(1.0, idtp + 0.5 * idfp + 0.5 * idfn),",
     "idf1=idtp / max( 0.0, idtp + 0.5 * idfp + 0.5 * idfn),",
     "idtp + (idfp + idfn) / 2 is half of all detections, >= 1 past identity's early "
     "returns (both sides have some)"),
    ("idp=idtp / max(1.0, idtp + idfp),", "idp=idtp / max( 0.0, idtp + idfp),",
     "idtp + idfp is the number of tracker detections, >= 1 past the early returns"),
    ("idr=idtp / max(1.0, idtp + idfn),", "idr=idtp / max( 0.0, idtp + idfn),",
     "idtp + idfn is the number of ground-truth detections, >= 1 past the early returns"),
    ("if data.n_tracker_dets == 0:", "if data.n_tracker_dets == -1:", _SHORTCUT, "identity"),
    ("if data.n_gt_dets == 0:", "if data.n_gt_dets == -1:", _SHORTCUT, "identity"),
    *[(f"{m} = 1e10", f"{m} = {v}", _FORBIDDEN)
      for m in ("fp_mat[ng:, :nt]", "fn_mat[:ng, nt:]")
      for v in ("10000000001.0", "9999999999.0")],
    *[("if data.n_tracker_dets == 0 or data.n_gt_dets == 0:", f"if {m}:", _SHORTCUT)
      for m in ("data.n_tracker_dets == -1 or data.n_gt_dets == 0",
                "data.n_tracker_dets == 0 and data.n_gt_dets == 0",
                "data.n_tracker_dets == 0 or data.n_gt_dets == -1")],
    *[("for gt_ids, trk_ids, sim in zip(data.gt_ids, data.tracker_ids, data.similarity, strict=True):",
       "for gt_ids, trk_ids, sim in zip(data.gt_ids, data.tracker_ids, data.similarity, strict=False):",
       "(hota only; clear's and identity's are killed) hota zips the same three tuples in "
       "two loops: the one left strict still raises on unequal lengths", "hota", after)
      for after in ("trk_count = np.zeros((1, nt))",
                    "tp, fn, fp, loca = zeros.copy(), zeros.copy(), zeros.copy(), zeros.copy()")],
    ("trk_count[0, trk_ids] += 1", "trk_count[ -1, trk_ids] += 1",
     "trk_count has one row: [-1] is [0]"),
    ("if len(gt_ids) == 0:", "if len(gt_ids) == -1:", "(hota) " + _EMPTY_LSA, "hota"),
    ("if len(trk_ids) == 0:", "if len(trk_ids) == -1:", "(hota) " + _EMPTY_LSA, "hota"),
    ("ass_a = mc / np.maximum(1, gt_count + trk_count - mc)",
     "ass_a = mc / np.maximum( 0, gt_count + trk_count - mc)",
     "mc <= min(gt_count, trk_count), so the denominator is >= max(gt_count, trk_count) "
     ">= 1 (" + _EVERY_ID + ")"),
    ("assre[a] = np.sum(mc * (mc / np.maximum(1, gt_count))) / np.maximum(1, tp[a])",
     "assre[a] = np.sum(mc * (mc / np.maximum( 0, gt_count))) / np.maximum(1, tp[a])",
     _EVERY_ID),
    ("asspr[a] = np.sum(mc * (mc / np.maximum(1, trk_count))) / np.maximum(1, tp[a])",
     "asspr[a] = np.sum(mc * (mc / np.maximum( 0, trk_count))) / np.maximum(1, tp[a])",
     _EVERY_ID),
]

# Round 18, every mutant of the generator's AR2 paths, compositor and ground truth:
EQUIVALENT["motion"] = [  # noqa: F821
    ("*,", "/,",
     "ar2_path's keyword-only marker read as an operator: every caller passes params, "
     "start, velocity and n by position; the mutant only also accepts rng, lo, hi, field "
     "by position"),
    ("limit = lo if c < lo else hi", "limit = lo if c <= lo else hi",
     "only reached for c outside [lo, hi]: c is never equal to lo there"),
]

_RESCAN = ("widens the test of a static entity's rectangle against the rectangles drawn over "
           "it: the entity is rescanned more often, and a rescan of labels that nothing was "
           "drawn over gives the static layer's statistics, which the shortcut copies")
_EMPTY_BOX = ("the box of an entity without visible pixels is never read (visible_box is "
              "NaN where the count is 0, and motion blur skips it); with pixels the first "
              "one found replaces the initial value")
_SAME = "assigns the value the variable already holds"
EQUIVALENT["compose"] = [  # noqa: F821
    *[(a, b, _RESCAN) for a, b in (
        ("drawn[d, 0] < bx1", "drawn[d, 0] <= bx1"),
        ("and bx0 < drawn[d, 2]", "and bx0 <= drawn[d, 2]"),
        ("and drawn[d, 1] < by1", "and drawn[d, 1] <= by1"),
        ("and by0 < drawn[d, 3]", "and by0 <= drawn[d, 3]"),
        ("and bx0 < drawn[d, 2]", "or bx0 < drawn[d, 2]"),
        ("and drawn[d, 1] < by1", "or drawn[d, 1] < by1"),
        ("and by0 < drawn[d, 3]", "or by0 < drawn[d, 3]"),
        ("touched = False", "touched = True"),
    )],
    ("break", "continue",
     "(_draw_frame) order is padded with -1 only at its end: continue skips the same "
     "entries; (_frame_stats) once touched is set, the remaining rectangles can only set "
     "it again", ("_draw_frame", "_frame_stats")),
    ("k_n = tidx.shape[0]", "k_n = tidx.shape[ -1]", "tidx is one-dimensional (K,)"),
    ("for k in range(tidx.shape[0]):", "for k in range(tidx.shape[ -1]):",
     "a frame's tidx is one-dimensional (K,)"),
    ("for j in range(order.shape[0]):", "for j in range(order.shape[ -1]):",
     "a frame's order is one-dimensional (D,)"),
    ("out_count[0] = n", "out_count[ -1] = n", "out_count has one element: [-1] is [0]"),
    ("out_count[k] = cnt[0]", "out_count[k] = cnt[ -1]", "cnt has one element: [-1] is [0]"),
    ("vis_count[k] = cnt[0]", "vis_count[k] = cnt[ -1]", "cnt has one element: [-1] is [0]"),
    ("drawn = np.empty((order.shape[1], 4), dtype=np.int64)",
     "drawn = np.empty((order.shape[1], 5), dtype=np.int64)",
     "a fifth column that nothing reads"),
    ("cnt = np.empty(1, dtype=np.int64)", "cnt = np.empty( 2, dtype=np.int64)",
     "a second element that nothing reads", ("scan_static", "render_chunk")),
    ("box = np.empty(4, dtype=np.int64)", "box = np.empty( 5, dtype=np.int64)",
     "a fifth element that nothing reads", ("scan_static", "render_chunk")),
    ("if c < cmin:", "if c <= cmin:", _SAME),
    ("if c > cmax:", "if c >= cmax:", _SAME),
    ("if r < rmin:", "if r <= rmin:", _SAME),
    ("if r > rmax:", "if r >= rmax:", _SAME),
    ("cmin, rmin, cmax, rmax, n = w, h, -1, -1, 0",
     "cmin, rmin, cmax, rmax, n = w, h, - 0, -1, 0", _EMPTY_BOX),
    ("cmin, rmin, cmax, rmax, n = w, h, -1, -1, 0",
     "cmin, rmin, cmax, rmax, n = w, h, -1, - 0, 0", _EMPTY_BOX),
    ("cmin, rmin, cmax, rmax, n = w, h, -1, -1, 0",
     "cmin, rmin, cmax, rmax, n = w, h, - 2, -1, 0", _EMPTY_BOX),
    ("cmin, rmin, cmax, rmax, n = w, h, -1, -1, 0",
     "cmin, rmin, cmax, rmax, n = w, h, -1, - 2, 0", _EMPTY_BOX),
    *[("vis_count[k] = 0", f"vis_count[k] = {v}",
       "the static layer's count of an entity outside it: only static entities' counts "
       "are read (is_static), and those are all in the layer") for v in ("1", "-1")],
    ("if ti < 0:", "if ti < -1:",
     "(in _frame_stats) an absent entity's label is nowhere in the frame's labels, so "
     "the scan, or the static layer's count, gives the 0 pixels the shortcut writes",
     "_frame_stats"),
]

_PARTIAL = "partial = present & ((x0 < 0) | (y0 < 0) | (x0 + tw[safe] > w) | (y0 + th[safe] > h))"
_EDGES = ("only chooses which entities crossing the frame's edge get the exact test of their "
          "in-frame alpha. Templates are cropped to their silhouette, so the template's "
          "outer row and column at each edge hold an opaque pixel: an entity crossing one "
          "edge, or none, always shows one. Only an entity crossing two edges (a corner, "
          "or wider or taller than the frame) can be wholly transparent in the frame, and "
          "the mutant still selects each such entity, or selects more, which the exact "
          "test keeps present")
EQUIVALENT["ground-truth"] = [  # noqa: F821
    *[(_PARTIAL, _PARTIAL.replace(a, b), _EDGES) for a, b in (
        ("y0 + th[safe] > h", "y0 - th[safe] > h"),
        ("y0 + th[safe] > h", "y0 + th[safe] >= h"),
        ("x0 + tw[safe] > w", "x0 - tw[safe] > w"),
        ("x0 + tw[safe] > w", "x0 + tw[safe] >= w"),
        ("(x0 + tw[safe] > w) | (y0", "(x0 + tw[safe] > w) & (y0"),
        ("(x0 < 0) | (y0 < 0)", "(x0 < 0) & (y0 < 0)"),
        ("(y0 < 0) | (x0", "(y0 < 0) & (x0"),
        ("(y0 < 0)", "(y0 < 1)"),
        ("(y0 < 0)", "(y0 <= 0)"),
        ("(x0 < 0)", "(x0 < 1)"),
        ("(x0 < 0)", "(x0 <= 0)"),
        ("(x0 < 0)", "(x0 < -1)"),
        ("(y0 < 0)", "(y0 < -1)"),
    )],
    (_PARTIAL, _PARTIAL.replace("present & (", "present | ("),
     "also tests the present entities inside the frame (their whole template, which has "
     "an opaque pixel: kept) and the absent ones (already not present)"),
    *[("if len(templates) > 1:", f"if len(templates) {m}:",
       "with one template the assignment to toff[1:] is empty") for m in ("> 0", ">= 1")],
    *[(f"for {a} in zip({b}, strict=True){c}", f"for {a} in zip({b}, strict=False){c}",
       "the zipped sequences have equal lengths by construction (the templates' offsets "
       "and sizes; np.nonzero's indices)")
      for a, b, c in (("o, hh, ww", "toff, th, tw", ""), ("f, k", "*np.nonzero(partial)", ":"))],
    ("else np.zeros(0, dtype=np.uint8)", "else np.zeros( 1, dtype=np.uint8)",
     "the buffer of no templates: nothing reads it"),
    ("amodal = np.where(present, alpha_count[safe], 1.0)",
     "amodal = np.where(present, alpha_count[safe], 2.0)",
     "the guard of a division whose value np.where discards for absent entities (0.0 "
     "is killed: 0/0 warns)"),
    ("safe = np.maximum(tidx, 0)", "safe = np.maximum(tidx, -1)",
     "an absent entity's size is then read from the last template: _drop_shapes_outside "
     "never tests absent entities, and _ground_truth replaces every value computed from "
     "it (box and centre by NaN, the silhouette's pixels by the guard 1)",
     ("_drop_shapes_outside", "_ground_truth")),
]

# 2026-12-03, every mutant of the MOTChallenge files (scenegen/io/mot.py, key mot-io):
_IDS_1D = ("the ids are one-dimensional (reshape(-1) in write_mot_tracker, np.array of a "
           "sorted list in read_mot_tracker_rows): shape[-1] is shape[0]")
EQUIVALENT["mot-io"] = [  # noqa: F821
    ("def write_mot_tracker(path: str | Path, boxes: ArrayLike, track_ids: ArrayLike) -> int:",
     "def write_mot_tracker(path: str & Path, boxes: ArrayLike, track_ids: ArrayLike) -> int:",
     _ANNOTATION),
    ("path: str | Path, n_frames: int", "path: str & Path, n_frames: int",
     "(read_mot_tracker, read_mot_tracker_rows) " + _ANNOTATION,
     ("read_mot_tracker", "read_mot_tracker_rows")),
    *[(line, line.replace("ids.shape[0]", "ids.shape[ -1]"), _IDS_1D) for line in (
        "if b.ndim != 3 or b.shape[1:] != (ids.shape[0], 4):",
        'raise ConfigError(f"boxes {b.shape} do not fit {ids.shape[0]} track ids")',
        "boxes = np.full((n_frames, ids.shape[0], 4), np.nan)",
        "rank = np.full((n_frames, ids.shape[0]), -1, dtype=np.int64)",
    )],
    *[("if not np.isnan(boxes[t, c, 0]):", f"if not np.isnan(boxes[t, c, {i}]):",
       "a row sets a box's four values at once, each finite (checked as it is read): all "
       "four are NaN or none is") for i in ("1", "-1")],
    ("ids = np.asarray(track_ids).astype(np.int64).reshape(-1)",
     "ids = np.asarray(track_ids).astype(np.int64).reshape(- 2)",
     "numpy reads any negative size in reshape as the one unknown dimension"),
]

# 2026-12-03, a sample of each histogram kernel (trackers/kernels/{integral,direct,profiles,
# quantize}.py): the box kernel's scratch rectangles, one row per level of the 1-d fracs.
_RECTS = "rects = np.empty((max(fracs.shape[0], 1), 4), dtype=np.int64)"
_RECTS_EQ = [
    (_RECTS, _RECTS.replace("shape[0]", "shape[ -1]"),
     "fracs is one-dimensional: shape[-1] is shape[0]"),
    (_RECTS, _RECTS.replace("1), 4)", "2), 4)"),
     "a larger scratch: rows past the levels' are never read (with no levels, the kernel "
     "is not the box kernel and rects is not read at all)"),
]
EQUIVALENT["integral"] = [  # noqa: F821
    *_RECTS_EQ,
    ("hgt = R1 - R0", "hgt = R1 + R0",
     "only sizes the integral array and picks its integer type in _integral_distances: "
     "_integral_score fills and reads the ROI's R1 - R0 + 1 rows of it, and the counts "
     "are the same integers in uint16 or int32", "_integral_distances"),
    # 2026-12-06, a seeded sample of 40: "(hgt + 1) / (wid + 1)" (16-bit counts on any ROI)
    # is killed by a 300 x 300 ROI test; these are not.
    ("for t in range(sq.shape[0]):", "for t in range(sq.shape[ -1]):",
     "sq is one-dimensional (its support bins): shape[-1] is shape[0]"),
    ("bounds = np.empty(n_parts + 1, dtype=np.int64)",
     "bounds = np.empty(n_parts + 2, dtype=np.int64)",
     "a last element that nothing writes or reads"),
    (_RECTS, _RECTS.replace("1), 4)", "1), 5)"), "a fifth column that nothing writes or reads"),
    ("if (hgt + 1) * (wid + 1) < 65536:", "if (hgt + 1) * (wid + 0) < 65536:",
     "a count is at most the ROI's hgt * wid pixels, and (hgt + 1) * wid < 65536 still "
     "bounds that below 2**16: 16-bit counts hold the same integers"),
    ("if r0 >= r1 or c0 >= c1:", "if r0 > r1 or c0 >= c1:",
     "with r0 == r1 the box has no row: _band_rows gives every band an empty row range, "
     "and each band adds its empty_rho, in the same order as the guarded branch"),
]
EQUIVALENT["direct"] = [  # noqa: F821
    *_RECTS_EQ,
    (_RECTS, _RECTS.replace("1), 4)", "1), 5)"), "a fifth column that nothing writes or reads"),
    ("if dy2 >= 1.0:", "if dy2 >= 2.0:",
     "rows with 1 <= dy^2 < 2 lie outside the ellipse: their Epanechnikov row weight "
     "(1 - dy^2 in fixed point) is <= 0 and their cone weights 1 - r < 0, all clamped to 0",
     ("_accumulate", "_accumulate_support")),
    ("return 4 if dim <= _SMALL_BINS else 1", "return 3 if dim <= _SMALL_BINS else 1",
     "any lane count but 4 takes _scatter's one-copy loop; the copies it leaves at zero "
     "add nothing when the copies are summed"),
    # 2026-12-06, a seeded sample of 30 (after the scratch rows became W wide): 3 survived;
    # "totals[j] > 1" and "part = n_parts - 0" are killed by tests of a rim pixel of one
    # fixed-point unit and of a last row that rounds into a band past the last.
    ("if r0 >= r1 or c0 >= c1:", "if r0 > r1 or c0 >= c1:",
     "with r0 == r1 the box has no row: the row loop does not run and totals (and sums) "
     "stay at the zeros set above; only the column table or rectangles are computed",
     ("_accumulate", "_accumulate_support")),
]
# The three mutants of _box_row_weights' last loop (the columns of a row no rectangle
# covers; two listed here on 2026-12-03, one on 12-06 below) were excused until 2026-12-07
# (stop 61) because the histogram paths never pass such a row; they are killed since by
# test_a_rows_weights_sum_the_levels_covering_each_pixel, which calls the function on the
# rows just above and below the box.
EQUIVALENT["profiles"] = []  # noqa: F821
EQUIVALENT["histogram"] = [  # noqa: F821
    # 2026-12-05, the path choice made observable (region_paths, and the direct-path mask
    # _region_distances returns): "n_groups += 0" and the "n_boxes > 0" guard were
    # equivalent while only the distances were compared; the first is now killed by
    # tests/trackers/models/test_histogram_paths.py, the second's line is gone.
    # The same day, the sample's eight unexamined survivors: the support path's choice
    # (now _support_colours, tested), the level count and the area (killed either side
    # of the cost model's tie), the empty-boxes guard (gone; the plan's order is tested
    # as a permutation) and the scratch rows' slack (gone: they are the frame's width).
    ("n_chunks = max(min(n_chunks, n_boxes), 1)", "n_chunks = max(min(n_chunks, n_boxes), 0)",
     "n_chunks (the thread count) is at least 1: the bound is 0 only with no boxes, when "
     "there is nothing to score"),
    ("for g in prange(integral.shape[0]):", "for g in prange(integral.shape[ -1]):",
     "integral is one-dimensional (G,): shape[-1] is shape[0]"),
    ("rects = np.empty((a_fixed.shape[0], 4), dtype=np.int64)",
     "rects = np.empty((a_fixed.shape[0], 5), dtype=np.int64)",
     "a fifth column that nothing writes or reads"),
    ("rects = np.empty((a_fixed.shape[0], 4), dtype=np.int64)",
     "rects = np.empty((a_fixed.shape[ -1], 4), dtype=np.int64)",
     "a_fixed is one-dimensional (L,): shape[-1] is shape[0]"),
    ("n_levels = max(a_fixed.shape[0], 1)", "n_levels = max(a_fixed.shape[ -1], 1)",
     "a_fixed is one-dimensional (L,): shape[-1] is shape[0]"),
    ("if q[r, b] > 0:", "if q[r, b] >= 0:",
     "bins where q = 0 join the support: each adds sqrt(p) * 0 = +0.0 to rho (the same "
     "bits) and 0 to the empty band's rho; they only make the support path or the "
     "integral's channels less likely, both bit-identical to the whole histogram"),
    # 2026-12-06, a seeded sample of 40 after the eight were dealt with: 34 killed, 6
    # survived; "roi[1] >= roi[0]" is killed by a frame with no rows, these five are not.
    ("for p in range(ch * n_boxes // n_chunks, (ch + 1) * n_boxes // n_chunks):",
     "for p in range(ch / n_boxes // n_chunks, (ch + 1) * n_boxes // n_chunks):",
     "every chunk starts at box 0 (ch / n_boxes < 1): the chunks overlap and score boxes "
     "again, each alone from zeroed scratch, so every write is the same value; only the "
     "time grows"),
    ("roi_pixels = max(roi[1] - roi[0], 0) * max(roi[3] - roi[2], 0) * 1.0",
     "roi_pixels = max(roi[1] - roi[0], 1) * max(roi[3] - roi[2], 0) * 1.0",
     "the ROI's height is <= 0 only when no member has a pixel, and then its width "
     "(0 - cols) is <= 0 too: the product is 0 either way"),
    ("roi[0], roi[1], roi[2], roi[3] = rows, 0, cols, 0",
     "roi[0], roi[1], roi[2], roi[3] = rows, 0, cols, -1",
     "a member with a pixel sets roi[3] to its c1 > 0 either way; with none, the width is "
     "negative either way (clipped to 0) and roi[1] > roi[0] sends the group direct"),
    ("ref = ref_index[members[0]]", "ref = ref_index[members[ -1]]",
     "a group's members share one reference (_reference_groups groups by it)",
     ("_plan_paths", "_region_distances")),
    ("*,", "/,",
     "every caller passes bin_img to kernel by position and method, box_levels by "
     "keyword: the mutant only also accepts the last two by position", "region_paths"),
]

# 2026-12-03, a seeded sample of 40 mutants of the compiled stages (key stages):
_STAGES_1D = "the array is one-dimensional (the weights (N,), the group sizes (C,)): shape[-1] is shape[0]"
EQUIVALENT["stages"] = [  # noqa: F821
    ("n = w.shape[0]", "n = w.shape[ -1]", _STAGES_1D),
    ("for g in range(sizes.shape[0]):", "for g in range(sizes.shape[ -1]):", _STAGES_1D,
     ("_normalise_groups", "_group_max_shift", "_final_log_weights")),
    ("f_lo = np.empty(64, dtype=np.int64)", "f_lo = np.empty( 63, dtype=np.int64)",
     "the explicit stack of the pairwise recursion holds one frame per halving of N / 128: "
     "63 frames would take N of about 2**69"),
    ("n = logw.shape[0]", "n = logw.shape[ -1]", _STAGES_1D),
    ("total = _numpy_sum(e, 0, e.shape[0])", "total = _numpy_sum(e, 0, e.shape[ -1])", _STAGES_1D),
    ("out = np.empty(x.shape[0])", "out = np.empty(x.shape[ -1])", _STAGES_1D,
     ("_group_max_shift", "_max_shift")),
    ("for i in range(x.shape[0]):", "for i in range(x.shape[ -1]):",
     "in _max_shift, of a one-dimensional array (the same line in _row_max_shift, of a "
     "(K, N) array, is killed: test_row_max_shift_and_normalise_rows_are_the_numpy_ones)",
     "_max_shift"),
    ("shifted = np.empty((2, n))", "shifted = np.empty(( 3, n))",
     "a third row of the reassembly's shifted logs that nothing reads (the sums take rows 0 and 1)"),
    ("NDArray[np.float64], NDArray[np.float64]] | None:",
     "NDArray[np.float64], NDArray[np.float64]] & None:",
     "an annotation: never evaluated (from __future__ import annotations)"),
    ("for j in range(1, x.shape[1]):", "for j in range( 0, x.shape[1]):",
     "the row's maximum starts at x[i, 0]: comparing x[i, 0] with it again changes nothing"),
]

# 2026-12-03, a seeded sample of 40 mutants of the compiled draws and distinct counts
# (trackers/kernels/sampling.py, key sampling):
_HASH = ("a constant of the hash of count_distinct's table: the hash only chooses where "
         "a row's probe starts; whether a row is new is decided by comparing the rows")
EQUIVALENT["sampling"] = [  # noqa: F821
    *[("h = (h ^ np.uint64(bits[i, obj, c])) * np.uint64(1099511628211)",
       f"h = (h ^ np.uint64(bits[i, obj, c])) * np.uint64( {m})", _HASH)
      for m in ("1099511628212", "1099511628210")],
    ("h = np.uint64(1469598103934665603)", "h = np.uint64( 1469598103934665604)", _HASH),
    ("h = (h ^ np.uint64(bits[i, obj, c])) * np.uint64(1099511628211)",
     "h = (h | np.uint64(bits[i, obj, c])) * np.uint64(1099511628211)",
     "the hash's mixing, or for xor: a worse spread of the probes' starts; whether a row "
     "is new is decided by comparing the rows"),
    ("while size < 2 * n:", "while size < 3 * n:",
     "a larger table (at most a third full instead of half): the probes end at a free slot "
     "or at an equal row either way"),
    ("for c in range(3):", "for c in range( 2):",
     "the hash of (u, v) only: " + _HASH.split(": ", 1)[1]),
    ("if u != u or v != v or a != a:", "if u != u and v != v or a != a:",
     "a shortcut: a row whose NaN is in u or v alone then goes through the table, where "
     "it equals no stored row (NaN != NaN) and so is counted once as new, as the shortcut "
     "counts it; the table (at least 2 N slots) never fills"),
    ("h ^= h >> np.uint64(29)", "h ^= h << np.uint64(29)", _HASH),
    ("slot = (slot + np.uint64(1)) & mask", "slot = (slot - np.uint64(1)) & mask",
     "linear probing downwards instead of upwards: modulo the power-of-two table size it "
     "still visits every slot, and the table is never more than half full"),
]

# 2026-12-06 (stop 49), every mutant of the new lines: the inverse-CDF draw's scan of sorted
# positions, the posterior row sums and the compiled box clipping.
_SCAN = ("only chooses between scanning on from the previous index and bisecting the "
         "group: both give the first index whose cdf exceeds u (the last if none does), "
         "because the cdf does not decrease and a scan starts only where u did not "
         "decrease either (test_inverse_cdf_groups_is_a_search_of_each_groups_cdf); the "
         "choice changes the time only")
EQUIVALENT["sampling"] += [  # noqa: F821
    ("if mode != MULTINOMIAL:", "if mode == MULTINOMIAL:", _SCAN),
    ("if mode != MULTINOMIAL:", "if not mode != MULTINOMIAL:", _SCAN),
    ("if not u >= last_u:", "if not u > last_u:", _SCAN),
]
EQUIVALENT["stages"] += [  # noqa: F821
    ("if centre < 0.0:", "if centre <= 0.0:",
     "a centre of exactly 0 set to 0: the box returned is the same (a centre of -0.0, from "
     "a size of -0.0, gives x = 0.0 - -0.0 = -0.0 - -0.0 = 0.0 either way)"),
    ("elif centre > top:", "elif centre >= top:",
     "a centre of exactly the frame's width or height set to that value: the same"),
    ("row = _pairwise_block(flat, r * k, k) if k <= _BLOCK else _pairwise(flat, r * k, k)",
     "row = _pairwise_block(flat, r * k, k) if k < _BLOCK else _pairwise(flat, r * k, k)",
     "a row of exactly 128 terms taken by _pairwise, which sums a block of at most 128 "
     "terms with _pairwise_block: the same sum"),
]

# 2026-12-06 (stop 50), a new seeded sample of 80 of the compiled stages (the module
# changed at stop 49, so the sample of 12-03 was stale): 67 killed, 5 listed above,
# these 8 survived and are equivalent.
EQUIVALENT["stages"] += [  # noqa: F821
    ("return None if out[0].shape[0] == 0 else out",
     "return None if out[ -1].shape[0] == 0 else out",
     "out[-1] is the new states, (0, 3) exactly when the weights out[0] are (0,) (the "
     "kernel returns both empty on failure, both with N rows otherwise)",
     "resample_propagate"),
    ("return None if out[0].shape[0] == 0 else out",
     "return None if out[0].shape[ -1] == 0 else out",
     "out[0], the weights, is one-dimensional: shape[-1] is shape[0]",
     "resample_propagate"),
    ("sums = np.empty((2, c))", "sums = np.empty(( 3, c))",
     "a third row of the reassembly's sums that nothing writes or reads (the caller takes "
     "rows 0 and 1)"),
    ("n = a.shape[0]", "n = a.shape[ -1]", _STAGES_1D),
    (") -> tuple[NDArray[np.float64], ...] | None:",
     ") -> tuple[NDArray[np.float64], ...] & None:",
     "an annotation: never evaluated (from __future__ import annotations)"),
    ("for i in range(start + 1, start + sizes[g]):",
     "for i in range(start + 0, start + sizes[g]):",
     "the group's maximum also compared with its own first value, m = max(m, m): the same "
     "m (NaN stays NaN, -0.0 stays -0.0)"),
    ("f_n = np.empty(64, dtype=np.int64)", "f_n = np.empty( 65, dtype=np.int64)",
     "a longer explicit stack of which the recursion uses at most log2(N / 128) frames"),
    ("wr = weights[r, 0] if shared else weights[r, o]",
     "wr = weights[r, -1] if shared else weights[r, o]",
     "shared means weights has one column: column -1 is column 0"),
]

# 2026-12-07 (stop 58), every mutant of the estimate's mean and variance and of the
# states' boxes (_weighted_mean_states, _state_boxes: 64 in scope, --timeout 240), run to
# the end: 62 killed, one equivalent listed above, this one survived:
EQUIVALENT["stages"] += [  # noqa: F821
    ("total = np.zeros((k, 3))", "total = np.zeros((k, 4))",
     "a fourth column of the sums that nothing writes: the variance reads avg[o, c] for "
     "c < 3 only, and avg is not returned"),
]

# 2026-12-07 (stop 58), every mutant of the row sums, the shifts by the maximum, the
# normalisations and the box clipping (89 in scope, --timeout 240): 77 killed, 7
# survivors already listed; "range( 2, x.shape[1])" in _row_max_shift (the maximum in
# the second column) is killed by test_row_max_shift_and_normalise_rows_are_the_numpy_ones;
# these survived:
_ROW_TERMS = "a, the terms added to the row sums (N,), is one-dimensional: shape[-1] is shape[0]"
EQUIVALENT["stages"] += [  # noqa: F821
    ("for i in range(1, x.shape[0]):", "for i in range(1, x.shape[ -1]):", _STAGES_1D),
    ("for i in range(1, x.shape[0]):", "for i in range( 0, x.shape[0]):",
     "the maximum starts at x[0]: comparing x[0] with it again changes nothing"),
    ("out = np.empty(a.shape[0])", "out = np.empty(a.shape[ -1])", _ROW_TERMS),
    ("for r in range(a.shape[0]):", "for r in range(a.shape[ -1]):", _ROW_TERMS),
]

# 2026-12-07 (stop 58), every mutant of _numpy_sum and _numpy_reduceat_sum (13): 11
# killed; the two survivors showed that a group of 2-8 terms all -0.0 summed to +0.0
# where np.add.reduceat gives -0.0 (numpy starts its short loop at -0.0; _pairwise_block
# now does, test_reduceat_sum_keeps_the_sign_of_zero_groups). Since then they are these:
_EMPTY_REST = ("a group of one: its element plus the empty rest's sum, which is -0.0, is the "
               "element itself (x + -0.0 is x for every x, -0.0 and NaN included)")
EQUIVALENT["stages"] += [  # noqa: F821
    ("if n > 1:", "if n >= 1:", _EMPTY_REST),
    ("if n > 1:", "if n > 0:", _EMPTY_REST),
]

# 2026-12-06 (stop 50), every mutant of sampling (136 in scope), stopped after 41 for
# the session's time: 36 killed, 5 survived. "particles + 1.0" is killed by
# test_count_distinct_tells_values_apart_closer_than_any_shift_keeps; "cdf[stop - 1] = 2.0"
# showed the line was never read (removed); "u > last_u" is listed above; these two:
EQUIVALENT["sampling"] += [  # noqa: F821
    ("table[:] = -1", "table[:] = - 2",
     "the empty-slot mark is tested as j < 0: any negative value marks a free slot"),
    ("while size < 2 * n:", "while size <= 2 * n:",
     "a table twice as large when 2 N is a power of two: the probes end at a free "
     "slot or at an equal row either way"),
]

# 2026-12-07 (stop 54), every mutant of sampling (131 in scope), run to the end with
# --timeout 120 (the survivors' test runs took 35-45 s); these survived:
EQUIVALENT["sampling"] += [  # noqa: F821
    ("slot = (slot + np.uint64(1)) & mask", "slot = (slot + np.uint64( 2)) & mask",
     "probing every other slot: the table has a power-of-two size of at least 2 N, so the "
     "slots of the start's parity number at least N, more than the at most N - 1 rows "
     "stored before any insertion, and the probe reaches a free slot; an equal row was "
     "stored at the first free slot of the same sequence, which slots never leave, so "
     "it is met before any free slot"),
    ("while size < 2 * n:", "while size < 1 * n:",
     "a table of at least N slots instead of 2 N: at most N - 1 rows are stored before "
     "any insertion, so linear probing still reaches a free slot or an equal row (the "
     "probes are longer, the count the same)"),
    *[("h ^= h >> np.uint64(29)", f"h ^= h >> np.uint64( {m})", _HASH) for m in (28, 30)],
    ("h = np.uint64(1469598103934665603)", "h = np.uint64( 1469598103934665602)", _HASH),
    ("if u != u or v != v or a != a:", "if u != u or v != v and a != a:",
     "a shortcut: a row whose NaN is in v or a alone then goes through the table, where "
     "it equals no stored row (NaN != NaN) and is counted once as new, as the shortcut "
     "counts it; stored, it equals no later row either; the table (at least 2 N slots) "
     "never fills"),
    ("cdf = np.empty(weights.shape[0])", "cdf = np.empty(weights.shape[ -1])",
     "the weights are one-dimensional: shape[-1] is shape[0]"),
    ("n_groups = sizes.shape[0]", "n_groups = sizes.shape[ -1]",
     "the group sizes are one-dimensional: shape[-1] is shape[0]"),
    ("break", "continue",
     "after storing a new row: the probe reads the slot again, finds that row, which "
     "equals itself (no row with a NaN reaches the table), and breaks there",
     "_count_distinct", "out[obj] += 1"),
]

# 2026-12-06 (stop 49), wider samples of the two kernel modules not re-run since 12-03:
# quantize 60 of 140 (59 killed), profiles 40 of 152 (34 killed; the cone's rounding,
# "+ -0.5", is killed by test_a_cone_weight_below_one_fixed_point_unit_rounds_to_one).
# quantize's one equivalent then, the hue bin's clamp (h_bins - 1 -> h_bins + 1), and a
# second one found by the full run of 2026-12-07 (-> h_bins - 0) showed the clamp can never
# act (h6 <= 6 d - 1); it was removed from the kernel, so quantize lists none.
EQUIVALENT["profiles"] += [  # noqa: F821
    ("n_levels = a_fixed.shape[0]", "n_levels = a_fixed.shape[ -1]",
     "a_fixed is one-dimensional: shape[-1] is shape[0]"),
    ("if r < b < nxt:", "if r < b <= nxt:",
     "a bound equal to the current next change sets it to the same row"),
    ("for e in range(2):", "for e in range( 3):",
     "a column bound taken as a row where the rectangles change only makes the caller "
     "recompute a row's weights where they have not changed: the same weights"),
]

# 2026-12-07 (stop 60), every mutant of the pixel ranges and the kernels' row weights
# (_first_inside, _pixel_range, _cone_weights, _epanechnikov_weights, _level_args): 37,
# 34 killed, the 3 others the clipping's bounds taken inclusively; and of the box kernel's
# rectangles (_level_rects): 29; and _next_change: 9, 6 killed, 2 already listed, 1 below.
EQUIVALENT["profiles"] += [  # noqa: F821
    ("if r < b < nxt:", "if r <= b < nxt:",
     "a bound at the current row r makes r the next change, so the caller recomputes the "
     "next row's weights from the rectangles alone (_box_row_weights keeps no state): the "
     "same weights, one more computation"),
    ("for lv in range(fracs.shape[0]):", "for lv in range(fracs.shape[ -1]):",
     "the level fractions are one-dimensional: shape[-1] is shape[0]"),
    ("if i0 < 0:", "if i0 <= 0:", "a first index of exactly 0 is set to 0: the same index"),
    ("if i0 < 0:", "if i0 < 1:", "a first index of exactly 0 is set to 0: the same index"),
    ("if i1 > n:", "if i1 >= n:", "an end index of exactly n is set to n: the same index"),
]

# 2026-12-07 (stop 61), every mutant of box_kernel_levels and _box_row_weights (77, 25 of
# them in earlier runs): 70 killed at first. Killed since by new tests in
# test_box_kernel.py: 16 levels refused (levels < 16; the extreme counts are accepted),
# and the four mutants that write a row no rectangle covers (the last loop's three, and
# "first - 2", which fills such a row with the box's level weight). Equivalent:
EQUIVALENT["profiles"] += [  # noqa: F821
    ("if ihi <= ilo:", "if ihi < ilo:",
     "an inner level whose columns in [lo, hi) are empty at ilo == ihi = v: both write "
     "[lo, hi) with the same weight, and the mutant leaves lo == hi == v instead of hi; "
     "the rectangles nest (test_the_outermost_rectangle_is_the_box_and_the_rectangles_"
     "nest), so every further level's columns are [v, v) as well and write nothing"),
]

# 2026-12-06 (stop 50), the comparisons users pin their trackers with, every mutant:
# compare 30 (23 killed at first; 6 survivors killed by new tests in test_compare.py),
# distribution 101 (83 killed at first; 17 survivors killed by new tests in
# test_distribution.py). The one left in each is an annotation.
EQUIVALENT["compare"] = [  # noqa: F821
    (") -> str | None:", ") -> str & None:",
     "an annotation: never evaluated (from __future__ import annotations)"),
]
EQUIVALENT["distribution"] = [  # noqa: F821
    (") -> str | None:", ") -> str & None:",
     "an annotation: never evaluated (from __future__ import annotations)"),
]

# 2026-12-06 (stop 50), every mutant of the conformance checks (185 in scope): 142 killed
# at first; of the 43 survivors, 31 were killed by new tests in test_conformance.py
# (--retest) and these 12 are equivalent.
_ANNOTATION = "an annotation: never evaluated (from __future__ import annotations)"
EQUIVALENT["checks"] = [  # noqa: F821
    ("def one(seed: int) -> str | None:", "def one(seed: int) -> str & None:", _ANNOTATION,
     "check_translation_equivariance"),
    ("def one(seed: int) -> str | None:", "def one(seed: int) -> str & None:", _ANNOTATION,
     "_iou_check"),
    ("def _judge(opts: Options, name: str, one: Callable[[int], str | None]) -> str:",
     "def _judge(opts: Options, name: str, one: Callable[[int], str & None]) -> str:",
     _ANNOTATION),
    ("run.error += _writes_hint(lambda f: tracker.init(f, init.copy()), frames[0])",
     "run.error += _writes_hint(lambda f: tracker.init(f, init.copy()), frames[ -1])",
     "the hint repeats init on a writable copy of a frame of the scene to see whether it "
     "writes into it: a tracker that writes into the frame it is given does so on any "
     "frame (only a write of the very values a frame holds could be seen on one and not "
     "the other)"),
    ("worst = np.nan_to_num(err, nan=0.0).max(axis=-1)  # (T, K)",
     "worst = np.nan_to_num(err, nan= -1.0).max(axis=-1)  # (T, K)",
     "the error is NaN only where both views lost the target (one view alone is reported "
     "before): -1 or 0, both within any tolerance (equivariance_tol >= 0 is checked)"),
    ("worst = np.nan_to_num(err, nan=0.0).max(axis=-1)  # (T, K)",
     "worst = np.nan_to_num(err, nan=0.0).max(axis=- 2)  # (T, K)",
     "the shifted scene has one target (K = 1): the maximum over K then over (x, y) is "
     "the maximum over (x, y), and the frame found is the same"),
    ("diff[np.isnan(a.boxes) & np.isnan(b.boxes)] = 0.0",
     "diff[np.isnan(a.boxes) & np.isnan(b.boxes)] = -1.0",
     "reached only when the runs differ, so some element is > 0: the first frame with "
     "diff > 0 and the largest difference are the same"),
    ("raise AssertionError(failures[0][1])", "raise AssertionError(failures[ -1][1])",
     "one seed: at most one failure, so the first is the last"),
    ("ran = [n for n, r in runs.items() if r.boxes is not None and len(r.boxes) > 1]",
     "ran = [n for n, r in runs.items() if r.boxes is not None and len(r.boxes) > 2]",
     "no conformance scene has exactly two frames (1, 6, 8, 12, 12 and 14)"),
    *[("lost = sum(int(np.isnan(runs[n].boxes[1:, :, 0]).sum()) for n in ran)",
       f"lost = sum(int(np.isnan(runs[n].boxes[1:, :, {c}]).sum()) for n in ran)",
       "the count is reached only when no estimate was malformed, so every row is all NaN "
       "or finite: any column is NaN exactly where column 0 is") for c in ("-1", "1")],
    ("lost = sum(int(np.isnan(runs[n].boxes[1:, :, 0]).sum()) for n in ran)",
     "lost = sum(int(np.isnan(runs[n].boxes[ 0:, :, 0]).sum()) for n in ran)",
     "frame 0 holds the initial boxes, the ground truth of targets present: never NaN"),
]

# 2026-12-06 (stop 52), every mutant of the hypothesis strategies (541 in scope).
_FITS = ("the canvas less twice the margin is at least min_size >= 1 (_check_fits, on the "
         "smallest canvas a scene may draw), and so are max_size and every target's side: "
         "the max() with 1 never acts, so max() with 0 is the same")
EQUIVALENT["strategies"] = [  # noqa: F821
    ("def _draw_camera(draw: Any, n_frames: int) -> Camera | None:",
     "def _draw_camera(draw: Any, n_frames: int) -> Camera & None:", _ANNOTATION),
    ("def _draw_photometric(draw: Any) -> Photometric | None:",
     "def _draw_photometric(draw: Any) -> Photometric & None:", _ANNOTATION),
    ("configs: SearchStrategy[SceneConfig] | None = None,",
     "configs: SearchStrategy[SceneConfig] & None = None,", _ANNOTATION),
    ("seeds: SearchStrategy[int] | None = None,",
     "seeds: SearchStrategy[int] & None = None,", _ANNOTATION),
    ("max_size: float | None = None,", "max_size: float & None = None,", _ANNOTATION),
    ("span_w = max(1, min(max_size, int(width - 2 * margin)))",
     "span_w = max( 0, min(max_size, int(width - 2 * margin)))", _FITS),
    ("span_h = max(1, min(max_size, int(height - 2 * margin)))",
     "span_h = max( 0, min(max_size, int(height - 2 * margin)))", _FITS),
    ("ow = max(1, min(tw + 2 * pad, int(width - 2 * margin)))",
     "ow = max( 0, min(tw + 2 * pad, int(width - 2 * margin)))", _FITS),
    ("oh = max(1, min(th + 2 * pad, int(height - 2 * margin)))",
     "oh = max( 0, min(th + 2 * pad, int(height - 2 * margin)))", _FITS),
    ("plain = ClutterSpec(count=0)", "plain = ClutterSpec(count= 1)",
     "only the default palette and n_colors are read from it"),
]

# 2026-12-07 (stop 55), every mutant of the DPS formulas of the compiled stages (146 in
# scope: the stage log-weights, the reassembly, the group shifts and normalisation, the
# AR2 propagation, the effective dynamics); 129 killed, 17 survived: 9 listed above, 2
# killed by new tests (σ² > 1 for σ² > 0 in _effective_uv; a group's maximum that skips
# its second value), these 6 equivalent.
EQUIVALENT["stages"] += [  # noqa: F821
    ("c = sizes.shape[0]", "c = sizes.shape[ -1]", _STAGES_1D),
    ("n = stage.shape[0]", "n = stage.shape[ -1]", _STAGES_1D),
    ("top = np.empty(sizes.shape[0])", "top = np.empty(sizes.shape[ -1])", _STAGES_1D),
    ("out = np.empty(logw.shape[0])", "out = np.empty(logw.shape[ -1])", _STAGES_1D),
    ("for c in range(sizes.shape[0]):", "for c in range(sizes.shape[ -1]):", _STAGES_1D),
    ("e = np.empty(2)", "e = np.empty( 3)",
     "a third slot of the (u, v) effective dynamics that nothing writes or reads"),
]
# 2026-12-07 (stop 57), every mutant of the weighted resampling and gathers of the
# compiled stages (85 in scope: _gather_pair, _gather_placed, _weighted_resample_gather,
# _scope and the two wrappers, _resample_propagate; 12 of them in the sample of 12-06):
# 64 killed, 21 survived: 5 listed above, 2 killed by new tests (one invalid factor, π
# or g, whose product still sums positive; a single particle, N = 1), these 14
# equivalent.
_DISCARDED = ("an early return's unused slot: the wrapper returns None whenever the "
              "weights are empty, and _resample_propagate never reads the ancestors")
_ANNOTATION = "an annotation: never evaluated (from __future__ import annotations)"
EQUIVALENT["stages"] += [  # noqa: F821
    *[("return w, x2, prev2, ll2, g2, np.empty((0, 3))",
       f"return w, x2, prev2, ll2, g2, np.empty({m})", _DISCARDED)
      for m in ("(0, 2)", "( 1, 3)", "(0, 4)")],
    ("return np.empty(0), np.empty(0, dtype=np.int64), x, prev, ll, log_g",
     "return np.empty(0), np.empty( 1, dtype=np.int64), x, prev, ll, log_g", _DISCARDED,
     "_weighted_resample_gather", "if not (_valid(a) and _valid(b)):"),
    ("return np.empty(0), np.empty(0, dtype=np.int64), x, prev, ll, log_g",
     "return np.empty(0), np.empty( 1, dtype=np.int64), x, prev, ll, log_g", _DISCARDED,
     "_weighted_resample_gather", "if not ok:"),
    ("if w.shape[0] == 0:", "if w.shape[ -1] == 0:", _STAGES_1D),
    ("if w.shape[0] == 0:", "if w.shape[0] == -1:",
     "never true: invalid weights then propagate the unchanged x, prev (a copy's worth of "
     "work), and the wrapper still returns None, the weights being empty"),
    ("n = idx.shape[0]", "n = idx.shape[ -1]", _STAGES_1D),
    ("return None if out[0].shape[0] == 0 else out",
     "return None if out[0].shape[ -1] == 0 else out", _STAGES_1D,
     "weighted_resample_gather"),
    ("return None if out[0].shape[0] == 0 else out",
     "return None if out[ 1].shape[0] == 0 else out",
     "out[1] is the ancestors (N,), empty exactly when the weights are (not so in "
     "resample_propagate, whose out[1] is x: that copy's mutant is killed)",
     "weighted_resample_gather"),
    ("new[i] = 1.0 / b[idx[i]]", "new[i] = 2.0 / b[idx[i]]",
     "the new weights are normalised per group next: doubling is exact in binary floating "
     "point and cancels, bit for bit, unless 1/g is within a factor 2 of overflow "
     "(g < 1.2e-308; g = exp(log g − max) reaches it only for log-weight spreads over "
     "708, where the group's sum overflows anyway)"),
    ("placed: NDArray[np.bool_] | None = None,", "placed: NDArray[np.bool_] & None = None,",
     _ANNOTATION, ("weighted_resample_gather", "resample_propagate")),
    ("def _scope(placed: NDArray[np.bool_] | None) -> tuple[bool, NDArray[np.bool_]]:",
     "def _scope(placed: NDArray[np.bool_] & None) -> tuple[bool, NDArray[np.bool_]]:",
     _ANNOTATION),
]

# 2026-12-07 (stop 59), every mutant of numpy's pairwise sum (_pairwise_block: 80, all
# killed, one by the timeout: `i += 0`, a loop that cannot end; _pairwise: 94), run to
# the end: of _pairwise's 12 survivors, 2 listed above, 1 killed by a new test (a half of
# exactly 128 terms split as 64 + 64), these 9 equivalent.
_STACK = ("the explicit stack of the pairwise recursion uses one frame (and holds at most "
          "one pending value) per halving of N / 128: 63 would take N of about 2**69, and "
          "a longer stack is never reached")
EQUIVALENT["stages"] += [  # noqa: F821
    ("f_lo = np.empty(64, dtype=np.int64)", "f_lo = np.empty( 65, dtype=np.int64)", _STACK),
    ("f_n = np.empty(64, dtype=np.int64)", "f_n = np.empty( 63, dtype=np.int64)", _STACK),
    ("f_state = np.empty(64, dtype=np.int64)", "f_state = np.empty( 63, dtype=np.int64)",
     _STACK),
    ("f_state = np.empty(64, dtype=np.int64)", "f_state = np.empty( 65, dtype=np.int64)",
     _STACK),
    ("vals = np.empty(64)", "vals = np.empty( 63)", _STACK),
    ("vals = np.empty(64)", "vals = np.empty( 65)", _STACK),
    ("n2 = m // 2", "n2 = m / 2",
     "a float half: n2 - n2 % 8 is then 8 floor(m / 16) as a float, the same multiple of "
     "8 as with integer division, stored exactly into the int64 stack (m < 2**53)"),
    ("if n <= _BLOCK:", "if n < _BLOCK:",
     "a sum of exactly 128 terms goes onto the stack, whose first frame (m = 128 <= "
     "_BLOCK) sums it with _pairwise_block: the same sum"),
    ("f_state[top] = 2", "f_state[top] = 3",
     "the frame's third visit: every state but 0 and 1 takes the last branch (left + "
     "right)"),
]
