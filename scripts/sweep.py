#!/usr/bin/python3
"""orbed sweep: the ViRAAl alignment error as one model input varies.

Each point runs orbed-user-study (the live run's protocol without the bus) for USERS emulated
persons (user.seed 1..USERS) with TRIALS trials per display mode, and reports the paper's Table 1
statistic over all their trials (results.json's table1, pooled: per axis of W the mean and sample
std of the trials' mean absolute landmark errors, then the norms of the two vectors). Sweeps:

  drift          slam.drift.fraction_of_distance (per metre walked), the same in every session
                 (session_log_sigma 0); the shipped walk and display.
  capture_angle  the angle, about the robot's middle (the walk's look-at point), between where the
                 display's frame is captured and where the person aligns (head_end); the walk starts
                 at the capture point and goes straight to head_end, so the path, and the drift the
                 alignment sees, grows with the angle (path_m says how much; the session's map begins
                 at hmd.session_start_m, which the person walks from to the capture point first).
  displays       1, 2, 3 displays (reflective_mirrors) captured at 104.5 deg (foot_end, shipped),
                 60 deg and 150 deg; the walk visits them from the farthest to head_end.
  collaborator   the display is a collaborator's headset standing at foot_end (hmd.collaborator,
                 viraal_trial.h: its live frame, in the wearer's map of the moment, through a shared
                 anchor) instead of the frame captured there on the walk; the anchor's translation
                 error 0, 5, 10, 20, 40 mm per axis (value -1: the shipped captured display).

Writes sweep.csv and one PNG per sweep into OUT and prints the table. Model inputs not swept keep
the shipped values (docs/parameters.md). Run by `scripts/orbed sweep`; needs python3-matplotlib.
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

LOOK_AT = (0.25, -0.45, 1.25)       # head_trajectory.look_at_m of viraal_walk.yaml
HEAD_END = (-0.75, -1.40, 1.70)     # the alignment waypoint of viraal_walk.yaml
FOOT_END = (1.45, -1.20, 1.70)      # the shipped display's capture waypoint
SPEED = 0.8                         # head_trajectory.speed_m_per_s of viraal_walk.yaml
MODES = ("ar_reflective", "ar")


def on_circle(angle_deg):
    """The point at head_end's distance and height from the look-at point, turned by angle_deg
    (counter-clockwise seen from above, towards foot_end) from head_end."""
    dx, dy = HEAD_END[0] - LOOK_AT[0], HEAD_END[1] - LOOK_AT[1]
    a = math.radians(angle_deg)
    return (round(LOOK_AT[0] + dx * math.cos(a) - dy * math.sin(a), 4),
            round(LOOK_AT[1] + dx * math.sin(a) + dy * math.cos(a), 4), HEAD_END[2])


def angle_from_head_end(p):
    a = math.atan2(p[1] - LOOK_AT[1], p[0] - LOOK_AT[0]) - math.atan2(HEAD_END[1] - LOOK_AT[1], HEAD_END[0] - LOOK_AT[0])
    return math.degrees(math.atan2(math.sin(a), math.cos(a)))


def walk_yaml(captures):
    """A head_trajectory + hmd overlay: the walk from the first capture point through the others to
    head_end, one display per capture point, in the order given."""
    lines = ["head_trajectory:", f"  speed_m_per_s: {SPEED}", f"  look_at_m: [{LOOK_AT[0]}, {LOOK_AT[1]}, {LOOK_AT[2]}]",
             "  waypoints:"]
    names = []
    for i, p in enumerate(captures):
        names.append(f"capture_{i}")
        lines.append(f"    - {{name: capture_{i}, position_m: [{p[0]}, {p[1]}, {p[2]}], dwell_s: 2.0}}")
    lines.append(f"    - {{name: head_end, position_m: [{HEAD_END[0]}, {HEAD_END[1]}, {HEAD_END[2]}], dwell_s: 60.0}}")
    lines += ["hmd:", "  align_waypoint: head_end", "  displays:"]
    lines += [f"    - {{capture_waypoint: {n}}}" for n in names]
    path = sum(math.dist(a, b) for a, b in zip(captures + [HEAD_END], captures[1:] + [HEAD_END]))
    return "\n".join(lines) + "\n", path


# The run's own settings (--base-config), given to orbed-user-study before each point's overlay.
BASE_CONFIGS = []


def run_point(study, tmp, trials, users, overlay_text, scenario_text, user_text=""):
    """Table 1 per mode over USERS persons for one model setting.

    overlay_text: headset config (no `user:` mapping); user_text: more keys of each person's `user:`
    mapping, each line indented by two spaces. Returns {mode: (mean, std, n)} for the modes run."""
    axes = {m: [] for m in MODES}
    truth = {m: [] for m in MODES}
    for user in range(1, users + 1):
        overlay = os.path.join(tmp, "overlay.yaml")
        with open(overlay, "w") as f:
            f.write(overlay_text + f"user:\n  seed: {user}\n" + user_text)
        scenario = os.path.join(tmp, "scenario.yaml")
        with open(scenario, "w") as f:
            f.write(scenario_text)
        out = os.path.join(tmp, "results.json")
        cmd = [study, "--trials", str(trials), "--run-id", f"sweep-u{user}",
               *[a for c in BASE_CONFIGS for a in ("--config", c)], "--config", overlay,
               "--scenario", scenario, "--json", out, "--quiet"]
        done = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        if done.returncode != 0:
            sys.exit(f"sweep: {' '.join(cmd)} failed: {done.stderr.strip()}")
        with open(out) as f:
            results = json.load(f)
        for s in results["sessions"]:
            axes[s["mode"]] += [t["misalignment_axes_mm"] for t in s["trials"]]
            truth[s["mode"]] += [t["truth_misalignment_mm"] for t in s["trials"]]
    row = {}
    for mode, values in axes.items():
        n = len(values)
        if n == 0:
            continue
        means = [sum(v[k] for v in values) / n for k in range(3)]
        stds = [math.sqrt(sum((v[k] - means[k]) ** 2 for v in values) / (n - 1)) if n > 1 else 0.0 for k in range(3)]
        row[mode] = (math.hypot(*means), math.hypot(*stds), n, sum(truth[mode]) / n)
    return row


def plot_collaborator(rows, xlabel, args, path):
    """The collaborator sweep: the Table 1 statistic and the truth's misalignment with the
    collaborator's display against the anchor's error, the captured display and AR only as lines."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.0), dpi=100)
    swept = [r for r in rows if r["mode"] == "ar_reflective" and r["value"] >= 0]
    captured = [r for r in rows if r["mode"] == "ar_reflective" and r["value"] < 0][0]
    ar_only = [r for r in rows if r["mode"] == "ar" and r["value"] < 0][0]
    for ax, key, title in ((ax1, "table1_mean_mm", "Table 1 statistic (measured in the headset)"),
                           (ax2, "truth_misalignment_mean_mm", "misalignment from the truth's landmarks")):
        ax.plot([r["value"] for r in swept], [r[key] for r in swept], "o-", color="tab:green",
                label="collaborator's live display")
        ax.axhline(captured[key], color="tab:blue", linestyle="--", label="display captured on the walk (shipped)")
        ax.axhline(ar_only[key], color="tab:orange", linestyle="--", label="AR only")
        ax.set_xlabel(xlabel)
        ax.set_ylabel("[mm]")
        ax.set_ylim(bottom=0)
        ax.set_title(title, fontsize=9)
        ax.legend(fontsize=8)
    fig.suptitle(f"{args.users} persons x {args.trials} trials per mode; collaborator at foot_end", fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--study", required=True, help="orbed-user-study")
    parser.add_argument("--source", required=True, help="the repository (for the shipped files)")
    parser.add_argument("--out", required=True, help="folder for sweep.csv and the PNGs")
    parser.add_argument("--trials", type=int, default=50, help="trials per person and mode (default 50)")
    parser.add_argument("--users", type=int, default=4, help="emulated persons per point (default 4)")
    parser.add_argument("--only", choices=["drift", "capture_angle", "displays", "collaborator"],
                        help="one sweep only")
    parser.add_argument("--base-config", action="append", default=[],
                        help="a headset configuration overlay under every point (the run's settings)")
    args = parser.parse_args()
    BASE_CONFIGS.extend(args.base_config)
    if args.trials < 2 or args.users < 1:
        sys.exit("sweep: --trials must be >= 2 and --users >= 1")
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.source, "experiments", "viraal", "viraal.yaml")) as f:
        scenario = f.read()

    def with_mirrors(n):
        return scenario.replace("reflective_mirrors: 1", f"reflective_mirrors: {n}")

    shipped_walk, shipped_path = walk_yaml([FOOT_END])
    sweeps = {
        "drift": [(f, f"slam:\n  drift:\n    fraction_of_distance: {f}\n    session_log_sigma: 0\n", scenario, shipped_path)
                  for f in (0.0, 0.003, 0.006, 0.01, 0.014, 0.02)],
        "capture_angle": [],
        "displays": [],
        "collaborator": [(-1, shipped_walk, scenario, shipped_path)] + [
            (t, shipped_walk + f"  collaborator: {{waypoint: capture_0, colocalization_translation_mm: {t}}}\n",
             scenario, shipped_path) for t in (0, 5, 10, 20, 40)],
    }
    for angle in (0, 15, 30, 60, 90, 120, 150, 170):
        text, path = walk_yaml([on_circle(angle)])
        sweeps["capture_angle"].append((angle, text, scenario, path))
    foot_angle = angle_from_head_end(FOOT_END)
    for n, captures in ((1, [FOOT_END]), (2, [FOOT_END, on_circle(60)]), (3, [on_circle(150), FOOT_END, on_circle(60)])):
        text, path = walk_yaml(captures)
        sweeps["displays"].append((n, text, with_mirrors(n), path))

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, points in sweeps.items():
            if args.only and name != args.only:
                continue
            for value, overlay, scenario_text, path in points:
                result = run_point(args.study, tmp, args.trials, args.users, overlay, scenario_text)
                for mode in MODES:
                    mean, std, n, true_mean = result[mode]
                    rows.append({"sweep": name, "value": value, "mode": mode, "trials": n,
                                 "table1_mean_mm": round(mean, 3), "table1_std_mm": round(std, 3),
                                 "truth_misalignment_mean_mm": round(true_mean, 3), "path_m": round(path, 3)})
                print(f"{name:14s} {value:>6}  with display {result['ar_reflective'][0]:5.1f} +/- "
                      f"{result['ar_reflective'][1]:4.1f} mm (truth {result['ar_reflective'][3]:5.1f})   "
                      f"AR only {result['ar'][0]:5.1f} +/- {result['ar'][1]:4.1f} mm (truth {result['ar'][3]:5.1f})"
                      f"   (walk {path:.2f} m)", flush=True)
    with open(os.path.join(args.out, "sweep.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        writer.writeheader()
        writer.writerows(rows)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    labels = {"drift": "SLAM drift [fraction of the distance walked]",
              "capture_angle": "angle between capture and alignment viewpoints [deg]",
              "displays": "number of reflective displays",
              "collaborator": "collaborator's shared-anchor error [mm per axis]"}
    for name in labels:
        mine = [r for r in rows if r["sweep"] == name]
        if not mine:
            continue
        if name == "collaborator":
            plot_collaborator(mine, labels[name], args, os.path.join(args.out, f"{name}.png"))
            continue
        fig, ax = plt.subplots(figsize=(6.4, 4.0), dpi=100)
        span = max(r["value"] for r in mine) - min(r["value"] for r in mine)
        for mode, colour, paper, shift in (("ar_reflective", "tab:blue", 16.5, -0.006), ("ar", "tab:orange", 30.2, 0.006)):
            pts = [r for r in mine if r["mode"] == mode]
            ax.errorbar([r["value"] + shift * span for r in pts], [r["table1_mean_mm"] for r in pts],
                        yerr=[r["table1_std_mm"] for r in pts], color=colour, marker="o", capsize=3,
                        label=("with the display" if mode == "ar_reflective" else "AR only"))
            ax.axhline(paper, color=colour, linestyle=":", linewidth=1)
        if name == "capture_angle":
            ax.axvline(foot_angle, color="grey", linestyle="--", linewidth=1)
            ax.text(foot_angle, ax.get_ylim()[1] * 0.95, " shipped", color="grey", fontsize=8, va="top")
        if name == "displays":
            ax.set_xticks(sorted({r["value"] for r in mine}))
        ax.set_xlabel(labels[name])
        ax.set_ylabel("misalignment, Table 1 statistic [mm]")
        ax.set_title(f"{args.users} persons x {args.trials} trials per mode; bars: norm of the per-axis stds; "
                     "dotted: paper", fontsize=8)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(args.out, f"{name}.png"))
        plt.close(fig)
    print(f"sweep: {os.path.join(args.out, 'sweep.csv')} and the PNGs beside it")


if __name__ == "__main__":
    main()
