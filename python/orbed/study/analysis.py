"""The whole analysis of a study folder into its tables.json, and the terminal summary.

orbed-study-tables writes the CSVs and a tables.json holding what only it knows ("provenance",
the paper's figures under "paper"); analyze() computes the rest from the CSVs and write() merges
them into tables.json (computed keys replace any earlier ones; "provenance" first, "paper" last):

  users, table1 (+ se3_mean, se3_n3), table1_viewer     alignment_*.csv (tables.py)
  landmark_validation_mm                                 mean of landmark_validation.csv's error_mm
  setup_users, table2, table3, table3_test, table4       setup_*.csv (tables.py; Table 3 the paper's reading)
  table3_reading                                         what Table 3 is
  beyond (docking, collisions, registration_share, power, power_method)   beyond.py, power.py
  setup_analysis                                         setup_stats.py (the reviewer's analysis)
"""
import json
import os

from . import beyond, files, power, setup_stats, tables

TABLE3_READING = "the paper's reading: unpaired, every joint of every set-up pooled"


def analyze(study_dir, resamples=power.RESAMPLES, seed=1):
    out = {}
    trials = files.read(study_dir, "alignment_trials.csv")
    if trials is not None and len(trials):
        out["users"] = int(trials["user"].nunique())
        out["table1"] = tables.table1(trials, files.read(study_dir, "alignment_means.csv"),
                                      files.read(study_dir, "alignment_groups.csv"))
        viewer = tables.table1_viewer(trials)
        if viewer is not None:
            out["table1_viewer"] = viewer
    validation = files.read(study_dir, "landmark_validation.csv")
    if validation is not None and len(validation):
        out["landmark_validation_mm"] = float(validation["error_mm"].astype(float).mean())
    joints = files.setup_joints(study_dir)
    if joints is not None and len(joints):
        out["setup_users"] = int(joints["user"].nunique())
        out["table2"] = tables.table2(joints)
        out["table3"] = tables.table3(joints)
        out["table3_test"] = "mann_whitney_u"
        out["table3_reading"] = TABLE3_READING
        times = files.setup_times(study_dir)
        if times is not None:
            out["table4"] = tables.table4(times)
        b = beyond.beyond(files.read(study_dir, "setup_docking.csv"), joints,
                          files.setup_joints(study_dir, "setup_truth_joints.csv"))
        b["power_method"] = power.METHOD % (resamples, power.ALPHA)
        b["power"] = power.power(joints, resamples=resamples, seed=seed)
        out["beyond"] = b
        out["setup_analysis"] = setup_stats.setup_analysis(joints, seed)
    return out


def write(study_dir, resamples=power.RESAMPLES, seed=1):
    """Merges analyze() into STUDY_DIR/tables.json; returns the merged tables."""
    path = os.path.join(study_dir, "tables.json")
    earlier = {}
    if os.path.exists(path):
        with open(path) as f:
            earlier = json.load(f)
    computed = analyze(study_dir, resamples, seed)
    merged = {}
    if "provenance" in earlier:
        merged["provenance"] = earlier["provenance"]
    merged.update(computed)
    for key, value in earlier.items():
        if key not in merged and key != "paper":
            merged[key] = value
    if "paper" in earlier:
        merged["paper"] = earlier["paper"]
    with open(path + ".tmp", "w") as f:
        json.dump(merged, f, indent=2, allow_nan=False)
        f.write("\n")
    os.replace(path + ".tmp", path)
    return merged


def fixed(value, digits=1):
    return "-" if value is None else ("%." + str(digits) + "f") % value


def pvalue(p):
    return "-" if p is None else "%.2g" % p


def clock(seconds):
    total = int(round(seconds))
    return "%d:%02d" % (total // 60, total % 60)


def stats_text(s, f):
    return " / ".join(f(s[k]) for k in ("mean", "median", "min", "max", "std"))


def summary(t):
    """Tables 1-4 beside the paper's, and the reviewer's analysis, for the terminal."""
    paper = t.get("paper", {})
    lines = []
    if "table1" in t:
        lines.append("ViRAAl study: %d users" % t["users"])
        for mode in ("ar_reflective", "ar"):
            row = t["table1"].get(mode)
            if not row:
                continue
            prow = paper.get("table1", {}).get(mode)
            lines.append("  %s" % mode)
            lines.append("    Table 1, all trials:     %s +/- %s mm  (x, y, z means %s; %d)%s" % (
                fixed(row["norm"][0]), fixed(row["norm"][1]), ", ".join(fixed(row[k][0]) for k in ("t_x", "t_y", "t_z")),
                row["num_trials"], "   paper %s +/- %s mm" % (prow["norm"][0], prow["norm"][1]) if prow else ""))
            viewer = t.get("table1_viewer", {}).get(mode)
            if viewer:
                lines.append("    viewer frame (z = line of sight): x, y, z means %s" %
                             ", ".join(fixed(viewer[k][0]) for k in ("t_x", "t_y", "t_z")))
            n3 = t["table1"].get("se3_n3", {}).get(mode)
            if n3:
                lines.append("    SE(3) means of N = 3:    %s +/- %s mm (%d groups)%s" % (
                    fixed(n3["norm"][0]), fixed(n3["norm"][1]), n3["groups"],
                    "   paper 11.3 +/- 1.01 mm" if mode == "ar_reflective" else ""))
            se3 = t["table1"].get("se3_mean", {}).get(mode)
            if se3:
                lines.append("    SE(3) mean per user (all trials): %s +/- %s mm (%d users)" % (
                    fixed(se3["norm"][0]), fixed(se3["norm"][1]), se3["num_trials"]))
    if "landmark_validation_mm" in t:
        lines.append("  landmark measurement error (optical table): %s mm   paper %s mm" % (
            fixed(t["landmark_validation_mm"]), paper.get("landmark_validation_mm", "-")))
    if "table2" in t:
        lines.append("Robot set-up study: %d users" % t["setup_users"])
        lines.append("  Table 2, joint error [deg]   mean / median / min / max / std")
        for mode, s in t["table2"].items():
            p = paper.get("table2", {}).get(mode)
            lines.append("    %-14s %s%s" % (mode, stats_text(s, fixed), "   paper " + stats_text(p, lambda v: fixed(v, 2)) if p else ""))
        lines.append("  Table 4, execution time [min:s]")
        for mode, s in t.get("table4", {}).items():
            p = paper.get("table4", {}).get(mode, {}).get("execution_s")
            lines.append("    %-14s %s%s" % (mode, stats_text(s["execution_s"], clock),
                                             "   paper " + stats_text(p, clock) if p else ""))
        b = t.get("beyond", {})
        if b.get("collisions"):
            lines.append("  Beyond the paper: docking error at the trocar (tip [mm] / tool axis [deg], median), contacts, "
                         "collision stops, near misses (< %s cm)" % fixed(100 * b["near_miss_m"], 0))
            for mode, c in b["collisions"].items():
                d = b.get("docking", {}).get(mode)
                lines.append("    %-14s %s, %d contact(s), %d stop(s), %d near miss(es)" % (
                    mode, "%s mm / %s deg" % (fixed(d["tip_mm"]["median"], 0), fixed(d["axis_deg"]["median"]))
                    if d else "(not recorded)", c["contact"], c["collision_stops"], c["near_miss"]))
        lines.append("  Total test between modes: p of %s | of the set-up as the unit (paired Wilcoxon, "
                     "n set-ups, rank-biserial r)" % TABLE3_READING)
        for pair, a in t["setup_analysis"]["pairs"].items():
            s = a["by_setup"]
            lines.append("    %-20s %s | %s (n %d, r %s)" % (pair, pvalue(a["pooled_mwu"]["p"]), pvalue(s["p"]), s["n"],
                                                           fixed(s["rank_biserial"], 2)))
        h = t["setup_analysis"]["half_turns"]["by_mode"]
        lines.append("  Half-turns (joint error > 90 deg): " + ", ".join(
            "%s %d of %d joints (%d of %d set-ups)" % (m, c["half_turns"], c["joints"], c["setups_with_half_turn"],
                                                      c["setups"]) for m, c in h.items()))
        for mode, share in t["beyond"].get("registration_share", {}).items():
            lines.append("  Registration's share, %s: mean joint error %s deg measured, %s deg with the true "
                         "registration (%s %%)" % (mode, fixed(share["measured_deg"]["mean"]),
                                                   fixed(share["truth_deg"]["mean"]), fixed(100 * share["share"], 0)))
        curve = t["beyond"]["power"].get("ar_reflective/ar")
        if curve:
            lines.append("  Power of ar_reflective vs ar (alpha 0.05), users: paired set-up test / pooled test")
            lines.append("    " + "  ".join("%d: %.2f/%.2f" % (n, q, p) for n, q, p in
                                            zip(curve["users"], curve["power_paired"], curve["power"])))
    return "\n".join(lines) + "\n"
