"""The statistics of the reports: confidence intervals of means, paired tests, and Holm's correction.

A mean over n instances gets the Student t interval, ``t(1 − α/2, n − 1)·s/√n``: with 20
instances per setting the normal 1.96 would be too narrow by about 7 %. Two methods run on the
same instances are compared by the Wilcoxon signed-rank test of their paired differences, which
assumes no normal distribution (coverage differences are discrete and often tied or zero; zero
differences are dropped, ties get the normal approximation with its tie correction). Where a
report counts how many of a family of comparisons are significant, the p-values are first
corrected by Holm's step-down method, which keeps the chance of any false claim in the family at
most α.
"""

from __future__ import annotations

import numpy as np
import pandas as pd


def t_halfwidth(x, level: float = 0.95) -> float:
    """Half-width of the two-sided ``level`` t interval of the mean of ``x`` (NaN left out); NaN
    below two values."""
    from scipy.stats import t

    v = pd.Series(x, dtype=float).dropna().to_numpy()
    if v.size < 2:
        return np.nan
    return float(t.ppf(0.5 + level / 2, v.size - 1) * v.std(ddof=1) / np.sqrt(v.size))


def wilcoxon_p(d) -> float:
    """Two-sided p-value of the Wilcoxon signed-rank test that the paired differences ``d`` are
    centred on 0 (NaN and zero differences left out); 1 where no difference is left, NaN for none."""
    from scipy.stats import wilcoxon

    v = pd.Series(d, dtype=float).dropna().to_numpy()
    if v.size == 0:
        return np.nan
    if not np.any(v != 0):
        return 1.0
    return float(wilcoxon(v, zero_method="wilcox", alternative="two-sided").pvalue)


def holm(pvalues) -> np.ndarray:
    """Holm's step-down adjusted p-values, in the input's order: the i-th smallest of m becomes
    max over j ≤ i of min(1, (m − j + 1)·p_(j)); a comparison is significant at α when its adjusted
    p-value is at most α. NaN stays NaN and does not count in m."""
    p = np.asarray(pvalues, dtype=float)
    out = np.full(p.shape, np.nan)
    idx = np.flatnonzero(~np.isnan(p))
    order = idx[np.argsort(p[idx], kind="stable")]
    m = order.size
    running = 0.0
    for rank, i in enumerate(order):
        running = max(running, min(1.0, (m - rank) * p[i]))
        out[i] = running
    return out
