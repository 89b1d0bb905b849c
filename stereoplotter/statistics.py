"""Monte Carlo summaries of per-trial values, each figure with its Monte Carlo standard error.

Pure numpy. A column is the values of one measure over T independent trials (a check's residual,
its pass flag, an RMS height error, …). :func:`summarise_values` gives the mean, the RMS, the
standard deviation, extremes and quantiles; :func:`summarise_flags` gives a pass rate. The
uncertainty of each Monte Carlo estimate:

- mean: standard error s/√T;
- RMS = √(mean x²): the delta method, SE(mean x²)/(2·RMS);
- pass rate p: √(p(1−p)/T);
- quantile q_p: a distribution-free 95 % confidence interval between the order statistics
  k = T·p ± 1.96·√(T·p(1−p)) (normal approximation to the binomial count below q_p).

Non-finite values (a check that could not be evaluated in a trial) are counted and left out; a
measure with the same value in every trial is reported as that constant.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["QUANTILES", "Z95", "scale_summary", "summarise_flags", "summarise_values"]

#: Quantile levels reported for every measure.
QUANTILES = (0.05, 0.5, 0.95)
#: Two-sided 95 % normal quantile.
Z95 = 1.959963984540054


def _ci_ranks(n: int, p: float) -> tuple[int, int]:
    """The order statistics (0-based ranks) that bound the 95 % confidence interval of q_p."""
    half = Z95 * math.sqrt(n * p * (1.0 - p))
    return math.floor(n * p - half), math.ceil(n * p + half)


def _ranks_read(n: int) -> list[int]:
    """Every rank :func:`_quantile_ci` reads of ``n`` values: the two neighbours of each
    quantile's position (n − 1)·p that ``np.quantile``'s linear method interpolates between,
    and the ranks of its confidence interval."""
    ranks: set[int] = set()
    for p in QUANTILES:
        below = math.floor((n - 1) * p)
        ranks.update((below, min(below + 1, n - 1)))
        ranks.update(r for r in _ci_ranks(n, p) if 0 <= r <= n - 1)
    return sorted(ranks)


def _quantile_ci(ranked: np.ndarray, p: float) -> dict[str, Any]:
    """q_p and its confidence interval from ``ranked``: the values with every rank of
    :func:`_ranks_read` in its sorted place (``np.partition``; a sorted array also serves)."""
    n = len(ranked)
    value = float(np.quantile(ranked, p, method="linear"))
    lo, hi = _ci_ranks(n, p)
    ci = None
    if n >= 2 and lo >= 0 and hi <= n - 1:
        ci = [float(ranked[lo]), float(ranked[hi])]
    return {"value": value, "ci95": ci}


def summarise_values(values: ArrayLike) -> dict[str, Any]:
    """Mean, RMS, SD, min, max and quantiles of one measure over the trials, with MC errors.

    Examples
    --------
    >>> s = summarise_values([1.0, 2.0, 3.0, 4.0])
    >>> s["mean"], round(s["mean_se"], 4), round(s["rms"], 4)
    (2.5, 0.6455, 2.7386)
    """
    a = np.asarray(values, float).reshape(-1)
    finite = np.isfinite(a)
    x = a[finite] if not finite.all() else a
    n = int(x.size)
    out: dict[str, Any] = {"n": n}
    if a.size > n:
        out["not_finite"] = int(a.size - n)
    if n == 0:
        return out
    if x[0] == x[-1] and np.all(x == x[0]):  # the same in every trial: one value says it all
        out["constant"] = float(x[0])
        return out
    mean = float(np.mean(x))
    sq = np.square(x)
    ms = float(np.mean(sq))
    rms = math.sqrt(ms)
    sd = float(np.std(x, ddof=1)) if n > 1 else None
    sd_sq = float(np.std(sq, ddof=1)) if n > 1 else None
    out.update(
        mean=mean,
        mean_se=None if sd is None else sd / math.sqrt(n),
        rms=rms,
        rms_se=None if sd_sq is None or rms == 0.0 else sd_sq / math.sqrt(n) / (2.0 * rms),
        std=sd,
        min=float(np.min(x)),
        max=float(np.max(x)),
    )
    # the few order statistics the quantiles read put in their places (O(n)), not a full sort
    ranked = np.partition(x, _ranks_read(n))
    out["quantiles"] = {f"p{round(100 * p):02d}": _quantile_ci(ranked, p) for p in QUANTILES}
    return out


def summarise_flags(flags: ArrayLike) -> dict[str, Any]:
    """Pass rate of a yes/no outcome over the trials with its standard error.

    Examples
    --------
    >>> summarise_flags([True, True, False, True])
    {'n': 4, 'rate': 0.75, 'rate_se': 0.21650635094610965}
    """
    a = np.asarray(flags, bool).reshape(-1)
    n = int(a.size)
    if n == 0:
        return {"n": 0}
    p = float(np.mean(a))
    return {"n": n, "rate": p, "rate_se": math.sqrt(p * (1.0 - p) / n)}


def scale_summary(summary: dict[str, Any], factor: float) -> dict[str, Any]:
    """The summary of ``factor · x`` (factor > 0) from the summary of x (a change of unit)."""
    if factor <= 0:
        raise ValueError(f"factor: expected > 0, found {factor}")
    out: dict[str, Any] = {}
    for key, v in summary.items():
        if key in ("n", "not_finite"):
            out[key] = v
        elif key == "quantiles":
            out[key] = {
                q: {
                    "value": e["value"] * factor,
                    "ci95": None if e["ci95"] is None else [c * factor for c in e["ci95"]],
                }
                for q, e in v.items()
            }
        else:  # mean, rms, their SE, std, min, max, constant
            out[key] = None if v is None else v * factor
    return out
