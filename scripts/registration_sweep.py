#!/usr/bin/python3
"""The set-up study's joint and docking error as an injected registration error grows.

Each point runs orbed-setup-study (the set-up half in one process, equal to the bus run) for
STUDIES studies of USERS users (8 x 3 modes x 3 targets by default) with every registration the
assistant receives moved by an injected error (experiments/setup/setup_study.h): an offset of
0, 10, ..., 50 mm (no tilt), and separately a tilt of 0, 1, ..., 5 deg (no offset), each in a
direction drawn per set-up from the seed (`--registration-direction random`: uniform on the sphere;
the tilt about a uniform horizontal axis). By default on top of the true registration
(`--registration truth`: the injected error is the whole registration error); --measured adds it
to the alignments' mean instead. The same users (seeds) at every point, so points are paired.

Per point and mode: the mean |reached - target| over every joint of every set-up [deg] and the mean
docking error at the tool tip [mm] (DockingError, setup_conductor.h), with a 95 % interval of the
mean over the set-ups (t, set-up means as the unit). Writes into OUT: registration_sweep.csv
(kind, offset_mm, tilt_deg, mode, setups, joint_error_deg, joint_ci_deg, docking_tip_mm,
docking_ci_mm) and registration_sweep.pdf / .png (300 dpi): offset and tilt against joint and docking
error, one line per mode. The fixed monitor shows no hologram, so its line is the control: the
injection cannot move it.

  scripts/registration_sweep.py OUT [--studies M] [--users U] [--seed S] [--threads T] [--measured]

Needs python3-matplotlib and python3-scipy (Debian); run with /usr/bin/python3.
"""
import argparse
import csv
import os
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from scipy import stats  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODES = ["ar_reflective", "ar", "fixed"]
OFFSETS_MM = [0, 10, 20, 30, 40, 50]
TILTS_DEG = [0, 1, 2, 3, 4, 5]


def mean_ci(values):
    n = len(values)
    mean = sum(values) / n
    if n < 2:
        return mean, float("nan")
    sd = (sum((v - mean) ** 2 for v in values) / (n - 1)) ** 0.5
    return mean, stats.t.ppf(0.975, n - 1) * sd / n ** 0.5


def run_point(binary, args, offset_mm, tilt_deg):
    with tempfile.TemporaryDirectory() as out:
        argv = [binary, "--studies", str(args.studies), "--users", str(args.users), "--seed", str(args.seed),
                "--threads", str(args.threads), "--registration", "measured" if args.measured else "truth",
                "--registration-offset-mm", str(offset_mm), "--registration-tilt-deg", str(tilt_deg),
                "--registration-direction", "random", "--allow-failures", "--quiet", "--out", out]
        subprocess.run(argv, check=True, stdout=subprocess.DEVNULL, env=dict(os.environ, ORBED_SOURCE_DIR=ROOT))
        setups = {}  # (study, user, mode, target) -> [joint errors]
        with open(os.path.join(out, "setup_joints.csv")) as f:
            for row in csv.DictReader(f):
                key = (row.get("study", "1"), row["user"], row["mode"], row["target"])
                setups.setdefault(key, []).append(float(row["error_deg"]))
        docking = {}
        with open(os.path.join(out, "setup_docking.csv")) as f:
            for row in csv.DictReader(f):
                docking.setdefault(row["mode"], []).append(float(row["docking_tip_mm"]))
    result = {}
    for mode in MODES:
        per_setup = [sum(e) / len(e) for (s, u, m, t), e in setups.items() if m == mode]
        if not per_setup:
            continue
        joint, joint_ci = mean_ci(per_setup)
        tip, tip_ci = mean_ci(docking[mode])
        result[mode] = (len(per_setup), joint, joint_ci, tip, tip_ci)
    return result


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out", help="folder of registration_sweep.csv, .pdf and .png")
    p.add_argument("--studies", type=int, default=1, help="studies per point (default 1)")
    p.add_argument("--users", type=int, default=8, help="users per study (default 8)")
    p.add_argument("--seed", type=int, default=1, help="the first user's seed (default 1)")
    p.add_argument("--threads", type=int, default=2, help="orbed-setup-study --threads (default 2)")
    p.add_argument("--measured", action="store_true", help="add the error to the alignments' mean, not the truth")
    args = p.parse_args()
    if args.studies < 1 or args.users < 1 or args.threads < 1:
        p.error("--studies, --users and --threads must be >= 1")
    build = os.environ.get("ORBED_BUILD_DIR", os.path.join(ROOT, "build"))
    if subprocess.run(["cmake", "--build", build, "-j2", "--target", "orbed-setup-study"],
                      stdout=subprocess.DEVNULL).returncode:
        sys.exit("registration_sweep: the build of orbed-setup-study failed")
    binary = os.path.join(build, "bin", "orbed-setup-study")
    os.makedirs(args.out, exist_ok=True)
    points = [("offset", mm, 0) for mm in OFFSETS_MM] + [("tilt", 0, deg) for deg in TILTS_DEG]
    rows = []
    for i, (kind, mm, deg) in enumerate(points):
        print(f"registration_sweep: point {i + 1}/{len(points)}: {kind} {mm} mm, {deg} deg", file=sys.stderr)
        for mode, (n, joint, joint_ci, tip, tip_ci) in run_point(binary, args, mm, deg).items():
            rows.append(dict(kind=kind, offset_mm=mm, tilt_deg=deg, mode=mode, setups=n, joint_error_deg=joint,
                             joint_ci_deg=joint_ci, docking_tip_mm=tip, docking_ci_mm=tip_ci))
    with open(os.path.join(args.out, "registration_sweep.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)

    fig, axes = plt.subplots(2, 2, figsize=(9, 7))
    base = "true registration" if not args.measured else "measured registration"
    for col, (kind, x_key, x_label) in enumerate([("offset", "offset_mm", "injected offset [mm]"),
                                                  ("tilt", "tilt_deg", "injected tilt [deg]")]):
        for row_i, (y_key, ci_key, y_label) in enumerate([("joint_error_deg", "joint_ci_deg", "mean joint error [deg]"),
                                                          ("docking_tip_mm", "docking_ci_mm",
                                                           "mean docking error at the tip [mm]")]):
            ax = axes[row_i][col]
            for mode, marker in zip(MODES, "osd"):
                pts = [r for r in rows if r["kind"] == kind and r["mode"] == mode]
                if not pts:
                    continue
                ax.errorbar([r[x_key] for r in pts], [r[y_key] for r in pts], yerr=[r[ci_key] for r in pts],
                            marker=marker, capsize=3, label=mode)
            ax.set_xlabel(x_label)
            ax.set_ylabel(y_label)
            ax.set_ylim(bottom=0)
            ax.grid(alpha=0.3)
    handles, labels = axes[0][0].get_legend_handles_labels()
    # Below the panels, clear of every curve.
    fig.legend(handles, labels, loc="lower center", ncol=3, title="guidance mode (bars: 95 % CI of the mean)")
    fig.suptitle(f"Injected registration error on the {base}: {args.studies} x {args.users} users, "
                 f"seeds from {args.seed}", fontsize=10)
    fig.tight_layout(rect=(0, 0.1, 1, 0.96))
    for ext, kw in (("pdf", {}), ("png", {"dpi": 300})):
        fig.savefig(os.path.join(args.out, f"registration_sweep.{ext}"), **kw)
    print(f"registration_sweep: {os.path.join(args.out, 'registration_sweep.csv')}, .pdf, .png")


if __name__ == "__main__":
    main()
