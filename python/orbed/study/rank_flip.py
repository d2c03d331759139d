"""How often the paper's Table 1 measurement ranks the two display modes opposite to the truth.

Input: the rows `orbed-user-study --studies M --csv FILE` writes (experiments/viraal/rank_flip.h),
one per simulated study and mode:

    study,first_user_seed,mode,users,trials,measured_w_mm,measured_s_mm,true_translation_mm,
    true_misalignment_mm

A study flips when its measured figure and its true figure order the two modes differently:
(measured_a - measured_b) * (true_a - true_b) < 0. A tie on either side is not a flip. The flip
fraction k / n over the n studies comes with its Wilson score interval (statsmodels'
proportion_confint, method "wilson"; 95 % unless told otherwise).

    /usr/bin/python3 python/orbed/study/rank_flip.py FILE [--modes ar_reflective,ar]

prints one line per measured figure (W axes, viewer axes S) and truth (translation error at the
robot centroid, landmark misalignment from the truth's pairs). Units: mm in the file; fractions here.
"""

import argparse
import csv
import math
import sys

from statsmodels.stats.proportion import proportion_confint

MEASURES = {
    "measured_w_mm": "Table 1 figure, axes of W",
    "measured_s_mm": "Table 1 figure, viewer axes S",
}
TRUTHS = {
    "true_translation_mm": "true translation error",
    "true_misalignment_mm": "true landmark misalignment",
}


def read_rows(path):
    """The CSV's rows as dicts, numbers as float (study as int)."""
    with open(path, newline="") as f:
        rows = []
        for row in csv.DictReader(f):
            parsed = dict(row)
            parsed["study"] = int(row["study"])
            for key in (*MEASURES, *TRUTHS):
                parsed[key] = float(row[key])
            rows.append(parsed)
    return rows


def study_flips(rows, modes=("ar_reflective", "ar"), measure="measured_w_mm", truth="true_translation_mm"):
    """One bool per study, in study order: does `measure` rank modes[0] and modes[1] opposite to `truth`?

    Raises ValueError when a study lacks one of the two modes or has one twice, or a figure is not a
    finite number (measured_s_mm is NaN when a trial had no viewer frame).
    """
    if measure not in MEASURES or truth not in TRUTHS:
        raise ValueError(f"unknown column: {measure if measure not in MEASURES else truth}")
    by_study = {}
    for row in rows:
        if row["mode"] not in modes:
            continue
        entry = by_study.setdefault(row["study"], {})
        if row["mode"] in entry:
            raise ValueError(f"study {row['study']}: mode {row['mode']} twice")
        for key in (measure, truth):
            if not math.isfinite(row[key]):
                raise ValueError(f"study {row['study']}, mode {row['mode']}: {key} is {row[key]}")
        entry[row["mode"]] = row
    flips = []
    for study in sorted(by_study):
        entry = by_study[study]
        missing = [m for m in modes if m not in entry]
        if missing:
            raise ValueError(f"study {study}: no row for mode {missing[0]}")
        a, b = entry[modes[0]], entry[modes[1]]
        flips.append((a[measure] - b[measure]) * (a[truth] - b[truth]) < 0)
    return flips


def wilson_interval(k, n, confidence=0.95):
    """The Wilson score interval of the proportion k / n."""
    if n < 1 or not 0 <= k <= n:
        raise ValueError(f"need 0 <= k <= n and n >= 1, got k={k}, n={n}")
    low, high = proportion_confint(k, n, alpha=1 - confidence, method="wilson")
    return float(low), float(high)


def summarize(rows, modes=("ar_reflective", "ar"), measure="measured_w_mm", truth="true_translation_mm",
              confidence=0.95):
    """{"studies", "flips", "fraction", "low", "high"} for one measure and truth."""
    flips = study_flips(rows, modes, measure, truth)
    k, n = sum(flips), len(flips)
    if n == 0:
        raise ValueError("no studies with both modes")
    low, high = wilson_interval(k, n, confidence)
    return {"studies": n, "flips": k, "fraction": k / n, "low": low, "high": high}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("csv", help="the rows of orbed-user-study --studies M --csv FILE")
    parser.add_argument("--modes", default="ar_reflective,ar", help="the two modes compared (default: %(default)s)")
    args = parser.parse_args(argv)
    modes = tuple(args.modes.split(","))
    if len(modes) != 2:
        parser.error("--modes needs two modes, comma-separated")
    rows = read_rows(args.csv)
    for measure, measure_text in MEASURES.items():
        for truth, truth_text in TRUTHS.items():
            try:
                s = summarize(rows, modes, measure, truth)
            except ValueError as e:
                print(f"{measure_text} vs {truth_text}: {e}")
                continue
            print(f"{measure_text} vs {truth_text}: {s['flips']} of {s['studies']} studies rank "
                  f"{modes[0]} and {modes[1]} the other way round: {100 * s['fraction']:.1f} % "
                  f"(95 % Wilson interval {100 * s['low']:.1f}-{100 * s['high']:.1f} %)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
