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
