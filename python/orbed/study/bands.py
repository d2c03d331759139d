"""Predictive bands: what the model predicts for a study of the paper's size, figure by figure.

Input: a folder of M simulated studies, each file with a leading `study` column (study m = the
study `scripts/orbed study --seed S + U*m` would run):
  alignment_trials.csv, alignment_groups.csv   orbed-user-study --studies M --tables-dir DIR
  setup_joints.csv, setup_times.csv            orbed-setup-study --studies M --out DIR
  tables.json                                  orbed-study-tables --paper-only --out DIR (the paper's)
and experiments/calibration.yaml (the figures parameters were fitted to).

Per study, every figure of Tables 1-4 is computed as the study's analysis computes it (tables.py:
Table 1's per-axis means and stds and their norms, the SE(3) row of groups of N = 3; Table 2; Table
3 the paper's reading; Table 4). Per figure the 95 % predictive interval is the 2.5th to the 97.5th
percentile over the M studies (numpy's linear interpolation), and the paper's figure is inside when
lo <= paper <= hi. A figure a parameter was fitted to is "calibrated": reported, not counted. The
count k of n is over the figures with a paper value that are not calibrated.

Table 1's per-axis figures are also read in the viewer frame S (z the line of sight; the study's
v_* columns), as table1_viewer.<mode>.<axis>_<mean|std> against the same paper figures: the paper does
not name its axes, so S is an alternative reading, shown and not counted.

Figure names: table1.<mode>.<t_x|t_y|t_z|norm>_<mean|std>, table1.<mode>.se3_n3_<mean|std>,
table2.<mode>.<mean|median|min|max|std>, table3.<pair>.<joint1..joint6|total>,
table4.<mode>.<execution_s|alignment_s>.<mean|median|min|max|std>. Units: mm, deg, s; p-values.

    /usr/bin/python3 -m orbed.study.bands DIR [--calibration FILE]

writes DIR/bands.csv, DIR/bands.json and DIR/figures/bands.{pdf,png}, and prints k of n.
"""
import argparse
import json
import math
import os
import sys

import matplotlib
import matplotlib.ticker
import numpy as np
import yaml

from . import files, tables

STATS = ("mean", "median", "min", "max", "std")
LEVEL = 0.95
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
CALIBRATION = os.path.join(ROOT, "experiments", "calibration.yaml")


def flatten(t):
    """{figure name: value} of a tables.json-shaped dict (the paper's or a study's); absent parts are
    skipped, None values kept as NaN."""
    out = {}

    def put(name, value):
        out[name] = float("nan") if value is None else float(value)

    for mode, row in t.get("table1", {}).items():
        if mode in ("se3_mean", "se3_n3"):
            continue
        for axis in ("t_x", "t_y", "t_z", "norm"):
            if axis in row:
                put("table1.%s.%s_mean" % (mode, axis), row[axis][0])
                put("table1.%s.%s_std" % (mode, axis), row[axis][1])
    # The paper's SE(3) row ("means of N = 3 trials") is under se3_mean in its figures, se3_n3 in ours
    # (where se3_mean is each user's mean of all trials, not the paper's row).
    table1 = t.get("table1", {})
    for mode, row in table1.get("se3_n3", table1.get("se3_mean", {})).items():
        put("table1.%s.se3_n3_mean" % mode, row["norm"][0])
        put("table1.%s.se3_n3_std" % mode, row["norm"][1])
    for mode, row in t.get("table1_viewer", {}).items():
        for axis in ("t_x", "t_y", "t_z", "norm"):
            put("table1_viewer.%s.%s_mean" % (mode, axis), row[axis][0])
            put("table1_viewer.%s.%s_std" % (mode, axis), row[axis][1])
    for mode, row in t.get("table2", {}).items():
        for s in STATS:
            put("table2.%s.%s" % (mode, s), row[s])
    for pair, row in t.get("table3", {}).items():
        for key, value in row.items():
            put("table3.%s.%s" % (pair, key), value)
    for mode, row in t.get("table4", {}).items():
        for kind in ("execution_s", "alignment_s"):
            for s in STATS:
                if kind in row:
                    put("table4.%s.%s.%s" % (mode, kind, s), row[kind][s])
    return out


def study_figures(trials, groups, joints, times):
    """The figures of one study (frames of that study only; any may be None)."""
    t = {}
    if trials is not None and len(trials):
        t["table1"] = {mode: tables.table1_row(trials[trials["mode"] == mode]) for mode in tables.modes_in(trials)}
        if groups is not None and len(groups):
            t["table1"]["se3_n3"] = tables.table1_groups(groups)
        viewer = tables.table1_viewer(trials)
        if viewer is not None:
            t["table1_viewer"] = viewer
    if joints is not None and len(joints):
        t["table2"] = tables.table2(joints)
        t["table3"] = tables.table3(joints)
    if times is not None and len(times):
        t["table4"] = tables.table4(times)
    return flatten(t)


def per_study(frame, study):
    return None if frame is None else frame[frame["study"] == study]


def all_studies(folder):
    """{figure: [value per study]} over the studies in the folder's files."""
    frames = {name: files.read(folder, name + ".csv")
              for name in ("alignment_trials", "alignment_groups", "setup_joints", "setup_times")}
    studies = sorted({int(s) for f in frames.values() if f is not None for s in f["study"].unique()})
    if not studies:
        raise ValueError("%s: no study rows (alignment_trials.csv or setup_joints.csv with a study column)" % folder)
    values = {}
    for m in studies:
        figures = study_figures(*(per_study(frames[n], m) for n in
                                  ("alignment_trials", "alignment_groups", "setup_joints", "setup_times")))
        for name, value in figures.items():
            values.setdefault(name, []).append(value)
    return len(studies), values


def calibrated_figures(path=CALIBRATION):
    with open(path) as f:
        return {figure for p in yaml.safe_load(f)["parameters"] for figure in p["fitted_to"]}


def bands(values, paper, calibrated, level=LEVEL):
    """One record per figure with a paper value: its band over the studies and whether the paper's
    figure is inside. Figures without a paper value, or without a value in any study, are left out."""
    tail = 100 * (1 - level) / 2
    out = []
    # The paper's per-axis Table 1 figures read in the viewer frame too (an alternative reading).
    paper = dict(paper)
    for name, value in list(paper.items()):
        if name.startswith("table1.") and ".se3_n3_" not in name:
            paper.setdefault("table1_viewer." + name[len("table1."):], value)
    for name, p in paper.items():
        if math.isnan(p) or name not in values:
            continue
        v = np.array([x for x in values[name] if not math.isnan(x)])
        if v.size == 0:
            continue
        lo, median, hi = (float(x) for x in np.percentile(v, [tail, 50, 100 - tail]))
        out.append({"figure": name, "paper": p, "lo": lo, "median": median, "hi": hi, "studies": int(v.size),
                    "inside": bool(lo <= p <= hi), "calibrated": name in calibrated,
                    "alternative": name.startswith("table1_viewer.")})
    return out


def count(records):
    """(k, n): paper figures inside their band, of the figures neither calibrated nor an alternative
    reading."""
    counted = [r for r in records if not r["calibrated"] and not r.get("alternative")]
    return sum(r["inside"] for r in counted), len(counted)


def by_relation(joints):
    """Over every simulated set-up pooled: per start-target relation (bending joints 2, 4, 6: "same"
    every sign the target's, "mirror" every sign opposite, "mixed" otherwise; a start joint at 0 is
    mixed) and mode, the set-ups, the half-turn rate (joints with error > 90 deg) and the joint error's
    median and mean [deg]; None without start_deg. The model's answer to "where did the arm start?"."""
    if joints is None or "start_deg" not in joints.columns or joints["start_deg"].isna().any():
        return None
    keys = ["study", "user", "mode", "target"]
    bending = joints[joints["joint"].astype(int).isin((2, 4, 6))]
    start, target = np.sign(bending["start_deg"].astype(float)), np.sign(bending["target_deg"].astype(float))
    signs = bending.assign(same=start == target, mirror=(start == -target) & (target != 0))
    setups = signs.groupby(keys).agg(same=("same", "all"), mirror=("mirror", "all")).reset_index()
    setups["relation"] = np.where(setups["same"], "same", np.where(setups["mirror"], "mirror", "mixed"))
    tagged = joints.merge(setups[keys + ["relation"]], on=keys)
    error = tagged["error_deg"].astype(float)
    out = {}
    for (relation, mode), rows in tagged.assign(error=error).groupby(["relation", "mode"]):
        out.setdefault(relation, {})[mode] = {
            "setups": int(len(rows.groupby(keys))), "half_turn_rate": float((rows["error"] > 90).mean()),
            "median_deg": float(rows["error"].median()), "mean_deg": float(rows["error"].mean())}
    return out


def write(folder, calibration=CALIBRATION):
    with open(os.path.join(folder, "tables.json")) as f:
        paper = flatten(json.load(f)["paper"])
    m, values = all_studies(folder)
    records = bands(values, paper, calibrated_figures(calibration))
    k, n = count(records)
    with open(os.path.join(folder, "bands.csv"), "w") as f:
        f.write("figure,paper,lo,median,hi,studies,inside,calibrated,alternative\n")
        for r in records:
            f.write("%s,%.6g,%.6g,%.6g,%.6g,%d,%d,%d,%d\n" % (r["figure"], r["paper"], r["lo"], r["median"], r["hi"],
                                                              r["studies"], r["inside"], r["calibrated"],
                                                              r["alternative"]))
    summary = {"studies": m, "level": LEVEL, "inside": k, "counted": n,
               "calibrated": sorted(r["figure"] for r in records if r["calibrated"]), "figures": records,
               "by_relation": by_relation(files.read(folder, "setup_joints.csv"))}
    with open(os.path.join(folder, "bands.json"), "w") as f:
        json.dump(summary, f, indent=1)
    plot(records, m, k, n, os.path.join(folder, "figures"))
    return summary


# Per table: the panel's title, its x axis (label with unit) and scale. Joint errors span 0 (a
# joint set exactly) to 250 deg: symmetric-log, linear below 0.01 deg so that a 0 shows. p-values
# span 1e-18 to 1: log. Alignment errors (mm) and times (s) are linear.
PANELS = (("table1", "Table 1", "alignment error [mm]", "linear"),
          ("table1_viewer", "Table 1 read in the viewer frame S (an alternative reading, not counted)",
           "alignment error [mm]", "linear"),
          ("table2", "Table 2", "joint error [deg] (log scale; linear below 0.01)", "symlog"),
          ("table3", "Table 3, the paper's reading", "p-value, two-sided (log scale)", "log"),
          ("table4", "Table 4", "time [s] (ticks every minute)", "minutes"))
SYMLOG_THRESHOLD_DEG = 0.01


def decade_ticks(lo, hi, most=8):
    """Powers of ten covering [lo, hi] (lo > 0), every k-th decade so that at most `most` remain."""
    first, last = math.floor(math.log10(lo)), math.ceil(math.log10(hi))
    step = max(1, math.ceil((last - first + 1) / most))
    return [10.0 ** e for e in range(last, first - 1, -step)][::-1]


def tick_label(value):
    """0.01, 0.1, 1, 10, 100 as written; 1e-16 and the like for the p-values' far decades."""
    if value == 0:
        return "0"
    return "%g" % value if 1e-3 <= abs(value) < 1e5 else "1e%d" % round(math.log10(value))


def set_axis(ax, scale, values):
    """The panel's x scale with explicit, readable ticks over the values shown."""
    if scale == "symlog":
        ax.set_xscale("symlog", linthresh=SYMLOG_THRESHOLD_DEG)
        top = max(max(values), SYMLOG_THRESHOLD_DEG)
        ticks = [0.0] + decade_ticks(SYMLOG_THRESHOLD_DEG, top)
        ax.set_xlim(-0.2 * SYMLOG_THRESHOLD_DEG, ticks[-1] * 1.05)
    elif scale == "log":
        positive = [v for v in values if v > 0] or [1.0]
        ticks = decade_ticks(max(min(positive), 1e-300), max(max(positive), 1.0))
        ax.set_xscale("log")
        ax.set_xlim(ticks[0] / 2, ticks[-1] * 2)
    elif scale == "minutes":
        ticks = [60.0 * i for i in range(int(1.03 * max(values) // 60) + 2)]
        ax.set_xlim(0.0, ticks[-1])
    else:
        return
    ax.set_xticks(ticks)
    ax.set_xticklabels([tick_label(t) for t in ticks])
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())


def plot(records, m, k, n, out_dir):
    """One panel per table: each figure's band (bar), the studies' median (tick) and the paper's value
    (dot: filled inside, a cross outside, grey when calibrated). Vector PDF and 300-dpi PNG."""
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(out_dir, exist_ok=True)
    panels = [(key, title, label, scale, [r for r in records if r["figure"].startswith(key + ".")])
              for key, title, label, scale in PANELS]
    panels = [p for p in panels if p[4]]
    heights = [max(2.0, 0.22 * len(p[4]) + 1.1) for p in panels]
    fig, axes = plt.subplots(len(panels), 1, figsize=(8.5, sum(heights)), gridspec_kw={"height_ratios": heights},
                             squeeze=False)
    for ax, (key, title, label, scale, rows) in zip(axes[:, 0], panels):
        y = np.arange(len(rows))[::-1]
        for yi, r in zip(y, rows):
            ax.plot([r["lo"], r["hi"]], [yi, yi], color="#4c72b0", lw=4, solid_capstyle="butt", alpha=0.6)
            ax.plot([r["median"]], [yi], marker="|", color="#1f3b73", ms=9)
            set_apart = r["calibrated"] or r.get("alternative")
            color = "0.55" if set_apart else ("#2a9d3f" if r["inside"] else "#d62728")
            ax.plot([r["paper"]], [yi], marker="o" if r["inside"] else "X", color=color, ms=6, ls="none")
        ax.set_yticks(y)
        ax.set_yticklabels([r["figure"].split(".", 1)[1] for r in rows], fontsize=7)
        ax.set_title(title, fontsize=10, loc="left")
        ax.set_xlabel(label, fontsize=9)
        set_axis(ax, scale, [v for r in rows for v in (r["lo"], r["hi"], r["paper"])])
        ax.grid(axis="x", which="major", alpha=0.3)
        ax.set_ylim(-0.7, len(rows) - 0.3)
    handles = [plt.Line2D([], [], color="#4c72b0", lw=4, alpha=0.6, label="95 % predictive interval"),
               plt.Line2D([], [], color="#1f3b73", marker="|", ls="none", ms=9, label="median of the studies"),
               plt.Line2D([], [], color="#2a9d3f", marker="o", ls="none", label="paper, inside"),
               plt.Line2D([], [], color="#d62728", marker="X", ls="none", label="paper, outside"),
               plt.Line2D([], [], color="0.55", marker="o", ls="none", label="paper, calibrated or viewer frame (not counted)")]
    fig.legend(handles=handles, loc="lower center", ncol=3, fontsize=8, frameon=False)
    fig.suptitle("Predictive bands over %d simulated studies: %d of %d paper figures inside" % (m, k, n), fontsize=11)
    fig.tight_layout(rect=(0, 0.04, 1, 0.98))
    fig.savefig(os.path.join(out_dir, "bands.pdf"))
    fig.savefig(os.path.join(out_dir, "bands.png"), dpi=300)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python3 -m orbed.study.bands", description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", help="the simulated studies' folder (see the module's documentation)")
    parser.add_argument("--calibration", default=CALIBRATION, help="the calibration set (default: the shipped one)")
    args = parser.parse_args(argv)
    try:
        s = write(args.folder, args.calibration)
    except (OSError, ValueError, KeyError) as e:
        print("bands: %s" % e, file=sys.stderr)
        return 1
    print("bands: %d of %d paper figures inside their %d %% predictive interval over %d studies (%d calibrated, "
          "not counted); %s" % (s["inside"], s["counted"], round(100 * s["level"]), s["studies"],
                                len(s["calibrated"]), os.path.join(args.folder, "bands.csv")))
    return 0


if __name__ == "__main__":
    sys.exit(main())
