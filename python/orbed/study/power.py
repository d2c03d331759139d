"""The power analysis: how many users a study would need for a test between two modes to reject at
alpha = 0.05 with probability 0.8, if people were like the emulated ones.

A bootstrap over users: for each study size N, `resamples` studies of N users drawn with replacement
from the users who did both modes (each drawn user brings all their set-ups of the two modes); on
each study two tests, the power of each being the fraction of studies with p < alpha:
  paired_setup  the reviewer's: two-sided Wilcoxon signed-rank on per-set-up mean joint errors
                paired by (user, target), normal approximation (a user drawn twice brings tied pairs,
                so the exact distribution does not apply);
  pooled_mwu    the paper's reading: two-sided Mann-Whitney U on every joint of every set-up, pooled.
Deterministic for a seed (numpy's default_rng).
"""
import warnings

import numpy as np
import scipy.stats

from .files import PAIRS, pair_modes
from .setup_stats import setup_means

USERS = (4, 8, 12, 16, 24, 32, 48, 64)
RESAMPLES = 500
ALPHA = 0.05

METHOD = ("bootstrap over users: %d studies of N users drawn with replacement per N; power = fraction "
          "with p < %g of the paired test (two-sided Wilcoxon signed-rank on per-set-up mean errors, paired "
          "by user and target) and of the paper's reading (two-sided Mann-Whitney U, every joint of every "
          "set-up pooled, unpaired)")


def user_samples(joints, a, b):
    """Per user who did both modes: (paired set-up means of a, of b, pooled errors of a, of b)."""
    means = setup_means(joints)
    out = []
    for user in sorted(set(joints["user"])):
        ma = means[(means["user"] == user) & (means["mode"] == a)][["target", "mean_error_deg"]]
        mb = means[(means["user"] == user) & (means["mode"] == b)][["target", "mean_error_deg"]]
        if ma.empty or mb.empty:
            continue
        m = ma.merge(mb, on="target", suffixes=("_a", "_b"))
        ea = joints[(joints["user"] == user) & (joints["mode"] == a)]["error_deg"].to_numpy(float)
        eb = joints[(joints["user"] == user) & (joints["mode"] == b)]["error_deg"].to_numpy(float)
        out.append((m["mean_error_deg_a"].to_numpy(), m["mean_error_deg_b"].to_numpy(), ea, eb))
    return out


def rejects_paired(x, y, alpha):
    d = x - y
    if not np.any(d != 0):
        return False
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        p = scipy.stats.wilcoxon(d, zero_method="wilcox", correction=True, method="approx").pvalue
    return bool(p < alpha)


def pooled_p(x, y):
    """The two-sided Mann-Whitney U p-value of scipy.stats.mannwhitneyu(x, y, alternative="two-sided",
    use_continuity=True, method="asymptotic"), from scipy's ranks and normal distribution without its
    per-call checks (the bootstrap calls it 12 000 times a study; pytest holds it to scipy's):
    U = max(U_x, U_y), z = (U - n_x n_y / 2 - 1/2) / s with the tie-corrected
    s^2 = n_x n_y / 12 ((n + 1) - sum(t^3 - t) / (n (n - 1))), p = min(1, 2 sf(z))."""
    both = np.concatenate([x, y])
    n1, n2, n = x.size, y.size, both.size
    u1 = scipy.stats.rankdata(both)[:n1].sum() - n1 * (n1 + 1) / 2
    u = max(u1, n1 * n2 - u1)
    _, ties = np.unique(both, return_counts=True)
    s = np.sqrt(n1 * n2 / 12 * ((n + 1) - (ties ** 3 - ties).sum() / (n * (n - 1))))
    return float(min(1.0, 2 * scipy.stats.norm.sf((u - n1 * n2 / 2 - 0.5) / s)))


def rejects_pooled(x, y, alpha):
    if np.ptp(np.concatenate([x, y])) == 0:
        return False
    return pooled_p(x, y) < alpha


def power_curve(samples, users=USERS, resamples=RESAMPLES, alpha=ALPHA, seed=1):
    """{"users", "paired_setup", "pooled_mwu"}: the two tests' power at each study size."""
    rng = np.random.default_rng(seed)
    out = {"users": list(users), "paired_setup": [], "pooled_mwu": []}
    for n in users:
        paired = pooled = 0
        for _ in range(resamples):
            drawn = [samples[i] for i in rng.integers(0, len(samples), size=n)]
            cat = [np.concatenate([s[k] for s in drawn]) for k in range(4)]
            paired += rejects_paired(cat[0], cat[1], alpha)
            pooled += rejects_pooled(cat[2], cat[3], alpha)
        out["paired_setup"].append(paired / resamples)
        out["pooled_mwu"].append(pooled / resamples)
    return out


def first_at(users, power, level=0.8):
    return next((n for n, p in zip(users, power) if p >= level), None)


def power(joints, users=USERS, resamples=RESAMPLES, alpha=ALPHA, seed=1):
    """tables.json beyond.power: {pair: {"users", "power" (the pooled test, as before), "users_for_80",
    "power_paired", "users_for_80_paired"}}."""
    out = {}
    present = set(joints["mode"])
    for pair in PAIRS:
        a, b = pair_modes(pair)
        if a not in present or b not in present:
            continue
        samples = user_samples(joints, a, b)
        if not samples:
            continue
        c = power_curve(samples, users, resamples, alpha, seed)
        out[pair] = {"users": c["users"], "power": c["pooled_mwu"], "users_for_80": first_at(c["users"], c["pooled_mwu"]),
                     "power_paired": c["paired_setup"],
                     "users_for_80_paired": first_at(c["users"], c["paired_setup"])}
    return out
