"""Equivalent mutants of the formula modules, read by ``mutate.py``.

EQUIVALENT[module] lists (original line, mutated line, reason), each line stripped of
surrounding spaces as it appears in cosmic-ray's diff. A surviving mutant listed here is
reported as equivalent and left out of the score.
"""

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
]
EQUIVALENT["resampling"] += [  # noqa: F821
    ("sizes = _check_sizes(sizes, w.shape[0] if w.ndim == 1 else -1)",
     "sizes = _check_sizes(sizes, w.shape[0] if w.ndim == 1 else - 2)",
     "-1 is only a size no group list can sum to; -2 is one too"),
    ("resid[np.repeat(totals <= 0, sizes)] = 1.0", "resid[np.repeat(totals <= 0, sizes)] = 2.0",
     "dummy mass of a group that receives no draw: any positive value"),
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
     "a row at dy2 = 1 has weights 1 - (dx^2 + 1) <= 0 for both kernels: skipped anyway"),
]

EQUIVALENT["kalman"] = [  # noqa: F821
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
]
EQUIVALENT["shm"] += [  # noqa: F821
    ("np.zeros((boxes.shape[0], m.dim)), m.P0, m.F, m.Q, m.H, np.eye(2) * self.params.r_floor",
     "np.zeros((boxes.shape[0], m.dim)), m.P0, m.F, m.Q, m.H, np.eye(2) / self.params.r_floor",
     "the filter's default R is never used: every update passes its own R"),
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
