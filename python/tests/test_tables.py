# Tables 1-4 (orbed.study.tables, beyond). Oracles: the tables.json the C++ orbed-study-tables wrote
# for tests/testdata/study before the statistics moved to Python; the pinned ViRAAl run's own table1
# (Python's statistics module computed it from the file's trials); hand computations.
import json
import math
import os

import pandas as pd
import pytest

from conftest import ROOT
from helpers import joints_frame
from orbed.study import analysis, beyond, files, tables

STUDY = os.path.join(ROOT, "tests", "testdata", "study")
PINNED = os.path.join(ROOT, "tests", "integration", "testdata", "viraal_pinned_results.json")


def close(a, b, rel=1e-9):
    """Nested dicts/lists of numbers equal to a relative 1e-9 (None equal None)."""
    if isinstance(b, dict):
        assert set(a) >= set(b), (sorted(a), sorted(b))
        for k in b:
            close(a[k], b[k], rel)
    elif isinstance(b, list):
        assert len(a) == len(b)
        for x, y in zip(a, b):
            close(x, y, rel)
    elif isinstance(b, (int, float)) and b is not None:
        assert a == pytest.approx(b, rel=rel, abs=1e-300), (a, b)
    else:
        assert a == b


@pytest.fixture(scope="module")
def before_and_now():
    with open(os.path.join(STUDY, "tables.json")) as f:
        before = json.load(f)
    return before, analysis.analyze(STUDY, resamples=20)


def test_equal_to_what_the_cpp_wrote_for_the_same_files(before_and_now):
    before, now = before_and_now
    for key in ("users", "setup_users", "landmark_validation_mm", "table2", "table3", "table3_test", "table4"):
        close(now[key], before[key])
    for mode in ("ar_reflective", "ar"):
        close(now["table1"][mode], before["table1"][mode])
        close(now["table1"]["se3_mean"][mode], before["table1"]["se3_mean"][mode])
    for key in ("docking", "collisions", "near_miss_m"):
        close(now["beyond"][key], before["beyond"][key])


def pinned_trials(users=1):
    with open(PINNED) as f:
        pinned = json.load(f)
    rows = []
    for u in range(1, users + 1):
        for s in pinned["sessions"]:
            for t in s["trials"]:
                x, y, z = t["misalignment_axes_mm"]
                rows.append({"user": "u%d" % u, "mode": s["mode"], "t_x_mm": x, "t_y_mm": y, "t_z_mm": z})
    return pinned, pd.DataFrame(rows)


def test_one_user_gives_the_pinned_runs_table1():
    pinned, trials = pinned_trials()
    t1 = tables.table1(trials)
    assert list(t1) == ["ar_reflective", "ar"]
    for s in pinned["sessions"]:
        row, expected = t1[s["mode"]], s["table1"]
        assert row["num_trials"] == expected["num_trials"]
        for k, axis in enumerate(("t_x", "t_y", "t_z")):
            assert row[axis][0] == pytest.approx(expected["axes_mean_mm"][k], abs=1e-12)
            assert row[axis][1] == pytest.approx(expected["axes_std_mm"][k], abs=1e-12)
        assert row["norm"] == pytest.approx([expected["mean_mm"], expected["std_mm"]], abs=1e-12)


def test_the_same_user_twice_keeps_the_means_and_shrinks_the_stds():
    # Each value twice: 2 sum (x - m)^2 over 6 - 1 instead of sum (x - m)^2 over 3 - 1: std * sqrt(4/5).
    _, one = pinned_trials(1)
    _, two = pinned_trials(2)
    a, b = tables.table1(one), tables.table1(two)
    for mode in ("ar_reflective", "ar"):
        assert b[mode]["num_trials"] == 2 * a[mode]["num_trials"]
        for axis in ("t_x", "t_y", "t_z"):
            assert b[mode][axis][0] == pytest.approx(a[mode][axis][0], abs=1e-12)
            assert b[mode][axis][1] == pytest.approx(a[mode][axis][1] * math.sqrt(4 / 5), abs=1e-12)


def test_table1_of_groups_of_three_and_in_the_viewer_frame():
    groups = pd.DataFrame({"user": ["u1", "u1", "u2", "u1"], "mode": ["ar_reflective"] * 3 + ["ar"],
                           "group": ["1", "2", "1", "1"], "trials": ["1-3", "4-6", "1-3", "1-3"],
                           "misalignment_mm": [10.0, 12.0, 14.0, 20.0]})
    g = tables.table1_groups(groups)
    assert g["ar_reflective"]["norm"] == pytest.approx([12.0, 2.0])  # (4 + 0 + 4) / 2 = 4
    assert g["ar_reflective"]["groups"] == 3 and g["ar_reflective"]["users"] == 2
    assert g["ar"]["norm"] == [20.0, 0.0] and g["ar"]["trials_per_group"] == 3
    assert tables.group_size("4-6") == 3 and tables.group_size("3") == 3
    trials = pd.DataFrame({"user": ["u1"] * 2, "mode": ["ar"] * 2, "t_x_mm": [1.0, 3.0], "t_y_mm": [0.0, 0.0],
                           "t_z_mm": [0.0, 0.0]})
    assert tables.table1_viewer(trials) is None
    trials["v_x_mm"], trials["v_y_mm"], trials["v_z_mm"] = [0.0, 0.0], [3.0, 5.0], [4.0, 4.0]
    v = tables.table1_viewer(trials)["ar"]
    assert v["t_y"] == pytest.approx([4.0, math.sqrt(2)]) and v["t_z"] == [4.0, 0.0]
    assert v["norm"][0] == pytest.approx(math.sqrt(32))


def two_users():
    # As setup_tables_test's TwoUsers: joint 1 off by the given error, the other joints exact.
    e = lambda x: [x, 0, 0, 0, 0, 0, 0]  # noqa: E731
    joints = joints_frame([("u1", "ar", 1, e(1)), ("u1", "ar", 2, e(2)), ("u1", "fixed", 1, e(4)),
                           ("u1", "fixed", 2, e(-5)), ("u2", "fixed", 1, e(6)), ("u2", "fixed", 2, e(7)),
                           ("u2", "ar", 1, e(-3))])
    times = pd.DataFrame({"user": ["u1"] * 4 + ["u2"] * 3, "mode": ["ar", "ar", "fixed", "fixed", "fixed", "fixed", "ar"],
                          "target": [1, 2, 1, 2, 1, 2, 1], "execution_s": [60, 90, 100, 120, 80, 140, 75],
                          "alignment_s": [100, 140, None, None, None, None, 120]})
    return joints, times


def test_tables_two_three_and_four_by_hand():
    joints, times = two_users()
    t2 = tables.table2(joints)
    # ar: joint 1 errors {1, 2, 3} and 18 zeros.
    assert t2["ar"]["mean"] == pytest.approx(6 / 21) and t2["ar"]["median"] == 0 and t2["ar"]["max"] == 3
    assert t2["ar"]["n"] == 21 and "ar_reflective" not in t2
    t3 = tables.table3(joints)
    # ar/fixed joint 1: {1, 2, 3} against {4, 5, 6, 7}: U = 0, sigma^2 = 3 * 4 * 8 / 12 = 8,
    # z = (6 - 0.5) / sqrt(8) = 1.94454, p = erfc(z / sqrt 2) = 0.0518299.
    assert t3["ar/fixed"]["joint1"] == pytest.approx(0.0518299272, abs=1e-9)
    assert t3["ar/fixed"]["joint2"] is None  # all zero: no test
    assert list(t3) == ["ar/fixed"]
    t4 = tables.table4(times)
    assert t4["ar"]["execution_s"]["median"] == 75 and t4["ar"]["execution_s"]["std"] == pytest.approx(15)
    assert t4["ar"]["alignment_s"]["mean"] == 120
    assert "alignment_s" not in t4["fixed"] and t4["fixed"]["execution_s"]["max"] == 140


def test_mann_whitney_u_counts_pairs():
    # Six tortoises and six hares finishing T H H H H H T T T T T H: U_T = #(T after H) = 0 + 5 * 5 = 25.
    r = tables.mann_whitney([1, 7, 8, 9, 10, 11], [2, 3, 4, 5, 6, 12])
    assert r["u_a"] == 25
    assert r["cliffs_delta"] == pytest.approx(2 * 25 / 36 - 1)  # P(T > H) - P(T < H) = (25 - 11) / 36
    # Ties count half: x = {1, 2, 2}, y = {2, 3, 4}: U = 0.5 + 0.5 = 1. Normal approximation with one
    # tie group of 3: sigma^2 = 9/12 (7 - 24/30) = 4.65, z = (1 - 4.5 + 0.5)/sqrt(4.65) = -1.39122,
    # two-sided p = 2 Phi(-1.39122) = 0.1642 (table).
    r = tables.mann_whitney([1, 2, 2], [2, 3, 4])
    assert r["u_a"] == 1 and r["p"] == pytest.approx(0.1642, abs=0.0015)
    assert tables.mann_whitney([3, 3], [3, 3, 3])["p"] is None


def test_beyond_the_paper_by_hand():
    # A contact is never also a near miss; a clearance of exactly 5 cm is not one; unknown is not one.
    d = pd.DataFrame({"user": ["u1", "u1", "u1", "u2", "u2"], "mode": ["ar", "ar", "fixed", "ar", "fixed"],
                      "docking_tip_mm": [4, 10, 80, 6, 40], "docking_axis_deg": [0.5, 1.5, 12, 1.0, 6],
                      "min_clearance_m": [0.01, -0.002, 0.05, None, 0.049], "contact": [0, 1, 0, 0, 0],
                      "collision_stops": [0, 2, 1, 0, 0]})
    b = beyond.beyond(d, None)
    assert b["docking"]["ar"]["tip_mm"]["median"] == 6 and b["docking"]["ar"]["axis_deg"]["mean"] == 1
    assert b["docking"]["fixed"]["tip_mm"]["mean"] == 60
    c = b["collisions"]
    assert (c["ar"]["setups"], c["ar"]["contact"], c["ar"]["collision_stops"], c["ar"]["near_miss"]) == (3, 1, 2, 1)
    assert c["ar"]["min_clearance_m"]["n"] == 2
    assert c["fixed"]["near_miss"] == 1 and c["fixed"]["collision_stops"] == 1


def test_registration_share_by_hand():
    # 1 - (mean error with the true registration) / (mean error measured) = 1 - 1.5 / 5.
    measured = joints_frame([("m1", "ar", 1, [4] * 7), ("m2", "ar", 1, [6] * 7)])
    truth = joints_frame([("m1", "ar", 1, [1] * 7), ("m2", "ar", 1, [2] * 7)])
    share = beyond.registration_share(measured, truth)
    assert share["ar"]["measured_deg"]["mean"] == 5 and share["ar"]["truth_deg"]["mean"] == 1.5
    assert share["ar"]["share"] == pytest.approx(0.7)
    assert "fixed" not in share


def test_target_key_is_the_id_when_the_csv_has_one():
    joints = joints_frame([("u1", "ar", 1, [1] * 7)])
    assert set(joints["target_key"]) == {"1"}
    joints["target_id"] = "trocar-b/park-2"
    assert set(files.with_target_key(joints)["target_key"]) == {"trocar-b/park-2"}
