"""The set-up half's analysis as a reviewer asks for it, beside the paper's reading (tables.py).

The paper's Table 3 pools every joint of every set-up per mode and compares two modes unpaired
(168 values per mode from 24 set-ups of 8 people): the values are neither independent (7 joints of
one set-up, 3 set-ups of one person) nor unpaired (every user did every mode on the same targets).
Here the unit of analysis is named in every result:

  set-up      per set-up mean joint error; two modes paired by (user, target index)
  user        per user mean over all that user's joint errors in a mode; paired by user
  joint       one joint's error per set-up, paired by (user, target index); Holm over the joints
  joint error every joint of every set-up, in a mixed-effects model that carries the dependence
              (random intercepts for user and for target, crossed)

Tests (all two-sided):
  Wilcoxon signed-rank (scipy.stats.wilcoxon): zero differences dropped (Wilcoxon's convention);
  the exact null distribution when n <= 50 and neither zeros nor ties, else the normal
  approximation with the tie and continuity corrections ("method" says which).
  Effect sizes: the matched-pairs rank-biserial correlation r = (W+ - W-) / (W+ + W-) (Kerby,
  Comprehensive Psychology 3, 2014, "the simple difference formula"); positive when the first mode's
  errors are larger. The median paired difference (first - second) with a 95 % percentile bootstrap
  CI over pairs (BOOTSTRAP resamples, seeded: the same files give the same CI).
  Holm's step-down correction over the joints' p-values (statsmodels multipletests, "holm").
  Mixed model (statsmodels MixedLM, REML, fitted by L-BFGS, then Powell if that fails): y ~ mode *
  kind, kind twisting/revolving, with crossed random intercepts for user and target (one group
  holding every row, vc_formula). y is the joint error [deg] or ln(error + LOG_OFFSET_DEG): both are
  fitted and the one whose residuals are less skewed is reported (errors are bounded below by 0 and
  have a half-turn tail near 180 deg, so the raw scale's residuals are expected to be far from
  normal); "scale" and "why" say which.

Half-turns: a set-up joint with an error above HALF_TURN_DEG (the arm left in the other
kinematic branch). With setup_joints.csv's start_deg (the set-up's start), each set-up's start-target
relation over the bending joints 2, 4, 6: "same" (every sign equal), "mirror" (every sign opposite),
"mixed".
"""
import warnings

import numpy as np
import pandas as pd
import scipy.stats
from statsmodels.stats.multitest import multipletests

from .describe import number, summarize
from .files import MODES, PAIRS, pair_modes
from .tables import mann_whitney, pooled_errors

HALF_TURN_DEG = 90.0
BENDING_JOINTS = (2, 4, 6)
BOOTSTRAP = 2000
ALPHA = 0.05
# ln(error + c) needs c > 0 (errors can be 0.00 deg, Table 2's minimum); 0.1 deg is below any error
# that matters for a set-up and has no source: a floor, not a fitted value.
LOG_OFFSET_DEG = 0.1


def median_difference_ci(d, seed=1, resamples=BOOTSTRAP, level=0.95):
    """The median of d and its percentile bootstrap CI (pairs resampled with replacement)."""
    d = np.asarray(d, float)
    if d.size == 0:
        return None, [None, None]
    rng = np.random.default_rng(seed)
    medians = np.median(d[rng.integers(0, d.size, size=(resamples, d.size))], axis=1)
    lo, hi = np.quantile(medians, [(1 - level) / 2, (1 + level) / 2])
    return float(np.median(d)), [float(lo), float(hi)]


def signed_rank(a, b, seed=1):
    """Two-sided Wilcoxon signed-rank test of the pairs (a[i], b[i]), with its effect sizes."""
    d = np.asarray(a, float) - np.asarray(b, float)
    nonzero = d[d != 0]
    n = int(nonzero.size)
    out = {"test": "wilcoxon_signed_rank", "pairs": int(d.size), "n": n, "n_zero": int(d.size - n),
           "w_plus": None, "w_minus": None, "p": None, "method": None, "rank_biserial": None}
    out["median_difference"], out["median_difference_ci95"] = median_difference_ci(d, seed)
    if n == 0:
        return out
    ranks = scipy.stats.rankdata(np.abs(nonzero))
    w_plus, w_minus = float(ranks[nonzero > 0].sum()), float(ranks[nonzero < 0].sum())
    ties = np.unique(np.abs(nonzero)).size < n
    exact = n <= 50 and not ties and out["n_zero"] == 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # scipy warns of the normal approximation for small n
        if exact:
            r = scipy.stats.wilcoxon(nonzero, method="exact")
        else:
            r = scipy.stats.wilcoxon(nonzero, zero_method="wilcox", correction=True, method="approx")
    out.update(w_plus=w_plus, w_minus=w_minus, p=number(r.pvalue), method="exact" if exact else "normal",
               rank_biserial=(w_plus - w_minus) / (w_plus + w_minus))
    return out


def setup_means(joints):
    """One row per set-up: user, mode, target, target_key, mean_error_deg."""
    return (joints.groupby(["user", "mode", "target", "target_key"], as_index=False)["error_deg"].mean()
            .rename(columns={"error_deg": "mean_error_deg"}))


def paired(frame, a, b, keys, value):
    """Rows of mode a and b matched on `keys`: (values of a, values of b)."""
    x = frame[frame["mode"] == a][keys + [value]]
    y = frame[frame["mode"] == b][keys + [value]]
    m = x.merge(y, on=keys, suffixes=("_a", "_b"))
    return m[value + "_a"].to_numpy(), m[value + "_b"].to_numpy()


def by_setup(joints, a, b, seed=1):
    x, y = paired(setup_means(joints), a, b, ["user", "target"], "mean_error_deg")
    return dict(signed_rank(x, y, seed), unit="set-up (mean joint error), paired by user and target")


def by_user(joints, a, b, seed=1):
    per_user = joints.groupby(["user", "mode"], as_index=False)["error_deg"].mean()
    x, y = paired(per_user, a, b, ["user"], "error_deg")
    return dict(signed_rank(x, y, seed), unit="user (mean of all joint errors), paired by user")


def per_joint(joints, a, b, seed=1):
    """{"joint1": signed_rank + "p_holm", ...}: Holm over the joints that have a test."""
    out = {}
    for j in sorted(joints["joint"].astype(int).unique()):
        rows = joints[joints["joint"].astype(int) == j]
        x, y = paired(rows, a, b, ["user", "target"], "error_deg")
        out["joint%d" % j] = dict(signed_rank(x, y, seed), unit="joint %d of a set-up, paired by user and target" % j)
    keys = [k for k, r in out.items() if r["p"] is not None]
    if keys:
        _, holm, _, _ = multipletests([out[k]["p"] for k in keys], alpha=ALPHA, method="holm")
        for k, p in zip(keys, holm):
            out[k]["p_holm"] = float(p)
    for r in out.values():
        r.setdefault("p_holm", None)
    return out


def pooled(joints, a, b):
    """The paper's reading, with its effect size, for the table beside the paired ones."""
    r = mann_whitney(pooled_errors(joints, a), pooled_errors(joints, b))
    return dict(r, test="mann_whitney_u", unit="joint error, every joint of every set-up pooled, unpaired",
                label="the paper's reading: unpaired, every joint of every set-up pooled")


def reference_mode(modes):
    return "ar" if "ar" in modes else modes[0]


def mixed_model(joints):
    """The mixed-effects model (see the file comment): coefficients with 95 % CIs."""
    import statsmodels.formula.api as smf  # statsmodels' formula layer is slow to import

    modes = [m for m in MODES if (joints["mode"] == m).any()]
    df = pd.DataFrame({
        "error": joints["error_deg"].astype(float).to_numpy(),
        "mode": pd.Categorical(joints["mode"], categories=[reference_mode(modes)] +
                               [m for m in modes if m != reference_mode(modes)]),
        "kind": pd.Categorical(np.where(joints["twisting"].astype(int) == 1, "twisting", "revolving"),
                               categories=["revolving", "twisting"]),
        "user": joints["user"].astype(str).to_numpy(),
        "target": joints["target_key"].astype(str).to_numpy(),
        "all": 1})
    df["log_error"] = np.log(df["error"] + LOG_OFFSET_DEG)
    fits, skew = {}, {}
    for y in ("error", "log_error"):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            model = smf.mixedlm(y + " ~ mode * kind", df, groups="all", re_formula="0",
                                vc_formula={"user": "0 + C(user)", "target": "0 + C(target)"})
            # L-BFGS first, then Powell: statsmodels' default (BFGS) stops short on these crossed
            # effects (a study's fit: not converged, log-likelihood 16 lower than L-BFGS's).
            result = model.fit(reml=True, method=["lbfgs", "powell"], maxiter=2000)
        fits[y] = (model, result, [str(w.message) for w in caught])
        skew[y] = float(scipy.stats.skew(result.resid))
    chosen = "log_error" if abs(skew["log_error"]) < abs(skew["error"]) else "error"
    model, result, messages = fits[chosen]
    ci = result.conf_int(alpha=0.05)
    coefficients = []
    for term in model.exog_names:
        c = {"term": term, "estimate": float(result.fe_params[term]), "se": float(result.bse_fe[term]),
             "ci95": [float(ci.loc[term, 0]), float(ci.loc[term, 1])], "p": number(result.pvalues[term])}
        if chosen == "log_error":
            c["ratio"] = float(np.exp(c["estimate"]))
            c["ratio_ci95"] = [float(np.exp(v)) for v in c["ci95"]]
        coefficients.append(c)
    scale = "ln(error_deg + %g)" % LOG_OFFSET_DEG if chosen == "log_error" else "error_deg"
    return {
        "test": "mixed_effects_model",
        "unit": "joint error of a set-up; random intercepts for user and for target (crossed)",
        "formula": "%s ~ mode * kind + (1 | user) + (1 | target)" % scale,
        "scale": scale,
        "why": "residual skewness %.2f on the degree scale, %.2f on the log scale: the less skewed is "
               "reported" % (skew["error"], skew["log_error"]),
        "residual_skewness": {"error_deg": skew["error"], "log": skew["log_error"]},
        "reference": {"mode": str(df["mode"].cat.categories[0]), "kind": "revolving"},
        "n": int(len(df)), "users": int(df["user"].nunique()), "targets": int(df["target"].nunique()),
        "coefficients": coefficients,
        "variance_components": {name: float(v) for name, v in zip(model.exog_vc.names, result.vcomp)},
        "residual_variance": float(result.scale),
        "converged": bool(result.converged), "warnings": sorted(set(messages)),
    }


def relations(joints):
    """Each set-up's start-target relation over the bending joints, or None without start_deg."""
    if "start_deg" not in joints.columns or joints["start_deg"].isna().any():
        return None
    bending = joints[joints["joint"].astype(int).isin(BENDING_JOINTS)]
    out = {}
    for key, rows in bending.groupby(["user", "mode", "target"]):
        start, target = np.sign(rows["start_deg"].astype(float)), np.sign(rows["target_deg"].astype(float))
        if (start == target).all():
            out[key] = "same"
        elif (start == -target).all() and (target != 0).all():
            out[key] = "mirror"
        else:
            out[key] = "mixed"
    return pd.Series(out, name="relation").rename_axis(["user", "mode", "target"]).reset_index()


def half_turn_counts(rows):
    half = rows["error_deg"].astype(float) > HALF_TURN_DEG
    per_setup = half.groupby([rows["user"], rows["target"]]).any()
    return {"joints": int(len(rows)), "half_turns": int(half.sum()),
            "rate": float(half.mean()) if len(rows) else None,
            "setups": int(per_setup.size), "setups_with_half_turn": int(per_setup.sum())}


def half_turns(joints):
    """{"threshold_deg", "by_mode": {mode: counts}, "by_relation": {relation: {mode: counts}} | None}."""
    out = {"threshold_deg": HALF_TURN_DEG,
           "by_mode": {m: half_turn_counts(joints[joints["mode"] == m]) for m in MODES if (joints["mode"] == m).any()},
           "by_relation": None}
    rel = relations(joints)
    if rel is not None:
        tagged = joints.merge(rel, on=["user", "mode", "target"])
        out["by_relation"] = {
            r: {m: half_turn_counts(tagged[(tagged["relation"] == r) & (tagged["mode"] == m)])
                for m in MODES if ((tagged["relation"] == r) & (tagged["mode"] == m)).any()}
            for r in ("same", "mirror", "mixed") if (tagged["relation"] == r).any()}
    return out


def per_target(joints, seed=1):
    """{target_key: {"modes": {mode: summary + half-turn rate}, "paired": {pair: signed_rank over
    users' set-ups on this target}}}."""
    out = {}
    means = setup_means(joints)
    keys = sorted(joints["target_key"].unique(), key=lambda k: (len(k), k))
    for key in keys:
        rows = joints[joints["target_key"] == key]
        entry = {"modes": {}, "paired": {}}
        for m in MODES:
            r = rows[rows["mode"] == m]
            if r.empty:
                continue
            entry["modes"][m] = dict(summarize(r["error_deg"]), setups=int(r.groupby(["user", "target"]).ngroups),
                                     half_turn_rate=float((r["error_deg"].astype(float) > HALF_TURN_DEG).mean()))
        present = set(rows["mode"])
        target_means = means[means["target_key"] == key]
        for pair in PAIRS:
            a, b = pair_modes(pair)
            if a in present and b in present:
                x, y = paired(target_means, a, b, ["user", "target"], "mean_error_deg")
                entry["paired"][pair] = dict(signed_rank(x, y, seed),
                                             unit="set-up on this target (mean joint error), paired by user")
        out[key] = entry
    return out


def setup_analysis(joints, seed=1):
    """Everything above for every pair of modes present: tables.json "setup_analysis"."""
    present = set(joints["mode"])
    pairs = {}
    for pair in PAIRS:
        a, b = pair_modes(pair)
        if a not in present or b not in present:
            continue
        pairs[pair] = {"pooled_mwu": pooled(joints, a, b), "by_setup": by_setup(joints, a, b, seed),
                       "by_user": by_user(joints, a, b, seed), "per_joint": per_joint(joints, a, b, seed)}
    out = {"pairs": pairs, "half_turns": half_turns(joints), "per_target": per_target(joints, seed),
           "target_grouping": "target_id" if "target_id" in joints.columns and joints["target_id"].notna().all()
           else "target index"}
    if len(present) >= 2 and joints["user"].nunique() >= 2:
        out["mixed_model"] = mixed_model(joints)
    return out
