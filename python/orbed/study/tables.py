"""Tables 1-4 as the paper computes them (../docs/studies.md says which reading each one is).

Table 1 (ViRAAl, alignment_trials.csv): per axis, the mean and sample std of the trials' per-axis
  error over every trial of a mode; then the norm of the three means and the norm of the three stds
  (the paper's own rows check: (17.4, 11.9, 21.6) -> 30.2). {mode: {"t_x": [mean, std], "t_y",
  "t_z", "norm": [norm of means, norm of stds], "num_trials"}}. The same from the v_* columns (a
  viewer frame, z the line of sight) when the CSV has them.
Table 1's SE(3) row: the paper's "means of N = 3 trials": alignment_groups.csv has one row per group
  of 3 consecutive trials of a user's session, its SE(3) mean scored by orbed-study-tables;
  mean +/- sample std of misalignment_mm over every group of a mode. The per-user mean of all of
  a user's trials (alignment_means.csv) is kept as "se3_mean", labelled as what it is.
Table 2: {mode: summarize(every joint's error of every set-up)}.
Table 3, the paper's reading: two-sided Mann-Whitney U between two modes' errors, unpaired, every
  joint of every set-up pooled (or one joint's over every set-up); normal approximation with the
  tie correction and the continuity correction (scipy.stats.mannwhitneyu, method="asymptotic").
  None when every value is tied (no test).
Table 4: {mode: {"execution_s": summarize, "alignment_s": summarize (headset modes)}}.
Units: mm, deg, s as the column names say.
"""
import numpy as np
import scipy.stats

from .describe import number, summarize
from .files import MODES, PAIRS, pair_modes

AXES = (("t_x", "t_x_mm"), ("t_y", "t_y_mm"), ("t_z", "t_z_mm"))
VIEWER_AXES = (("t_x", "v_x_mm"), ("t_y", "v_y_mm"), ("t_z", "v_z_mm"))


def table1_row(rows, axes=AXES):
    """The Table 1 row of a frame of trials (or of means)."""
    means, stds = [], []
    for _, column in axes:
        x = rows[column].astype(float).to_numpy()
        means.append(float(x.mean()))
        stds.append(float(x.std(ddof=1)) if x.size > 1 else 0.0)
    row = {key: [m, s] for (key, _), m, s in zip(axes, means, stds)}
    row["norm"] = [float(np.linalg.norm(means)), float(np.linalg.norm(stds))]
    row["num_trials"] = int(len(rows))
    return row


def modes_in(df):
    """The modes of a frame in order of first appearance (as the C++ tables listed them)."""
    return list(dict.fromkeys(df["mode"]))


def table1(trials, means=None, groups=None):
    out = {mode: table1_row(trials[trials["mode"] == mode]) for mode in modes_in(trials)}
    if means is not None and len(means):
        out["se3_mean"] = {mode: table1_row(means[means["mode"] == mode]) for mode in modes_in(means)}
        out["se3_mean_label"] = ("the SE(3) mean of all of each user's trials of a mode (one per user), "
                                 "scored with the user's annotated landmarks; not the paper's N = 3")
    if groups is not None and len(groups):
        out["se3_n3"] = table1_groups(groups)
        out["se3_n3_label"] = ("the paper's statistic: the SE(3) means of N = 3 consecutive trials of a user's "
                               "session, mean +/- sample std over every group of the mode's users, measured as a "
                               "session mean is (against the real landmarks annotated in the group's trials); "
                               "true_norm: the same from the truth's landmarks")
    return out


def group_size(trials):
    """Trials in a group from alignment_groups.csv's `trials` cell: a range "1-3" or a count "3"."""
    first, _, last = str(trials).partition("-")
    return int(last) - int(first) + 1 if last else int(first)


def table1_groups(groups):
    """The SE(3) row, means of N = 3 trials: mean +/- std of the groups' misalignment (measured as the
    paper measured a mean) and, when the file has it, of true_misalignment_mm (the truth's landmarks)."""
    out = {}
    for mode in modes_in(groups):
        rows = groups[groups["mode"] == mode]
        x = rows["misalignment_mm"].astype(float).to_numpy()
        out[mode] = {"norm": [float(x.mean()), float(x.std(ddof=1)) if x.size > 1 else 0.0],
                     "groups": int(x.size), "trials_per_group": group_size(rows["trials"].iloc[0]),
                     "users": int(rows["user"].nunique())}
        if "true_misalignment_mm" in rows.columns:
            t = rows["true_misalignment_mm"].astype(float).to_numpy()
            out[mode]["true_norm"] = [float(t.mean()), float(t.std(ddof=1)) if t.size > 1 else 0.0]
    return out


def table1_viewer(trials):
    """Table 1 in the viewer frame (z along the line of sight), or None without the v_* columns."""
    if not all(c in trials.columns for _, c in VIEWER_AXES) or trials[[c for _, c in VIEWER_AXES]].isna().any().any():
        return None
    return {mode: table1_row(trials[trials["mode"] == mode], VIEWER_AXES) for mode in modes_in(trials)}


def table2(joints):
    return {mode: summarize(joints.loc[joints["mode"] == mode, "error_deg"])
            for mode in MODES if (joints["mode"] == mode).any()}


def mann_whitney(x, y):
    """Two-sided pooled Mann-Whitney U: {"u_a", "p", "cliffs_delta", "n_a", "n_b"}; p None when
    a sample is empty or every value is tied. cliffs_delta = P(a > b) - P(a < b) = 2 U_a / (n_a n_b) - 1."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    out = {"n_a": int(x.size), "n_b": int(y.size), "u_a": None, "p": None, "cliffs_delta": None}
    if x.size == 0 or y.size == 0:
        return out
    r = scipy.stats.mannwhitneyu(x, y, alternative="two-sided", use_continuity=True, method="asymptotic")
    u = float(r.statistic)
    out["u_a"] = u
    out["cliffs_delta"] = 2 * u / (x.size * y.size) - 1
    if np.ptp(np.concatenate([x, y])) > 0:
        out["p"] = number(r.pvalue)
    return out


def pooled_errors(joints, mode, joint=None):
    rows = joints[joints["mode"] == mode]
    if joint is not None:
        rows = rows[rows["joint"].astype(int) == joint]
    return rows["error_deg"].astype(float).to_numpy()


def table3(joints):
    """The paper's reading: {pair: {"joint1".., "total"}} of two-sided pooled MWU p-values."""
    out = {}
    num_joints = int(joints["joint"].max())
    present = set(joints["mode"])
    for pair in PAIRS:
        a, b = pair_modes(pair)
        if a not in present or b not in present:
            continue
        row = {"total": mann_whitney(pooled_errors(joints, a), pooled_errors(joints, b))["p"]}
        for j in range(1, num_joints + 1):
            row["joint%d" % j] = mann_whitney(pooled_errors(joints, a, j), pooled_errors(joints, b, j))["p"]
        out[pair] = row
    return out


def table4(times):
    out = {}
    for mode in MODES:
        rows = times[times["mode"] == mode]
        if rows.empty:
            continue
        out[mode] = {"execution_s": summarize(rows["execution_s"])}
        alignment = rows["alignment_s"].dropna()
        if len(alignment):
            out[mode]["alignment_s"] = summarize(alignment)
    return out
