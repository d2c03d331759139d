"""rank_flip.py against hand-made rows and the Wilson interval's closed form."""

import math
import os
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

from orbed.study import rank_flip  # noqa: E402

HEADER = ("study,first_user_seed,mode,users,trials,measured_w_mm,measured_s_mm,true_translation_mm,"
          "true_misalignment_mm\n")


def row(study, mode, measured_w, true_translation, measured_s=None, true_misalignment=None):
    return {"study": study, "mode": mode, "measured_w_mm": measured_w,
            "measured_s_mm": measured_w if measured_s is None else measured_s,
            "true_translation_mm": true_translation,
            "true_misalignment_mm": true_translation if true_misalignment is None else true_misalignment}


# Four studies: 0 agrees (display better both ways), 1 flips (measured better, truly worse),
# 2 agrees (display worse both ways), 3 ties on the measured side (not a flip).
ROWS = [
    row(0, "ar_reflective", 17.0, 20.0), row(0, "ar", 24.0, 30.0),
    row(1, "ar_reflective", 19.5, 46.0), row(1, "ar", 27.0, 29.1),
    row(2, "ar", 20.0, 20.0), row(2, "ar_reflective", 25.0, 22.0),
    row(3, "ar_reflective", 21.0, 10.0), row(3, "ar", 21.0, 30.0),
]


def wilson_closed_form(k, n, z=1.959963984540054):
    # Wilson (1927): (p + z²/2n ± z·sqrt(p(1 − p)/n + z²/4n²)) / (1 + z²/n).
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z / (1 + z * z / n) * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return centre - half, centre + half


def test_a_flip_is_an_opposite_order_and_a_tie_is_not():
    assert rank_flip.study_flips(ROWS) == [False, True, False, False]


def test_the_order_of_the_modes_does_not_matter():
    assert rank_flip.study_flips(ROWS, modes=("ar", "ar_reflective")) == [False, True, False, False]


def test_other_columns_are_chosen_by_name():
    rows = [row(0, "ar_reflective", 10.0, 20.0, measured_s=30.0, true_misalignment=5.0),
            row(0, "ar", 12.0, 30.0, measured_s=25.0, true_misalignment=6.0)]
    assert rank_flip.study_flips(rows) == [False]
    assert rank_flip.study_flips(rows, measure="measured_s_mm") == [True]
    assert rank_flip.study_flips(rows, measure="measured_s_mm", truth="true_misalignment_mm") == [True]
    with pytest.raises(ValueError):
        rank_flip.study_flips(rows, measure="misalignment_mm")


def test_summary_is_one_flip_in_four_with_wilsons_interval():
    s = rank_flip.summarize(ROWS)
    assert (s["studies"], s["flips"], s["fraction"]) == (4, 1, 0.25)
    low, high = wilson_closed_form(1, 4)
    assert s["low"] == pytest.approx(low, abs=1e-12)
    assert s["high"] == pytest.approx(high, abs=1e-12)


def test_wilson_interval_at_zero_and_at_all():
    # k = 0: the lower end is 0 and the upper z²/(n + z²) (= 0.27753 for n = 10).
    z2 = 1.959963984540054 ** 2
    low, high = rank_flip.wilson_interval(0, 10)
    assert low == pytest.approx(0.0, abs=1e-15)
    assert high == pytest.approx(z2 / (10 + z2), abs=1e-12)
    assert high == pytest.approx(0.27753, abs=1e-5)
    low, high = rank_flip.wilson_interval(10, 10)
    assert (low, high) == (pytest.approx(1 - z2 / (10 + z2), abs=1e-12), pytest.approx(1.0, abs=1e-15))
    with pytest.raises(ValueError):
        rank_flip.wilson_interval(3, 2)


def test_a_study_without_both_modes_or_with_nan_is_refused():
    with pytest.raises(ValueError, match="no row for mode ar"):
        rank_flip.study_flips(ROWS[:3])
    with pytest.raises(ValueError, match="twice"):
        rank_flip.study_flips(ROWS + [row(0, "ar", 1.0, 1.0)])
    with pytest.raises(ValueError, match="nan"):
        rank_flip.study_flips([row(0, "ar_reflective", 1.0, 1.0, measured_s=math.nan), row(0, "ar", 2.0, 2.0)],
                              measure="measured_s_mm")


def test_the_file_as_orbed_user_study_writes_it(tmp_path, capsys):
    path = tmp_path / "rank_flip.csv"
    lines = [HEADER]
    for r in ROWS:
        lines.append(f"{r['study']},1,{r['mode']},4,40,{r['measured_w_mm']},nan,{r['true_translation_mm']},"
                     f"{r['true_misalignment_mm']}\n")
    path.write_text("".join(lines))
    rows = rank_flip.read_rows(str(path))
    assert len(rows) == 8 and math.isnan(rows[0]["measured_s_mm"])
    assert rank_flip.summarize(rows)["flips"] == 1
    assert rank_flip.main([str(path)]) == 0
    out = capsys.readouterr().out
    assert "Table 1 figure, axes of W vs true translation error: 1 of 4 studies" in out
    assert "25.0 %" in out
    assert "viewer axes S vs true translation error: study 0, mode ar_reflective: measured_s_mm is nan" in out
