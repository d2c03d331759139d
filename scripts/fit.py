#!/usr/bin/python3
"""orbed fit: the one calibration of the ViRAAl user, made again.

Only the AR-only row of the paper's Table 1 (30.2 +/- 23.9 mm) is fitted, with the two parameters of
the depth judgement that set its size and its person-to-person spread:
user.direct_view.depth_bias_fraction_std and user.direct_view.user_scale_log_sigma. Each grid point
runs orbed-user-study in AR-only mode for USERS emulated persons (user.seed 1..USERS) x TRIALS trials
and takes Table 1's statistic over all their trials (scripts/sweep.py's run_point): the model's
expectation over persons, not the draw of the paper's four. The best point is the one nearest the
paper in relative terms, (mean / 30.2 - 1)^2 + (std / 23.9 - 1)^2. Everything else keeps the shipped
values, so a change to any of them calls for this fit again. Writes fit.csv into OUT and prints the
grid; run by `scripts/orbed fit`.
"""
import argparse
import csv
import math
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sweep import run_point  # noqa: E402

PAPER_AR_ONLY_MM = (30.2, 23.9)  # Table 1, ViRAAl without the display (mean, std)


def floats(text):
    try:
        values = [float(x) for x in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got '{text}'")
    if not values or any(not math.isfinite(v) or v < 0 for v in values):
        raise argparse.ArgumentTypeError(f"expected finite non-negative numbers, got '{text}'")
    return values


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--study", required=True, help="orbed-user-study")
    parser.add_argument("--source", required=True, help="the repository (for the shipped files)")
    parser.add_argument("--out", required=True, help="folder for fit.csv")
    parser.add_argument("--users", type=int, default=48, help="emulated persons per point (default 48)")
    parser.add_argument("--trials", type=int, default=50, help="trials per person (default 50)")
    parser.add_argument("--depth-bias", type=floats, default=floats("0.012,0.013,0.014,0.015"),
                        help="values of depth_bias_fraction_std (default 0.012,0.013,0.014,0.015)")
    parser.add_argument("--log-sigma", type=floats, default=floats("0.4,0.45,0.5"),
                        help="values of user_scale_log_sigma (default 0.4,0.45,0.5)")
    args = parser.parse_args()
    if args.trials < 2 or args.users < 1:
        sys.exit("fit: --trials must be >= 2 and --users >= 1")
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.source, "experiments", "viraal", "viraal.yaml")) as f:
        scenario = f.read()
    if "modes: [ar_reflective, ar]" not in scenario:
        sys.exit("fit: experiments/viraal/viraal.yaml no longer says 'modes: [ar_reflective, ar]'")
    ar_only = scenario.replace("modes: [ar_reflective, ar]", "modes: [ar]")

    rows = []
    total = len(args.depth_bias) * len(args.log_sigma)
    with tempfile.TemporaryDirectory() as tmp:
        for bias in args.depth_bias:
            for sigma in args.log_sigma:
                user_text = (f"  direct_view: {{depth_bias_fraction_std: {bias}, "
                             f"user_scale_log_sigma: {sigma}}}\n")
                mean, std, n = run_point(args.study, tmp, args.trials, args.users, "", ar_only, user_text)["ar"]
                cost = (mean / PAPER_AR_ONLY_MM[0] - 1) ** 2 + (std / PAPER_AR_ONLY_MM[1] - 1) ** 2
                rows.append((bias, sigma, mean, std, n, cost))
                print(f"[{len(rows)}/{total}] depth_bias_fraction_std {bias:<6} user_scale_log_sigma {sigma:<5}"
                      f" AR only {mean:5.1f} +/- {std:4.1f} mm  ({n} trials)", flush=True)
    best = min(rows, key=lambda r: r[5])
    path = os.path.join(args.out, "fit.csv")
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["depth_bias_fraction_std", "user_scale_log_sigma", "table1_mean_mm", "table1_std_mm",
                    "trials", "cost"])
        for r in rows:
            w.writerow([r[0], r[1], f"{r[2]:.2f}", f"{r[3]:.2f}", r[4], f"{r[5]:.5f}"])
    print(f"best: depth_bias_fraction_std {best[0]}, user_scale_log_sigma {best[1]}: "
          f"{best[2]:.1f} +/- {best[3]:.1f} mm (paper {PAPER_AR_ONLY_MM[0]} +/- {PAPER_AR_ONLY_MM[1]} mm)")
    print(f"fit: {path}")


if __name__ == "__main__":
    main()
