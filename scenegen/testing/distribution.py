"""Regression expectations for stochastic outputs: a stored distribution over runs.

A tracker that is not reproducible run to run (OpenCV's MIL, or any tracker drawing from
global random state) cannot be pinned to exact boxes. Instead, run it R times, keep a
summary per run (say the mean IoU, shape (R,), or per-target values, (R, K)), and compare
the new runs with the stored ones: for every element, the means may differ by at most

    z * sqrt(s_stored**2 / R_stored + s_new**2 / R_new) + atol

(``s`` the standard deviations over runs, ddof=1): a two-sample z test at ``z`` standard
errors. With the default ``z = 4`` a tracker that has not changed fails with probability
about 6e-5 per element when the summaries are roughly normal (more with few runs, whose
standard deviations are themselves uncertain: keep R >= 5, summaries few). ``atol`` keeps
a band for outputs that barely vary, whose stored spread may be 0.

NaN counts as "not available": an element must be NaN in every run of both or in none.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["DEFAULT_Z", "assert_distribution_matches", "distribution_difference"]

DEFAULT_Z = 4.0


def _runs(samples: ArrayLike, what: str) -> np.ndarray:
    arr = np.asarray(samples, dtype=np.float64)
    if arr.ndim < 1 or arr.shape[0] < 2:
        raise ValueError(f"{what} must have shape (R, ...) with R >= 2 runs, got {arr.shape}")
    return arr


def distribution_difference(
    samples: ArrayLike, stored: ArrayLike, *, z: float = DEFAULT_Z, atol: float = 0.0
) -> str | None:
    """What is out of band between new ``samples`` (R, ...) and ``stored`` (R0, ...), or
    None if every element's mean is within the band (see the module docstring).

    Parameters
    ----------
    samples : array_like of float, shape (R, ...)
        The new runs' summaries, R >= 2; NaN: not available.
    stored : array_like of float, shape (R0, ...)
        The stored runs' summaries, R0 >= 2, of the same per-run shape.
    z : float, default :data:`DEFAULT_Z`
        Width of the band in standard errors, > 0.
    atol : float, default 0.0
        Added to the band, >= 0.

    Returns
    -------
    str or None
        One line: the number of elements out of band and the first one (means, spread,
        allowed difference), or an element that is NaN in some runs only or on one side
        only; None if they agree.

    Raises
    ------
    ValueError
        Fewer than 2 runs on either side, ``z <= 0`` or ``atol < 0``.
    AssertionError
        The per-run shapes differ.
    """
    if z <= 0 or atol < 0:
        raise ValueError(f"need z > 0 and atol >= 0, got z={z}, atol={atol}")
    new, old = _runs(samples, "samples"), _runs(stored, "the stored samples")
    if new.shape[1:] != old.shape[1:]:
        raise AssertionError(
            f"per-run shape {new.shape[1:]}, stored {old.shape[1:]} (runs: {len(new)}, "
            f"stored {len(old)})"
        )
    nan_new, nan_old = np.isnan(new), np.isnan(old)
    partial = (nan_new.any(0) & ~nan_new.all(0)) | (nan_old.any(0) & ~nan_old.all(0))
    if partial.any():
        idx = tuple(int(i) for i in np.argwhere(partial)[0])
        return f"element {idx} is NaN in some runs only (NaN must be in every run or none)"
    gone = nan_new.all(0) != nan_old.all(0)
    if gone.any():
        idx = tuple(int(i) for i in np.argwhere(gone)[0])
        which = "new" if nan_new.all(0)[idx] else "stored"
        return f"element {idx} is NaN in the {which} runs only"
    valid = ~nan_new.all(0)  # elements NaN in every run of both are not compared
    new0, old0 = np.nan_to_num(new), np.nan_to_num(old)
    mean_new, mean_old = new0.mean(axis=0), old0.mean(axis=0)
    sd_new, sd_old = new0.std(axis=0, ddof=1), old0.std(axis=0, ddof=1)
    allowed = z * np.sqrt(sd_new**2 / len(new) + sd_old**2 / len(old)) + atol
    out = valid & (np.abs(mean_new - mean_old) > allowed)
    if not out.any():
        return None
    idx = tuple(int(i) for i in np.argwhere(out)[0])
    return (
        f"{int(out.sum())} of {out.size} elements out of band; first {idx}: mean "
        f"{mean_new[idx]:.6g} over {len(new)} runs, stored {mean_old[idx]:.6g} ± {sd_old[idx]:.3g} "
        f"(sd over {len(old)} runs); allowed |difference| <= {allowed[idx]:.3g} "
        f"(z={z:g}, atol={atol:g})"
    )


def assert_distribution_matches(
    path: Path,
    samples: Any,
    *,
    z: float = DEFAULT_Z,
    atol: float = 0.0,
    regen: bool = False,
) -> bool:
    """Compare ``samples`` (R, ...) with the runs stored at ``path`` (``.npy``), or store
    them (``regen``; always rewritten, since new runs differ). Returns True if written.

    Parameters
    ----------
    path : Path
        The ``.npy`` file of the stored runs.
    samples : array_like of float, shape (R, ...)
        The new runs' summaries, R >= 2.
    z : float, default :data:`DEFAULT_Z`
        Width of the band in standard errors (:func:`distribution_difference`).
    atol : float, default 0.0
        Added to the band.
    regen : bool, default False
        Store ``samples`` (as float64, creating the folders) instead of comparing.

    Returns
    -------
    bool
        True if the file was written (``regen``), False after a successful comparison.

    Raises
    ------
    AssertionError
        Naming the file and the first element out of band; or a missing or unreadable
        file (run pytest with ``--scenegen-regen``).
    ValueError
        Fewer than 2 runs, or bad ``z``/``atol`` (checked when comparing).
    """
    from scenegen.io.atomic import write_npy
    from scenegen.testing.compare import load_expected

    arr = _runs(samples, "samples")
    if regen:
        write_npy(path, arr, parents=True)
        return True
    if not path.exists():
        raise AssertionError(f"no stored distribution {path}; run pytest with --scenegen-regen")
    stored = load_expected(path)
    if stored is None:
        raise AssertionError(
            f"{path}: not a readable .npy file; run pytest with --scenegen-regen to rewrite it"
        )
    what = distribution_difference(arr, stored, z=z, atol=atol)
    if what is not None:
        raise AssertionError(f"{path}: {what}")
    return False
