"""One-at-a-time sensitivity of the set-up half: what each unsourced assistant parameter does.

experiments/setup/sensitivity.yaml lists the keys and the values each is swept to. For the baseline
(the shipped parameters) and for each (key, value), `orbed-setup-study` runs the same N simulated
studies of the paper's size (the same seeds, so the runs differ by that key only) with an assistant
file holding just that key (LoadAssistantConfig: every key optional, the rest the shipped values).
Per run and mode, over every set-up of the N studies pooled: the mean and median joint error [deg],
the half-turn rate (joints with error > 90 deg), the mean execution time [s]; and the two differences
the paper's comparisons rest on, ar_reflective - ar and fixed - ar in mean joint error.

    scripts/orbed sensitivity [--studies N]     (runs it; python/orbed/study/sensitivity.py reads)

writes sensitivity.csv (one row per run and output) and figures/sensitivity.{pdf,png} (per output,
each setting's value against the baseline's). Units: deg, s, fractions.
"""
import os

import numpy as np
import yaml

from . import files

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
SWEEP = os.path.join(ROOT, "experiments", "setup", "sensitivity.yaml")
HALF_TURN_DEG = 90.0
BASELINE = "baseline"


def settings(path=SWEEP):
    """[(name, key, value)]: the baseline first, then each key at each of its values."""
    with open(path) as f:
        spec = yaml.safe_load(f)["parameters"]
    out = [(BASELINE, None, None)]
    for p in spec:
        for v in p["values"]:
            out.append(("%s=%s" % (p["key"], v), p["key"], v))
    return out


def overlay(key, value):
    """The assistant file of one setting: the dotted key as nested mappings."""
    tree = value
    for part in reversed(key.split(".")):
        tree = {part: tree}
    return yaml.safe_dump(tree, default_flow_style=False)


def outputs(joints, times):
    """{output name: value} of one run (every set-up of its studies pooled)."""
    out = {}
    for mode in files.MODES:
        e = joints.loc[joints["mode"] == mode, "error_deg"].astype(float)
        t = times.loc[times["mode"] == mode, "execution_s"].astype(float)
        if e.empty:
            continue
        out["%s.mean_error_deg" % mode] = float(e.mean())
        out["%s.median_error_deg" % mode] = float(e.median())
        out["%s.half_turn_rate" % mode] = float((e > HALF_TURN_DEG).mean())
        out["%s.execution_s" % mode] = float(t.mean())
    for a in ("ar_reflective", "fixed"):
        if "%s.mean_error_deg" % a in out and "ar.mean_error_deg" in out:
            out["%s-ar.mean_error_deg" % a] = out["%s.mean_error_deg" % a] - out["ar.mean_error_deg"]
    return out


def table(run_dirs):
    """{setting name: outputs} of the runs' folders ({name: folder})."""
    return {name: outputs(files.read(d, "setup_joints.csv"), files.read(d, "setup_times.csv"))
            for name, d in run_dirs.items()}


def write(results, out_dir):
    names = list(results)
    keys = sorted({k for r in results.values() for k in r})
    with open(os.path.join(out_dir, "sensitivity.csv"), "w") as f:
        f.write("setting,output,value,baseline,change\n")
        base = results[BASELINE]
        for n in names:
            for k in keys:
                if k in results[n]:
                    f.write("%s,%s,%.6g,%.6g,%.6g\n" % (n, k, results[n][k], base.get(k, np.nan),
                                                        results[n][k] - base.get(k, np.nan)))
    plot(results, os.path.join(out_dir, "figures"))


PANELS = (("mean_error_deg", "mean joint error [deg]"), ("half_turn_rate", "half-turn rate (error > 90 deg)"),
          ("execution_s", "mean execution time [s]"))
MODE_COLORS = {"ar_reflective": "#4c72b0", "ar": "#dd8452", "fixed": "#55a868"}


def plot(results, out_dir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(out_dir, exist_ok=True)
    names = [n for n in results if n != BASELINE]
    fig, axes = plt.subplots(1, len(PANELS), figsize=(13, 0.28 * len(names) + 1.8), sharey=True)
    y = np.arange(len(names))[::-1]
    for ax, (output, label) in zip(axes, PANELS):
        for k, mode in enumerate(files.MODES):
            key = "%s.%s" % (mode, output)
            base = results[BASELINE].get(key)
            if base is None:
                continue
            values = [results[n].get(key, np.nan) for n in names]
            ax.plot(values, y + (k - 1) * 0.22, "o", ms=3.5, color=MODE_COLORS[mode], label=mode)
            ax.axvline(base, color=MODE_COLORS[mode], lw=1, ls="--", alpha=0.8)
        ax.set_xlabel(label)
        ax.grid(axis="x", alpha=0.3)
    axes[0].set_yticks(y)
    axes[0].set_yticklabels([n.replace("assistant.", "") for n in names], fontsize=7)
    axes[0].set_ylim(-0.8, len(names) - 0.2)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", ncol=3, fontsize=8, frameon=False,
               title="dashed: the shipped parameters; dots: one key changed", title_fontsize=8)
    fig.tight_layout(rect=(0, 0, 1, 0.93))
    fig.savefig(os.path.join(out_dir, "sensitivity.pdf"))
    fig.savefig(os.path.join(out_dir, "sensitivity.png"), dpi=300)
    plt.close(fig)
