#!/usr/bin/python3
"""orbed study report: report.html and figures/*.png from a study folder (scripts/orbed study).

Usage: /usr/bin/python3 scripts/report.py STUDY_DIR

Reads STUDY_DIR/tables.json, setup_joints.csv, setup_times.csv and, when present,
alignment_trials.csv (orbed-study-tables writes them) and writes:
  figures/joint_errors.png   per-joint error distributions per guidance mode (violins; the paper's
                             Fig. 6)
  figures/total_errors.png   every joint's error per mode (violins; the paper's Fig. 7)
  figures/joint_rank.png     the mean error per joint and mode on a log scale, twisting joints (odd)
                             and revolving joints (even) told apart (the paper's Fig. 8)
  report.html                Tables 1-4 beside the paper's, the figures, the ground-truth columns
                             the paper could not measure, and what was calibrated to which figure.
Needs python3-matplotlib (Debian); nothing else outside the standard library.
"""
import csv
import html
import json
import os
import statistics
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

MODES = ("ar_reflective", "ar", "fixed")
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


def figures(study_dir, joints_rows):
    os.makedirs(os.path.join(study_dir, "figures"), exist_ok=True)
    modes = [m for m in MODES if any(r["mode"] == m for r in joints_rows)]
    num_joints = max(int(r["joint"]) for r in joints_rows)

    def errors(mode, joint=None):
        return [float(r["error_deg"]) for r in joints_rows
                if r["mode"] == mode and (joint is None or int(r["joint"]) == joint)]

    fig, axes = plt.subplots(1, len(modes), figsize=(5 * len(modes), 4), sharey=True)
    axes = axes if len(modes) > 1 else [axes]
    for ax, mode in zip(axes, modes):
        violins(ax, [errors(mode, j) for j in range(1, num_joints + 1)], list(range(1, num_joints + 1)),
                COLORS[mode])
        ax.set_title(LABELS[mode])
        ax.set_xlabel("joint")
        ax.set_xticks(list(range(1, num_joints + 1)))
    axes[0].set_ylabel("|reached - target| [deg]")
    fig.tight_layout()
    fig.savefig(os.path.join(study_dir, "figures", "joint_errors.png"), dpi=100)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6, 4))
    for i, mode in enumerate(modes):
        violins(ax, [errors(mode)], [i + 1], COLORS[mode])
    ax.set_xticks(list(range(1, len(modes) + 1)))
    ax.set_xticklabels([LABELS[m] for m in modes])
    ax.set_ylabel("joint error, all joints [deg]")
    fig.tight_layout()
    fig.savefig(os.path.join(study_dir, "figures", "total_errors.png"), dpi=100)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(7, 4))
    width = 0.8 / len(modes)
    for i, mode in enumerate(modes):
        for j in range(1, num_joints + 1):
            values = errors(mode, j)
            mean = statistics.mean(values) if values else 0.0
            twisting = any(r["twisting"] == "1" for r in joints_rows if int(r["joint"]) == j)
            ax.bar(j - 0.4 + (i + 0.5) * width, max(mean, 1e-3), width, color=COLORS[mode],
                   edgecolor="red" if twisting else "blue", linewidth=1.5,
                   label=LABELS[mode] if j == 1 else None)
    ax.set_yscale("log")
    ax.set_xticks(list(range(1, num_joints + 1)))
    ax.set_xlabel("joint (red edge: twisting, blue edge: revolving)")
    ax.set_ylabel("mean error [deg], log scale")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(study_dir, "figures", "joint_rank.png"), dpi=100)
    plt.close(fig)


def power_figure(study_dir, beyond):
    """The power analysis's curves (tables.json beyond.power): one line per pair of modes."""
    curves = beyond.get("power", {})
    if not curves:
        return False
    fig, ax = plt.subplots(figsize=(6, 4))
    for pair, curve in curves.items():
        ax.plot(curve["users"], curve["power"], marker="o", label=pair)
    ax.axhline(0.8, color="grey", linestyle="--", linewidth=1)
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlabel("users in the study")
    ax.set_ylabel("power of the total test (alpha 0.05)")
    ax.legend()
    fig.tight_layout()
    os.makedirs(os.path.join(study_dir, "figures"), exist_ok=True)
    fig.savefig(os.path.join(study_dir, "figures", "power.png"), dpi=100)
    plt.close(fig)
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
        parts.append("<p>Power analysis (%s). Users needed for 80 %% power: %s.</p>" % (
            html.escape(beyond.get("power_method", "")),
            ", ".join("%s %s" % (html.escape(pair), curve["users_for_80"] if curve["users_for_80"] is not None
                                 else "more than %d" % curve["users"][-1])
                      for pair, curve in power.items())))
        if power_figure(study_dir, beyond):
            parts.append("<figure><img src='figures/power.png'><figcaption>Power of Table 3's total test "
                         "against the number of users, from the emulated people</figcaption></figure>")
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
    """Where the numbers came from: the study folder's provenance record (scripts/provenance.py)."""
    path = os.path.join(study_dir, "provenance.json")
    if not os.path.exists(path):
        return "<footer><p>No provenance.json in this folder: made without scripts/orbed.</p></footer>"
    with open(path) as f:
        p = json.load(f)
    git = p.get("git", {})
    commit = (git.get("commit") or "unknown commit") + (" (uncommitted changes)" if git.get("dirty") else "")
    settings = ", ".join("%s=%s" % (k, v) for k, v in sorted(p.get("settings", {}).items()))
    return ("<footer><hr><p>Made by orbed %s at commit %s, run %s on %s, started %s: <code>%s</code>. "
            "Settings: %s. Every input and output with its SHA-256: provenance.json (and each user's "
            "run folder's); check them with <code>scripts/orbed verify</code>.</p></footer>" % (
                html.escape(str(p.get("orbed_version"))), html.escape(commit), html.escape(p.get("run", "")),
                html.escape(p.get("host", "")), html.escape(p.get("started_utc", "")),
                html.escape(" ".join(p.get("command_line", []))), html.escape(settings)))


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
    if tables.get("table1"):
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
        parts.append("</table>")
    if "table2" in tables:
        head = ("<tr><th></th>" + "".join("<th>%s</th>" % k for k in ("mean", "median", "min", "max", "std"))
                + "".join("<th class=paper>paper %s</th>" % k for k in ("mean", "median", "min", "max", "std"))
                + "</tr>")
        parts.append("<h2>Table 2: joint errors over all joints [deg]</h2><table>" + head)
        for mode in MODES:
            if mode in tables["table2"]:
                parts.append(stats_row(LABELS[mode], tables["table2"][mode], paper.get("table2", {}).get(mode)))
        parts.append("</table>")
        parts.append("<h2>Table 3: p-values (%s, two-sided, unpaired)</h2><table><tr><th></th>%s"
                     "</tr>" % (html.escape(tables.get("table3_test", "")),
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
        for name, caption in (("joint_errors.png", "Per-joint error per guidance mode (the paper's Fig. 6)"),
                              ("total_errors.png", "All joints' errors per mode (Fig. 7)"),
                              ("joint_rank.png", "Mean error per joint, log scale; twisting joints "
                                                 "red-edged (Fig. 8)")):
            parts.append("<figure><img src='figures/%s'><figcaption>%s</figcaption></figure>" % (name, caption))
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
        figures(study_dir, read_csv(joints_path))
    report(study_dir)
    print("report: %s" % os.path.join(study_dir, "report.html"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
