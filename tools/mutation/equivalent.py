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
]
EQUIVALENT["resampling"] += [  # noqa: F821
    ("sizes = _check_sizes(sizes, w.shape[0] if w.ndim == 1 else -1)",
     "sizes = _check_sizes(sizes, w.shape[0] if w.ndim == 1 else - 2)",
     "-1 is only a size no group list can sum to; -2 is one too"),
    ("resid[np.repeat(totals <= 0, sizes)] = 1.0", "resid[np.repeat(totals <= 0, sizes)] = 2.0",
     "dummy mass of a group that receives no draw: any positive value"),
]
