"""Confidence intervals, the paired test and Holm's correction of the reports."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from sarcover.reports.stats import holm, t_halfwidth, wilcoxon_p


@pytest.mark.parametrize("n", [2, 5, 20, 200])
def test_t_halfwidth_is_scipys_t_interval(n):
    """The half-width equals that of scipy.stats.t.interval of the mean, wider than 1.96·s/√n."""
    x = np.random.default_rng(n).normal(0.8, 0.1, size=n)
    lo, hi = stats.t.interval(0.95, n - 1, loc=x.mean(), scale=stats.sem(x))
    assert t_halfwidth(x) == pytest.approx((hi - lo) / 2, rel=1e-12)
    assert t_halfwidth(x) > 1.96 * x.std(ddof=1) / np.sqrt(n)
    assert t_halfwidth(pd.Series([*x, np.nan])) == pytest.approx(t_halfwidth(x))


def test_t_halfwidth_needs_two_values():
    """One value (or none) has no interval."""
    assert np.isnan(t_halfwidth([0.5])) and np.isnan(t_halfwidth([]))


def test_holm_by_hand():
    """Holm's adjusted p-values of a four-test example worked by hand; at 5 % it keeps two, where BH keeps all."""
    # sorted: 0.005·4 = 0.02, 0.01·3 = 0.03, 0.03·2 = 0.06, max(0.06, 0.04·1) = 0.06
    p = [0.01, 0.04, 0.03, 0.005]
    np.testing.assert_allclose(holm(p), [0.03, 0.06, 0.06, 0.02])
    assert (holm(p) <= 0.05).sum() == 2
    assert (stats.false_discovery_control(p) <= 0.05).sum() == 4


def test_holm_leaves_nan_out_of_the_family_and_caps_at_one():
    """A NaN p-value stays NaN and does not count in m; no adjusted value exceeds 1."""
    np.testing.assert_allclose(holm([0.02, np.nan, 0.6, 0.7]), [0.06, np.nan, 1.0, 1.0])


def test_wilcoxon_p_on_ties_zeros_and_a_clear_shift():
    """All-zero differences give p = 1; tied ones mostly one way a small p, scipy's on the non-zero ones."""
    assert wilcoxon_p(np.zeros(20)) == 1.0 and np.isnan(wilcoxon_p([]))
    d = np.array([1 / 60] * 12 + [2 / 60] * 4 + [0.0] * 3 + [-1 / 60])
    assert wilcoxon_p(d) == pytest.approx(stats.wilcoxon(d[d != 0]).pvalue)
    assert wilcoxon_p(d) < 0.01
    assert wilcoxon_p(np.tile([1 / 60, -1 / 60], 10)) > 0.5
