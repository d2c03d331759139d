# The power analysis (orbed.study.power). Oracles: modes that give each user the same errors are never
# told apart; modes whose errors never overlap always are; a pool of one separating user (S) and one
# indifferent user (I) has the power the binomial count of S among N draws gives: the sum over k of
# C(N, k) / 2^N for the k whose test rejects (each test run here on the k-of-N study directly).
import math
import warnings

import numpy as np
import pytest
import scipy.stats

from helpers import joints_frame
from orbed.study import power


def user(name, error_a, error_b):
    return [(name, "ar_reflective", 1, [error_a] * 7), (name, "ar", 1, [error_b] * 7),
            (name, "ar_reflective", 2, [error_a + 0.5] * 7), (name, "ar", 2, [error_b + 0.5] * 7)]


def test_identical_and_separated_modes():
    same = power.power(joints_frame(user("a", 2, 2) + user("b", 7, 7)), users=(4, 8), resamples=50, seed=3)
    assert same["ar_reflective/ar"]["power"] == [0, 0] and same["ar_reflective/ar"]["power_paired"] == [0, 0]
    apart = power.power(joints_frame(user("a", 1, 20) + user("b", 2, 30)), users=(4, 8), resamples=50, seed=3)
    assert apart["ar_reflective/ar"]["power"] == [1, 1] and apart["ar_reflective/ar"]["users_for_80"] == 4
    # 4 users bring 8 pairs, all of one sign: normal approximation z = (0 - 18 + 0.5)/sqrt(51) = -2.45,
    # p = 0.014 < 0.05.
    assert apart["ar_reflective/ar"]["power_paired"] == [1, 1]
    assert power.power(joints_frame(user("a", 1, 2)), users=(4,), resamples=5).keys() == {"ar_reflective/ar"}


def test_mixed_pool_has_the_binomial_power():
    separating, indifferent = user("s", 1, 20), user("i", 5, 5)
    joints = joints_frame(separating + indifferent)
    samples = power.user_samples(joints, "ar_reflective", "ar")
    assert len(samples) == 2
    n = 4
    expected_pooled = expected_paired = 0.0
    for k in range(n + 1):
        drawn = [samples[1]] * k + [samples[0]] * (n - k)  # users sorted: "i" then "s"
        cat = [np.concatenate([s[i] for s in drawn]) for i in range(4)]
        binomial = math.comb(n, k) / 2 ** n
        if np.ptp(np.concatenate([cat[2], cat[3]])) > 0 and scipy.stats.mannwhitneyu(
                cat[2], cat[3], method="asymptotic").pvalue < 0.05:
            expected_pooled += binomial
        d = cat[0] - cat[1]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # scipy: "sample size too small for normal approximation"
            if np.any(d != 0) and scipy.stats.wilcoxon(d, correction=True, method="approx").pvalue < 0.05:
                expected_paired += binomial
    assert 0 < expected_pooled < 1 and 0 < expected_paired < 1
    curve = power.power_curve(samples, users=(n,), resamples=2000, seed=7)
    # 2000 resamples: each estimate's standard error is at most 0.012.
    assert curve["pooled_mwu"][0] == pytest.approx(expected_pooled, abs=0.04)
    assert curve["paired_setup"][0] == pytest.approx(expected_paired, abs=0.04)
    assert power.power_curve(samples, users=(n,), resamples=200, seed=7) == \
        power.power_curve(samples, users=(n,), resamples=200, seed=7)


def test_the_bootstraps_pooled_p_is_scipys():
    rng = np.random.default_rng(3)
    for _ in range(300):
        n1, n2 = rng.integers(2, 60, size=2)
        # Rounded values: many ties, as joint errors of a drawn user twice have.
        x, y = np.round(rng.gamma(1.0, 30.0, n1), int(rng.integers(0, 2))), np.round(rng.gamma(1.2, 30.0, n2), 0)
        if np.ptp(np.concatenate([x, y])) == 0:
            continue
        expected = scipy.stats.mannwhitneyu(x, y, alternative="two-sided", use_continuity=True,
                                            method="asymptotic").pvalue
        assert power.pooled_p(x, y) == pytest.approx(expected, rel=1e-9, abs=1e-15)
