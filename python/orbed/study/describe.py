"""The summary every table uses: {mean, median, min, max, std, n} of a sample.

std is the sample standard deviation (n - 1), 0 for one value; the median of an even count is the
mean of the middle two (numpy's). An empty sample gives None (no row).
"""
import numpy as np


def summarize(values, with_n=True):
    x = np.asarray(list(values), dtype=float)
    if x.size == 0:
        return None
    out = {"mean": float(x.mean()), "median": float(np.median(x)), "min": float(x.min()),
           "max": float(x.max()), "std": float(x.std(ddof=1)) if x.size > 1 else 0.0}
    if with_n:
        out["n"] = int(x.size)
    return out


def number(value):
    """A float for JSON, or None for NaN/None (no test, no value)."""
    if value is None:
        return None
    value = float(value)
    return None if np.isnan(value) else value
