#!/usr/bin/python3
"""A study's robot set-up joint errors from its folder: the mean |error| per joint for each display
mode, printed and plotted (setup_joints.csv, written by orbed-study-tables).

    PYTHONPATH=python examples/plot_joint_errors.py logs/study-<time>-<id> [--out joint_errors.png]
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python"))
import matplotlib  # noqa: E402

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt  # noqa: E402

from orbed import runs  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study", help="a study's run folder (scripts/orbed study)")
    parser.add_argument("--out", default="joint_errors.png", help="the figure (PNG)")
    args = parser.parse_args()
    joints = runs.load(args.study).csv["setup_joints"]
    means = joints.pivot_table(index="joint", columns="mode", values="error_deg", aggfunc="mean")
    print("mean |joint error| [deg]")
    print(means.to_string(float_format=lambda v: f"{v:.6f}"))
    ax = means.plot.bar(rot=0, figsize=(7, 4))
    ax.set_xlabel("joint")
    ax.set_ylabel("mean |error| [deg]")
    ax.set_title(f"set-up joint errors, {joints['user'].nunique()} users")
    plt.tight_layout()
    plt.savefig(args.out, dpi=100)
    print(f"figure: {args.out}")


if __name__ == "__main__":
    main()
