#!/usr/bin/python3
"""orbed study report: report.html and figures/ from a study folder (scripts/orbed study).

Usage: /usr/bin/python3 scripts/report.py STUDY_DIR

Reads STUDY_DIR/tables.json, setup_joints.csv, setup_times.csv and, when present,
alignment_trials.csv, landmark_validation.csv (orbed-study-tables writes them), provenance.json
(scripts/provenance.py) and bands/ (scripts/orbed study --bands M: bands.json, rank_flip.csv,
figures/bands.{pdf,png}), and writes, each figure as a vector PDF and a 300-dpi PNG:
  figures/joint_errors   per-joint error distributions per guidance mode (violins; the paper's
                         Fig. 6), the paper's median over all joints (Table 2) dashed
  figures/total_errors   every joint's error per mode (violins; the paper's Fig. 7), the paper's mean
                         and median (Table 2) beside each violin
  figures/joint_rank     the mean error per joint and mode on a log scale (ticks 0.1, 1, 10, 100 deg),
                         twisting joints (odd) and revolving joints (even) told apart (the paper's
                         Fig. 8), the paper's mean per mode dashed
  figures/power          the power analysis's curves, the paper's 8 users marked
  report.html            Tables 1-4 beside the paper's (Table 1 with its SE(3) row of groups of N = 3
                         and the landmark check), the figures (PNG shown, PDF linked), the reviewer's
                         analysis of the set-up half (tables.json setup_analysis: paired tests with
                         the set-up and the user as the unit, Holm-corrected per-joint tests, the
                         mixed model, effect sizes, per target, half-turn rates) beside the paper's
                         reading, the predictive bands (k of n paper figures inside, each figure's
                         band, the bands figure) and the rank flip when bands/ exists, the
                         ground-truth columns the paper could not measure, and a provenance footer
                         (commit, command line, host, times, settings).
tables.json's numbers are python/orbed/study's (python3 -m orbed.study STUDY_DIR); this only
formats them. Needs python3-matplotlib (Debian); for the rank flip python/orbed/study/rank_flip.py
(statsmodels).
"""
import csv
import html
import json
import math
import os
import statistics
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.patches  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

MODES = ("ar_reflective", "ar", "fixed")
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LABELS = {"ar_reflective": "AR + reflective display", "ar": "AR", "fixed": "fixed display"}
COLORS = {"ar_reflective": "#4c72b0", "ar": "#55a868", "fixed": "#c44e52"}


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def violins(ax, data, positions, color):
    parts = ax.violinplot([d if d else [0.0] for d in data], positions=positions, widths=0.8,
                          showmedians=True)
    for body in parts["bodies"]:
        body.set_facecolor(color)
        body.set_alpha(0.6)
    for key in ("cbars", "cmins", "cmaxes", "cmedians"):
        parts[key].set_color("0.3")
        parts[key].set_linewidth(1)


# A log axis of angles in degrees reads best with round decades written out (0.1, 1, 10, 100),
# not matplotlib's 10^k labels.
DEGREE_TICKS = (0.01, 0.1, 1, 10, 100, 1000)


def decade_label(value):
    return "%g" % value


def log_degree_axis(ax, lo, hi):
    """y on a log scale from lo to hi [deg], ticked at the decades of DEGREE_TICKS inside it."""
    ax.set_yscale("log")
    ax.set_ylim(lo, hi)
    ticks = [t for t in DEGREE_TICKS if lo <= t <= hi]
    ax.set_yticks(ticks)
    ax.set_yticklabels([decade_label(t) for t in ticks])
    ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())


def save(fig, study_dir, name):
    """figures/NAME.pdf (vector) and figures/NAME.png (300 dpi) of one figure, then closes it."""
    folder = os.path.join(study_dir, "figures")
    os.makedirs(folder, exist_ok=True)
    fig.savefig(os.path.join(folder, name + ".pdf"))
    fig.savefig(os.path.join(folder, name + ".png"), dpi=300)
    plt.close(fig)


def figure_html(path, caption):
    """A figure of the page: the PNG shown, linked to its PDF beside it (path without extension,
    relative to report.html)."""
    return ("<figure><a href='%s.pdf'><img src='%s.png'></a><figcaption>%s (<a href='%s.pdf'>PDF</a>)"
            "</figcaption></figure>" % (path, path, caption, path))


def figures(study_dir, joints_rows, paper_table2=None):
    """The paper's Figs. 6-8 from setup_joints.csv, Table 2's paper values (mean, median over all
    joints per mode) marked on them when given."""
    paper_table2 = paper_table2 or {}
    modes = [m for m in MODES if any(r["mode"] == m for r in joints_rows)]
    num_joints = max(int(r["joint"]) for r in joints_rows)
    joints = list(range(1, num_joints + 1))

    def errors(mode, joint=None):
        return [float(r["error_deg"]) for r in joints_rows
                if r["mode"] == mode and (joint is None or int(r["joint"]) == joint)]

    # Fig. 6: per joint and mode; the paper's median over all joints of the mode as a dashed line.
    fig, axes = plt.subplots(1, len(modes), figsize=(4.2 * len(modes) + 1.6, 3.8), sharey=True, squeeze=False)
    axes = axes[0]
    for ax, mode in zip(axes, modes):
        violins(ax, [errors(mode, j) for j in joints], joints, COLORS[mode])
        p = paper_table2.get(mode)
        if p:
            ax.axhline(p["median"], color="k", linestyle="--", linewidth=1)
        ax.set_title(LABELS[mode])
        ax.set_xlabel("joint")
        ax.set_xticks(joints)
    axes[0].set_ylabel("|reached - target| [deg]")
    if any(paper_table2.get(m) for m in modes):
        axes[-1].legend(handles=[plt.Line2D([], [], color="k", linestyle="--", label="paper: median over\nall joints (Table 2)")],
                        loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8, frameon=False)
    fig.tight_layout()
    save(fig, study_dir, "joint_errors")

    # Fig. 7: every joint's error per mode; the paper's mean and median per mode as markers.
    fig, ax = plt.subplots(figsize=(7.5, 4))
    for i, mode in enumerate(modes):
        violins(ax, [errors(mode)], [i + 1], COLORS[mode])
        p = paper_table2.get(mode)
        if p:
            ax.plot([i + 1.45], [p["mean"]], marker="D", color="k", ls="none")
            ax.plot([i + 1.45], [p["median"]], marker="_", color="k", ms=14, mew=2, ls="none")
        values = errors(mode)
        if values:
            ax.plot([i + 1], [statistics.mean(values)], marker="D", color="w", mec="k", ls="none")
    ax.set_xticks(list(range(1, len(modes) + 1)))
    ax.set_xticklabels([LABELS[m] for m in modes])
    ax.set_xlim(0.4, len(modes) + 0.8)
    ax.set_xlabel("guidance mode")
    ax.set_ylabel("joint error, all joints [deg]")
    handles = [plt.Line2D([], [], color="0.3", linewidth=1, label="this study: median (bar)"),
               plt.Line2D([], [], marker="D", color="w", mec="k", ls="none", label="this study: mean"),
               plt.Line2D([], [], marker="D", color="k", ls="none", label="paper: mean (Table 2)"),
               plt.Line2D([], [], marker="_", color="k", ms=14, mew=2, ls="none", label="paper: median (Table 2)")]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8, frameon=False)
    fig.tight_layout()
    save(fig, study_dir, "total_errors")

    # Fig. 8: mean per joint and mode on a log scale; the paper's mean over all joints per mode as a
    # dashed line of the mode's colour (the paper gives no per-joint numbers).
    fig, ax = plt.subplots(figsize=(8.5, 4))
    width = 0.8 / len(modes)
    means = []
    for i, mode in enumerate(modes):
        for j in joints:
            values = errors(mode, j)
            mean = statistics.mean(values) if values else 0.0
            means.append(mean)
            twisting = any(r["twisting"] == "1" for r in joints_rows if int(r["joint"]) == j)
            ax.bar(j - 0.4 + (i + 0.5) * width, max(mean, 1e-3), width, color=COLORS[mode],
                   edgecolor="red" if twisting else "blue", linewidth=1.5)
        p = paper_table2.get(mode)
        if p:
            ax.axhline(p["mean"], color=COLORS[mode], linestyle="--", linewidth=1.2)
            means.append(p["mean"])
    positive = [m for m in means if m > 0] or [1.0]
    lo = 10 ** math.floor(math.log10(min(positive)))
    hi = 10 ** math.ceil(math.log10(max(positive) * 1.01))
    log_degree_axis(ax, max(lo, DEGREE_TICKS[0]), max(hi, 10 * lo))
    ax.set_xticks(joints)
    ax.set_xlabel("joint")
    ax.set_ylabel("mean error [deg], log scale")
    handles = [matplotlib.patches.Patch(facecolor=COLORS[m], label=LABELS[m]) for m in modes]
    handles += [matplotlib.patches.Patch(facecolor="white", edgecolor="red", linewidth=1.5, label="twisting joint"),
                matplotlib.patches.Patch(facecolor="white", edgecolor="blue", linewidth=1.5, label="revolving joint")]
    if any(paper_table2.get(m) for m in modes):
        handles.append(plt.Line2D([], [], color="0.3", linestyle="--", label="paper: mean over all\njoints (Table 2)"))
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8, frameon=False)
    fig.tight_layout()
    save(fig, study_dir, "joint_rank")


def power_figure(study_dir, beyond, paper_users=8):
    """The power analysis's curves (tables.json beyond.power): one line per pair of modes; the
    paper's number of users marked."""
    curves = beyond.get("power", {})
    if not curves:
        return False
    fig, ax = plt.subplots(figsize=(8, 4))
    for i, (pair, curve) in enumerate(curves.items()):
        color = "C%d" % i
        ax.plot(curve["users"], curve["power"], marker="o", linestyle="--", color=color,
                label=pair + ", pooled (paper's reading)")
        if "power_paired" in curve:
            ax.plot(curve["users"], curve["power_paired"], marker="s", color=color, label=pair + ", paired set-ups")
    ax.axhline(0.8, color="grey", linestyle=":", linewidth=1, label="power 0.8")
    ax.axvline(paper_users, color="k", linestyle="-.", linewidth=1, label="the paper's %d users" % paper_users)
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlabel("users in the study [people]")
    ax.set_ylabel("power of the total test (alpha 0.05) [probability]")
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)
    fig.tight_layout()
    save(fig, study_dir, "power")
    return True


def beyond_section(study_dir, beyond):
    """Docking error, collisions and the power analysis: numbers the paper did not report."""
    parts = ["<h2>Beyond the paper</h2>"]
    docking = beyond.get("docking", {})
    collisions = beyond.get("collisions", {})
    if docking or collisions:
        parts.append("<table><tr><th></th><th>docking: tool tip [mm] median / max</th>"
                     "<th>tool axis [deg] median / max</th><th>set-ups</th><th>contacts</th>"
                     "<th>collision stops</th><th>near misses (&lt; %s cm)</th>"
                     "<th>smallest clearance [mm]</th></tr>" % fmt(beyond.get("near_miss_m", 0) * 100, 0))
        for mode in MODES:
            d = docking.get(mode)
            c = collisions.get(mode)
            if not d and not c:
                continue
            tip = "%s / %s" % (fmt(d["tip_mm"]["median"], 0), fmt(d["tip_mm"]["max"], 0)) if d else "-"
            axis = "%s / %s" % (fmt(d["axis_deg"]["median"]), fmt(d["axis_deg"]["max"])) if d else "-"
            clearance = c.get("min_clearance_m") if c else None
            parts.append("<tr><th>%s</th><td>%s</td><td>%s</td><td>%s</td><td>%s</td><td>%s</td><td>%s</td>"
                         "<td>%s</td></tr>" % (
                             LABELS[mode], tip, axis, c["setups"] if c else "-", c["contact"] if c else "-",
                             c["collision_stops"] if c else "-", c["near_miss"] if c else "-",
                             fmt(clearance["min"] * 1e3, 0) if clearance else "-"))
        parts.append("</table><p>The docking error is where the tool tip and its axis end up against where "
                     "the target configuration puts them at the trocar (forward kinematics of the sim's "
                     "joints); contacts, stops and clearances are the sim's collision checks while the "
                     "assistant moved the arm.</p>")
    power = beyond.get("power", {})
    if power:
        def needed(curve, key):
            return curve.get(key) if curve.get(key) is not None else "more than %d" % curve["users"][-1]
        parts.append("<p>Power analysis (%s). Users needed for 80 %% power, pooled (the paper's reading) / "
                     "paired set-ups: %s.</p>" % (
                         html.escape(beyond.get("power_method", "")),
                         ", ".join("%s %s / %s" % (html.escape(pair), needed(curve, "users_for_80"),
                                                   needed(curve, "users_for_80_paired") if "power_paired" in curve
                                                   else "-")
                                   for pair, curve in power.items())))
        if power_figure(study_dir, beyond):
            parts.append(figure_html("figures/power", "Power of Table 3's total test against the number of "
                                                      "users, from the emulated people"))
    return parts


BAND_UNITS = {"table1": "mm", "table1_viewer": "mm", "table2": "deg", "table3": "p", "table4": "s"}


def band_status(record):
    if record.get("alternative"):
        return "viewer-frame reading (%s; not counted)" % ("inside" if record["inside"] else "outside")
    if record["calibrated"]:
        return "calibrated (%s; not counted)" % ("inside" if record["inside"] else "outside")
    return "inside" if record["inside"] else "<b>outside</b>"


def bands_section(study_dir):
    """The predictive bands (STUDY/bands/bands.json, python/orbed/study/bands.py) and the rank flip
    (STUDY/bands/rank_flip.csv); nothing when the study ran without --bands."""
    folder = os.path.join(study_dir, "bands")
    path = os.path.join(folder, "bands.json")
    if not os.path.exists(path):
        return []
    with open(path) as f:
        b = json.load(f)
    level = round(100 * b["level"])
    parts = ["<h2>Predictive bands: the paper's figures against %d simulated studies</h2>" % b["studies"],
             "<p class=count><b>%d of %d paper figures inside</b> their %d %% predictive interval (calibrated ones "
             "not counted: %d figures a parameter was fitted to, experiments/calibration.yaml). Each simulated "
             "study has the paper's size and is analysed as this one; the band of a figure is the central %d %% "
             "of its values over the studies (2.5th to 97.5th percentile). The same seed as this study "
             "(<code>scripts/orbed study --bands %d</code>).</p>" % (
                 b["inside"], b["counted"], level, len(b["calibrated"]), level, b["studies"])]
    parts.append(figure_html("bands/figures/bands", "Each figure's %d %% predictive interval (bar), the studies' "
                                                    "median (tick) and the paper's value (dot)" % level))
    flips = rank_flip_line(folder)
    if flips:
        parts.append("<p class=rank-flip>%s</p>" % flips)
    relations = b.get("by_relation") or {}
    if relations:
        parts.append("<p>Where the arm started, over every simulated set-up: the start-target relation of "
                     "the bending joints 2, 4, 6 (same signs, all opposite: mirror, else mixed).</p>")
        parts.append("<table class=relations><tr><th>relation</th><th>mode</th><th>set-ups</th>"
                     "<th>median error [deg]</th><th>mean error [deg]</th><th>half-turn rate</th></tr>")
        for relation, modes in relations.items():
            for mode, v in modes.items():
                parts.append("<tr><th>%s</th><td>%s</td><td>%d</td><td>%s</td><td>%s</td><td>%.2f</td></tr>" % (
                    html.escape(relation), LABELS.get(mode, html.escape(mode)), v["setups"], fmt(v["median_deg"]),
                    fmt(v["mean_deg"]), v["half_turn_rate"]))
        parts.append("</table>")
    parts.append("<table class=bands><tr><th>figure</th><th>unit</th><th class=paper>paper</th><th>band (%d %%)</th>"
                 "<th>median of the studies</th><th>the paper's figure is</th></tr>" % level)
    for r in b["figures"]:
        digits = 2 if r["figure"].startswith("table3.") else 1
        number = (lambda v: "%.2g" % v) if digits == 2 else (lambda v: fmt(v))
        parts.append("<tr><th>%s</th><td>%s</td><td class=paper>%s</td><td>[%s, %s]</td><td>%s</td><td>%s</td></tr>" % (
            html.escape(r["figure"]), BAND_UNITS.get(r["figure"].split(".")[0], ""), number(r["paper"]),
            number(r["lo"]), number(r["hi"]), number(r["median"]), band_status(r)))
    parts.append("</table>")
    return parts


def sensitivity_section(study_dir):
    """The set-up half's one-at-a-time sensitivity (STUDY/sensitivity/sensitivity.csv,
    python/orbed/study/sensitivity.py): per setting, each mode's mean joint error, half-turn rate and
    execution time beside the shipped parameters'; nothing when the study ran without --sensitivity."""
    path = os.path.join(study_dir, "sensitivity", "sensitivity.csv")
    if not os.path.exists(path):
        return []
    values = {}  # setting -> output -> value
    for row in read_csv(path):
        values.setdefault(row["setting"], {})[row["output"]] = float(row["value"])
    base = values.get("baseline", {})
    columns = [(m, o) for o in ("mean_error_deg", "half_turn_rate", "execution_s") for m in
               ("ar_reflective", "ar", "fixed") if "%s.%s" % (m, o) in base]
    heads = {"mean_error_deg": "mean error [deg]", "half_turn_rate": "half-turn rate", "execution_s": "execution [s]"}
    parts = ["<h2>Sensitivity to the parameters without a source</h2>",
             "<p>The set-up half's simulated studies again for every assistant parameter whose source is a choice, "
             "at each end of its band (experiments/setup/sensitivity.yaml), one key at a time, the same seeds "
             "in every setting (<code>scripts/orbed sensitivity</code>). The first row is the shipped "
             "parameters.</p>"]
    parts.append(figure_html("sensitivity/figures/sensitivity", "Each setting's mean joint error, half-turn rate "
                                                               "and mean execution time per mode; dashed: the "
                                                               "shipped parameters"))
    parts.append("<table class=sensitivity><tr><th>setting</th>%s</tr>" % "".join(
        "<th>%s %s</th>" % (LABELS.get(m, m), heads[o]) for m, o in columns))
    for setting, row in values.items():
        cells = []
        for m, o in columns:
            v = row.get("%s.%s" % (m, o))
            cells.append("<td>%s</td>" % ("-" if v is None else ("%.2f" % v if o == "half_turn_rate" else fmt(v))))
        parts.append("<tr><th>%s</th>%s</tr>" % (html.escape(setting), "".join(cells)))
    parts.append("</table>")
    return parts


def rank_flip_line(folder):
    """One sentence on how often the paper's Table 1 measurement ranks the two display modes
    opposite to the truth, from FOLDER/rank_flip.csv (python/orbed/study/rank_flip.py); None without
    the file."""
    path = os.path.join(folder, "rank_flip.csv")
    if not os.path.exists(path):
        return None
    sys.path.insert(0, os.path.join(ROOT, "python"))
    from orbed.study import rank_flip  # statsmodels: imported only when there is a rank flip to show

    try:
        s = rank_flip.summarize(rank_flip.read_rows(path))
    except (ValueError, KeyError) as e:
        return "Rank flip: %s has no usable rows (%s)." % (html.escape(os.path.basename(path)), html.escape(str(e)))
    return ("Rank flip: in %d of %d simulated studies (%s %%, 95 %% Wilson interval %s-%s %%) the paper's Table 1 "
            "measurement (norm of the per-axis means, axes of W) ranks the AR + reflective display and AR alone "
            "opposite to the truth (the registration's translation error at the robot's centroid)." % (
                s["flips"], s["studies"], fmt(100 * s["fraction"]), fmt(100 * s["low"]), fmt(100 * s["high"])))


def landmark_check(tables, study_dir):
    """The measurement's own error: landmarks a known distance apart annotated by gaze (the paper's
    optical-table check, 3.6 mm)."""
    if "landmark_validation_mm" not in tables:
        return ""
    rows_path = os.path.join(study_dir, "landmark_validation.csv")
    rows = read_csv(rows_path) if os.path.exists(rows_path) else []
    separations = sorted({float(r["separation_mm"]) for r in rows})
    what = (" (%d measurements of pairs %s mm apart)" % (len(rows), ", ".join("%g" % d for d in separations))
            if rows else "")
    paper = tables.get("paper", {}).get("landmark_validation_mm")
    return ("<p class=landmark-check>Landmark check, the measurement's own error: the distance between two "
            "landmarks annotated by gaze against their true separation%s: mean error %s mm (paper %s mm, "
            "targets 5-20 cm apart on an optical table, 12 measurements).</p>" % (
                what, fmt(tables["landmark_validation_mm"]), fmt(paper) if paper is not None else "-"))


def pv(p):
    return "-" if p is None else "%.2g" % p


def ci(pair_of_values, digits=1):
    lo, hi = pair_of_values
    return "-" if lo is None else "[%s, %s]" % (fmt(lo, digits), fmt(hi, digits))


def setup_analysis_section(a):
    """The reviewer's analysis (tables.json setup_analysis) beside the paper's reading."""
    parts = ["<h2>The set-up half as a reviewer reads it</h2>",
             "<p>The paper's Table 3 pools every joint of every set-up and compares two modes unpaired; its "
             "values are neither independent (seven joints of one set-up, three set-ups of one person) nor "
             "unpaired (every user did every mode on the same targets). Below, each test names its unit. All "
             "tests are two-sided; r is the matched-pairs rank-biserial correlation (positive: the first mode's "
             "errors larger), delta Cliff's delta; the median paired difference is first minus second mode "
             "[deg] with a 95 % bootstrap CI.</p>",
             "<table><tr><th>modes</th><th>test</th><th>unit</th><th>n</th><th>p</th><th>effect size</th>"
             "<th>median difference [deg]</th></tr>"]
    for pair, t in a.get("pairs", {}).items():
        m = t["pooled_mwu"]
        parts.append("<tr><th>%s</th><td>Mann-Whitney U (the paper's reading)</td><td>%s</td><td>%d + %d</td>"
                     "<td>%s</td><td>delta %s</td><td>-</td></tr>" % (
                         html.escape(pair), html.escape(m["unit"]), m["n_a"], m["n_b"], pv(m["p"]),
                         fmt(m["cliffs_delta"], 2)))
        for key in ("by_setup", "by_user"):
            w = t[key]
            parts.append("<tr><th>%s</th><td>Wilcoxon signed-rank (%s)</td><td>%s</td><td>%d</td><td>%s</td>"
                         "<td>r %s</td><td>%s %s</td></tr>" % (
                             html.escape(pair), w["method"] or "-", html.escape(w["unit"]), w["n"], pv(w["p"]),
                             fmt(w["rank_biserial"], 2), fmt(w["median_difference"]), ci(w["median_difference_ci95"])))
    parts.append("</table>")
    joints = sorted({j for t in a.get("pairs", {}).values() for j in t["per_joint"]}, key=lambda k: int(k[5:]))
    if joints:
        parts.append("<h3>Per joint: paired Wilcoxon on each set-up's joint error, Holm-corrected over the "
                     "joints</h3><table><tr><th></th>%s</tr>" % "".join("<th>%s</th>" % j for j in joints))
        for pair, t in a["pairs"].items():
            parts.append("<tr><th>%s</th>%s</tr>" % (html.escape(pair), "".join(
                "<td>%s<br><b>%s</b><br>r %s</td>" % (pv(t["per_joint"][j]["p"]), pv(t["per_joint"][j]["p_holm"]),
                                                     fmt(t["per_joint"][j]["rank_biserial"], 2)) for j in joints)))
        parts.append("</table><p>Each cell: the raw p, the Holm-adjusted p (bold), the rank-biserial r.</p>")
    mm = a.get("mixed_model")
    if mm:
        ratio = mm["scale"].startswith("ln(")
        parts.append("<h3>Mixed-effects model</h3><p><code>%s</code>, REML (statsmodels MixedLM, crossed random "
                     "intercepts); reference mode %s, reference kind revolving; %d joint errors of %d users on %d "
                     "targets. Scale: %s (%s). Variance components: %s; residual %s.%s</p>" % (
                         html.escape(mm["formula"]), html.escape(mm["reference"]["mode"]), mm["n"], mm["users"],
                         mm["targets"], html.escape(mm["scale"]), html.escape(mm["why"]),
                         ", ".join("%s %s" % (html.escape(k), fmt(v, 3)) for k, v in mm["variance_components"].items()),
                         fmt(mm["residual_variance"], 3), "" if mm["converged"] else " <b>Did not converge.</b>"))
        parts.append("<table><tr><th>term</th><th>estimate</th><th>95 %% CI</th><th>p</th>%s</tr>" % (
            "<th>factor on the error</th><th>95 % CI</th>" if ratio else ""))
        for c in mm["coefficients"]:
            parts.append("<tr><th>%s</th><td>%s</td><td>%s</td><td>%s</td>%s</tr>" % (
                html.escape(c["term"]), fmt(c["estimate"], 3), ci(c["ci95"], 3), pv(c["p"]),
                "<td>%s</td><td>%s</td>" % (fmt(c["ratio"], 2), ci(c["ratio_ci95"], 2)) if ratio else ""))
        parts.append("</table>")
    per_target = a.get("per_target", {})
    if per_target:
        parts.append("<h3>Per target (grouped by %s)</h3><table><tr><th>target</th><th>mode</th><th>set-ups</th>"
                     "<th>mean [deg]</th><th>median</th><th>max</th><th>half-turn rate</th></tr>" %
                     html.escape(a.get("target_grouping", "target")))
        for key, t in per_target.items():
            for mode, s in t["modes"].items():
                parts.append("<tr><th>%s</th><td>%s</td><td>%d</td><td>%s</td><td>%s</td><td>%s</td><td>%s</td></tr>" % (
                    html.escape(key), LABELS.get(mode, mode), s["setups"], fmt(s["mean"]), fmt(s["median"]),
                    fmt(s["max"]), fmt(100 * s["half_turn_rate"], 0) + " %"))
        parts.append("</table><table><tr><th>target</th>%s</tr>" % "".join(
            "<th>%s: p (n, r)</th>" % html.escape(pair) for pair in a.get("pairs", {})))
        for key, t in per_target.items():
            parts.append("<tr><th>%s</th>%s</tr>" % (html.escape(key), "".join(
                "<td>%s (%d, %s)</td>" % (pv(w["p"]), w["n"], fmt(w["rank_biserial"], 2)) if w else "<td>-</td>"
                for w in (t["paired"].get(pair) for pair in a.get("pairs", {})))))
        parts.append("</table><p>Paired Wilcoxon over the users' set-ups on that target (per-set-up mean error).</p>")
    h = a.get("half_turns")
    if h:
        parts.append("<h3>Half-turns (a set-up joint with an error above %s deg)</h3><table><tr><th>mode</th>"
                     "<th>joints</th><th>half-turns</th><th>rate</th><th>set-ups with one</th></tr>" %
                     fmt(h["threshold_deg"], 0))
        for mode, c in h["by_mode"].items():
            parts.append("<tr><th>%s</th><td>%d</td><td>%d</td><td>%s %%</td><td>%d of %d</td></tr>" % (
                LABELS.get(mode, mode), c["joints"], c["half_turns"], fmt(100 * c["rate"], 1),
                c["setups_with_half_turn"], c["setups"]))
        parts.append("</table>")
        if h.get("by_relation"):
            parts.append("<p>By the start-target relation over the bending joints 2, 4, 6 (same signs, mirrored, "
                         "mixed):</p><table><tr><th>relation</th><th>mode</th><th>set-ups</th><th>half-turn rate"
                         "</th></tr>")
            for relation, modes in h["by_relation"].items():
                for mode, c in modes.items():
                    parts.append("<tr><th>%s</th><td>%s</td><td>%d</td><td>%s %%</td></tr>" % (
                        relation, LABELS.get(mode, mode), c["setups"], fmt(100 * c["rate"], 1)))
            parts.append("</table>")
        else:
            parts.append("<p>No start angles in setup_joints.csv: no breakdown by start-target relation.</p>")
    return parts


def fmt(value, digits=1):
    if value is None:
        return "-"
    if isinstance(value, float) and (abs(value) < 1e-2 and value != 0):
        return "%.2g" % value
    return ("%." + str(digits) + "f") % value


def clock(seconds):
    total = int(round(seconds))
    return "%d:%02d" % (total // 60, total % 60)


def stats_row(name, ours, paper, as_clock=False):
    keys = ("mean", "median", "min", "max", "std")
    f = clock if as_clock else fmt
    cells = "".join("<td>%s</td>" % (f(ours[k]) if ours else "-") for k in keys)
    cells += "".join("<td class=paper>%s</td>" % (f(paper[k]) if paper else "-") for k in keys)
    return "<tr><th>%s</th>%s</tr>" % (html.escape(name), cells)


def provenance_footer(study_dir):
    """Where the numbers came from: the study folder's provenance record (scripts/provenance.py:
    version, commit and whether the tree was dirty, the command line, host, start and end times,
    settings)."""
    path = os.path.join(study_dir, "provenance.json")
    if not os.path.exists(path):
        return "<footer><p>No provenance.json in this folder: made without scripts/orbed.</p></footer>"
    with open(path) as f:
        p = json.load(f)
    git = p.get("git") or {}
    commit = (git.get("commit") or "unknown commit") + (" (uncommitted changes)" if git.get("dirty") else "")
    settings = ", ".join("%s=%s" % (k, v) for k, v in sorted((p.get("settings") or {}).items()))
    ended = ("finished %s with exit code %s" % (p["ended_utc"], p.get("exit_code")) if p.get("ended_utc")
             else "not finished when the report was made")
    return ("<footer class=provenance><hr><p>Made by orbed %s at commit %s, run %s on host %s, started %s, %s: "
            "<code>%s</code>. Settings: %s. Every input and output with its SHA-256: provenance.json (and each "
            "user's run folder's); check them with <code>scripts/orbed verify</code>.</p></footer>" % (
                html.escape(str(p.get("orbed_version"))), html.escape(commit), html.escape(p.get("run", "")),
                html.escape(p.get("host", "")), html.escape(p.get("started_utc", "")), html.escape(ended),
                html.escape(" ".join(p.get("command_line") or [])), html.escape(settings or "none")))


def table1_section(tables):
    """Table 1 (tables.json table1, table1_viewer) beside the paper's: the per-trial rows, the SE(3)
    rows (means of N = 3 trials: the paper's statistic; the mean of each user's trials, labelled as
    not the paper's), the per-axis errors in W and in the viewer's frame."""
    if not tables.get("table1"):
        return []
    paper = tables.get("paper", {})
    parts = []
    parts.append("<h2>Table 1: ViRAAl landmark misalignment [mm]</h2>"
                 "<p>Measured as the paper did: three landmarks on the real robot and on the hologram, "
                 "each annotated by head gaze from two positions (rays from the headset's estimated "
                 "pose) and triangulated by orbed-registration. Nobody looks at an SE(3) mean: it is scored "
                 "against the real landmarks annotated in the user's trials, its virtual landmarks "
                 "placed by the mean.</p><table>"
                 "<tr><th></th><th>norm of means</th><th>norm of stds</th>"
                 "<th class=paper>paper</th></tr>")
    for mode in ("ar_reflective", "ar"):
        row = tables["table1"].get(mode)
        prow = paper.get("table1", {}).get(mode)
        if row:
            parts.append("<tr><th>%s</th><td>%s</td><td>%s</td><td class=paper>%s</td></tr>" % (
                LABELS[mode], fmt(row["norm"][0]), fmt(row["norm"][1]),
                "%s +/- %s" % (fmt(prow["norm"][0]), fmt(prow["norm"][1])) if prow else "-"))
    pse3 = paper.get("table1", {}).get("se3_mean", {})
    for mode, row in tables["table1"].get("se3_n3", {}).items():
        p = pse3.get(mode)
        parts.append("<tr><th>%s: SE(3) means of N = 3 trials (%d groups; the paper's statistic, measured "
                     "against the landmarks annotated in the group's trials)</th>"
                     "<td>%s</td><td>%s</td><td class=paper>%s</td></tr>" % (
                         LABELS[mode], row["groups"], fmt(row["norm"][0]), fmt(row["norm"][1]),
                         "%s +/- %s" % (fmt(p["norm"][0]), fmt(p["norm"][1], 2)) if p else "-"))
    for mode, row in tables["table1"].get("se3_mean", {}).items():
        parts.append("<tr><th>%s: SE(3) mean of each user's %s trials (one per user; not the paper's "
                     "N = 3)</th><td>%s</td><td>%s</td><td class=paper>-</td></tr>" % (
                         LABELS[mode], "all", fmt(row["norm"][0]), fmt(row["norm"][1])))
    parts.append("</table>")
    for frame, key in (("W (the OR frame, z up)", "table1"), ("the viewer's (z along the line of sight)",
                                                               "table1_viewer")):
        rows1 = tables.get(key)
        if not rows1 or key == "table1" and not tables.get("table1_viewer"):
            continue
        parts.append("<p>Per axis in %s [mm], mean +/- std:</p><table><tr><th></th><th>x</th><th>y</th>"
                     "<th>z</th><th class=paper>paper x, y, z</th></tr>" % frame)
        for mode in ("ar_reflective", "ar"):
            row, prow = rows1.get(mode), paper.get("table1", {}).get(mode)
            if row:
                parts.append("<tr><th>%s</th>%s<td class=paper>%s</td></tr>" % (LABELS[mode], "".join(
                    "<td>%s +/- %s</td>" % (fmt(row[a][0]), fmt(row[a][1])) for a in ("t_x", "t_y", "t_z")),
                    ", ".join(fmt(prow[a][0]) for a in ("t_x", "t_y", "t_z")) if prow else "-"))
        parts.append("</table>")
    return parts


def report(study_dir):
    tables = json.load(open(os.path.join(study_dir, "tables.json")))
    paper = tables.get("paper", {})
    parts = ["<!doctype html><meta charset=utf-8><title>orbed study</title>",
             "<style>body{font-family:sans-serif;max-width:1100px;margin:auto}"
             "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #bbb;padding:3px 8px}"
             "td.paper{color:#666}img{max-width:100%}</style>",
             "<h1>orbed study</h1>",
             "<p>Every number here was measured on the emulated testbed over the bus "
             "(scripts/orbed study). Grey columns are the paper's (%s). "
             "Which model parameters were fitted and to what: docs/parameters.md. In the set-up "
             "half only the assistant's time per joint and its person-to-person pace were fitted "
             "(to Table 4's AR execution mean and spread); every joint error and the other modes' "
             "times are predictions.</p>"
             % html.escape(paper.get("setup_source", paper.get("source", "")))]
    parts.extend(table1_section(tables))
    parts.append(landmark_check(tables, study_dir))
    if "table2" in tables:
        head = ("<tr><th></th>" + "".join("<th>%s</th>" % k for k in ("mean", "median", "min", "max", "std"))
                + "".join("<th class=paper>paper %s</th>" % k for k in ("mean", "median", "min", "max", "std"))
                + "</tr>")
        parts.append("<h2>Table 2: joint errors over all joints [deg]</h2><table>" + head)
        for mode in MODES:
            if mode in tables["table2"]:
                parts.append(stats_row(LABELS[mode], tables["table2"][mode], paper.get("table2", {}).get(mode)))
        parts.append("</table>")
        parts.append("<h2>Table 3: p-values, %s (%s, two-sided)</h2><table><tr><th></th>%s"
                     "</tr>" % (html.escape(tables.get("table3_reading", "unpaired, every joint of every set-up pooled")),
                                html.escape(tables.get("table3_test", "")),
                                "".join("<th>%s</th>" % k for k in
                                        ["joint%d" % j for j in range(1, 8)] + ["total"])))
        for pair, row in tables.get("table3", {}).items():
            prow = paper.get("table3", {}).get(pair, {})
            keys = ["joint%d" % j for j in range(1, 8)] + ["total"]
            parts.append("<tr><th>%s</th>%s</tr>" % (html.escape(pair), "".join(
                "<td>%s<br><span style=color:#666>%s</span></td>" % (
                    "%.2g" % row[k] if row.get(k) is not None else "-",
                    "%.2g" % prow[k] if k in prow else "-") for k in keys)))
        parts.append("</table><p>Upper figure ours, lower the paper's (which lists joints 1-6).</p>")
        parts.append("<h2>Table 4: times [min:s]</h2><table>" + head.replace("<th></th>", "<th>execution</th>", 1))
        for mode in MODES:
            row = tables.get("table4", {}).get(mode)
            if row:
                parts.append(stats_row(LABELS[mode], row["execution_s"],
                                       paper.get("table4", {}).get(mode, {}).get("execution_s"), True))
        for mode in MODES:
            row = tables.get("table4", {}).get(mode)
            if row and "alignment_s" in row:
                parts.append(stats_row(LABELS[mode] + ": alignment (N = 3)", row["alignment_s"],
                                       paper.get("table4", {}).get(mode, {}).get("alignment_s"), True))
        parts.append("</table>")
        parts.append("<h2>Figures</h2>")
        for name, caption in (("joint_errors", "Per-joint error per guidance mode (the paper's Fig. 6); dashed: "
                                               "the paper's median over all joints of the mode"),
                              ("total_errors", "All joints' errors per mode (Fig. 7), the paper's mean and median "
                                               "beside each violin"),
                              ("joint_rank", "Mean error per joint, log scale; twisting joints red-edged (Fig. 8); "
                                             "dashed: the paper's mean over all joints per mode")):
            parts.append(figure_html("figures/" + name, caption))
    if tables.get("setup_analysis"):
        parts.extend(setup_analysis_section(tables["setup_analysis"]))
    parts.extend(bands_section(study_dir))
    parts.extend(sensitivity_section(study_dir))
    if tables.get("beyond"):
        parts.extend(beyond_section(study_dir, tables["beyond"]))
    trials_path = os.path.join(study_dir, "alignment_trials.csv")
    rows = read_csv(trials_path) if os.path.exists(trials_path) else []
    if rows:
        parts.append("<h2>Ground truth the paper could not measure</h2><table><tr><th></th>"
                     "<th>registration error at the robot's centroid [mm]</th><th>rotation error [deg]</th>"
                     "<th>landmark misalignment, the truth's landmarks [mm]</th></tr>")

        def mean_std(values, digits=1):
            if not values:
                return "-"
            return "%s +/- %s" % (fmt(statistics.mean(values), digits),
                                  fmt(statistics.stdev(values) if len(values) > 1 else 0.0, digits))
        for mode in ("ar_reflective", "ar"):
            t = [float(r["true_translation_mm"]) for r in rows if r["mode"] == mode]
            a = [float(r["true_rotation_deg"]) for r in rows if r["mode"] == mode]
            # Absent from studies written before the gaze annotation (their misalignment was the truth's).
            m = [float(r["true_misalignment_mm"]) for r in rows if r["mode"] == mode and r.get("true_misalignment_mm")]
            if t:
                parts.append("<tr><th>%s</th><td>%s</td><td>%s</td><td>%s</td></tr>" % (
                    LABELS[mode], mean_std(t), mean_std(a, 2), mean_std(m)))
        parts.append("</table>")
    parts.append(provenance_footer(study_dir))
    # The page checks itself once loaded: how many of its pictures decoded, as data-images-loaded on
    # <body> (what a headless browser's DOM dump shows; tests/report_test.sh reads it).
    parts.append("<script>addEventListener('load', () => { const i = [...document.images]; "
                 "document.body.dataset.imagesLoaded = i.filter(m => m.complete && m.naturalWidth > 0).length"
                 " + '/' + i.length; });</script>")
    with open(os.path.join(study_dir, "report.html"), "w") as f:
        f.write("\n".join(parts) + "\n")


def main():
    if len(sys.argv) != 2 or sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        return 0 if len(sys.argv) == 2 else 2
    study_dir = sys.argv[1]
    joints_path = os.path.join(study_dir, "setup_joints.csv")
    if not os.path.exists(os.path.join(study_dir, "tables.json")):
        print("report.py: %s has no tables.json (run orbed-study-tables first)" % study_dir, file=sys.stderr)
        return 1
    if os.path.exists(joints_path):
        with open(os.path.join(study_dir, "tables.json")) as f:
            paper_table2 = json.load(f).get("paper", {}).get("table2", {})
        figures(study_dir, read_csv(joints_path), paper_table2)
    report(study_dir)
    print("report: %s" % os.path.join(study_dir, "report.html"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
