"""The predictive bands (orbed.study.bands): percentiles by hand, the count, the names the
calibration set uses, and a folder of hand-made studies end to end."""
import json
import os

import pandas as pd
import pytest

from orbed.study import bands


def test_band_is_the_central_95_percent_by_linear_interpolation():
    # 100 values 1..100: position 99 * 0.025 = 2.475 -> 3 + 0.475; 99 * 0.975 = 96.525 -> 97.525.
    records = bands.bands({"table2.ar.mean": list(range(1, 101))}, {"table2.ar.mean": 97.6}, set())
    (r,) = records
    assert (r["lo"], r["median"], r["hi"]) == pytest.approx((3.475, 50.5, 97.525))
    assert not r["inside"] and r["studies"] == 100


def test_count_leaves_calibrated_and_paperless_figures_out():
    values = {"a": [1.0, 2.0, 3.0], "b": [1.0, 2.0, 3.0], "c": [1.0, 2.0, 3.0], "d": [float("nan")] * 3}
    paper = {"a": 2.0, "b": 9.0, "c": 2.0, "d": 1.0, "e": 1.0}
    records = bands.bands(values, paper, {"c"})
    assert [r["figure"] for r in records] == ["a", "b", "c"]  # d: no value in any study; e: not simulated
    assert bands.count(records) == (1, 2)


def test_flatten_names_match_the_calibration_set():
    paper = {"table1": {"ar": {"t_x": [17.4, 16.1], "t_y": [11.9, 6.24], "t_z": [21.6, 16.5], "norm": [30.2, 23.9]},
                        "se3_mean": {"ar_reflective": {"norm": [11.3, 1.01]}}},
             "table2": {"fixed": {"mean": 71.4, "median": 50.6, "min": 0.64, "max": 249, "std": 61.8}},
             "table3": {"ar/fixed": {"joint1": 1.6e-7, "total": 2.0e-18}},
             "table4": {"ar": {"execution_s": {"mean": 91, "median": 83, "min": 22, "max": 306, "std": 59}}}}
    f = bands.flatten(paper)
    assert f["table1.ar.norm_mean"] == 30.2 and f["table1.ar.t_z_std"] == 16.5
    assert f["table1.ar_reflective.se3_n3_std"] == 1.01
    assert f["table2.fixed.median"] == 50.6 and f["table3.ar/fixed.total"] == 2.0e-18
    assert f["table4.ar.execution_s.std"] == 59
    assert bands.calibrated_figures() <= set(f) | {n.replace(".ar.", ".ar_reflective.") for n in f} | {
        "table4.ar.alignment_s.mean", "table4.ar_reflective.alignment_s.mean"}


def test_a_folder_of_studies_end_to_end(tmp_path):
    # Three studies of one user, one set-up per mode, one joint: study m has errors (m+1, 10(m+1), 100)
    # for ar_reflective, ar, fixed and execution times 60 (m+1) s.
    joints, times = [], []
    for m in range(3):
        for mode, error in (("ar_reflective", m + 1.0), ("ar", 10.0 * (m + 1)), ("fixed", 100.0)):
            joints.append({"study": m, "user": "u1", "mode": mode, "order": 1, "target": 1, "joint": 1,
                           "twisting": 1, "target_deg": 0.0, "reached_deg": error, "error_deg": error})
            times.append({"study": m, "user": "u1", "mode": mode, "order": 1, "target": 1,
                          "execution_s": 60.0 * (m + 1), "alignment_s": None if mode == "fixed" else 100.0})
    pd.DataFrame(joints).to_csv(tmp_path / "setup_joints.csv", index=False)
    pd.DataFrame(times).to_csv(tmp_path / "setup_times.csv", index=False)
    paper = {"table2": {"ar": {"mean": 15.0, "median": 5.88, "min": 0.0, "max": 197, "std": 42.4}},
             "table4": {"fixed": {"execution_s": {"mean": 94, "median": 95, "min": 27, "max": 200, "std": 48}}}}
    (tmp_path / "tables.json").write_text(json.dumps({"paper": paper}))
    calibration = tmp_path / "calibration.yaml"
    calibration.write_text("parameters:\n  - {file: x, key: y, value: 1, fitted_to: [table4.fixed.execution_s.mean], "
                           "how: test}\n")
    s = bands.write(str(tmp_path), str(calibration))
    by = {r["figure"]: r for r in s["figures"]}
    assert s["studies"] == 3
    # ar's mean over the studies is 10, 20, 30: the band [10.5, 29.5] holds 15.
    assert (by["table2.ar.mean"]["lo"], by["table2.ar.mean"]["hi"]) == pytest.approx((10.5, 29.5))
    assert by["table2.ar.mean"]["inside"] and not by["table2.ar.median"]["inside"]
    assert by["table4.fixed.execution_s.mean"]["calibrated"]
    # One value per mode and study: the std is 0 in every study.
    assert by["table2.ar.std"]["hi"] == 0 and not by["table2.ar.std"]["inside"]
    assert (s["inside"], s["counted"]) == bands.count(s["figures"])
    assert os.path.exists(tmp_path / "figures" / "bands.pdf") and os.path.exists(tmp_path / "figures" / "bands.png")


def test_the_viewer_frame_is_an_alternative_reading_not_counted():
    paper = {"table1.ar.t_z_mean": 21.6}
    values = {"table1.ar.t_z_mean": [5.0, 6.0, 7.0], "table1_viewer.ar.t_z_mean": [20.0, 21.0, 22.0]}
    records = {r["figure"]: r for r in bands.bands(values, paper, set())}
    assert not records["table1.ar.t_z_mean"]["inside"] and not records["table1.ar.t_z_mean"]["alternative"]
    assert records["table1_viewer.ar.t_z_mean"]["inside"] and records["table1_viewer.ar.t_z_mean"]["alternative"]
    assert bands.count(list(records.values())) == (0, 1)


def test_by_relation_classifies_each_setup_by_its_bending_joints():
    import pandas as pd
    rows = []
    # Set-up 1: start signs (+, -, +) = target's -> same; 2: all opposite -> mirror; 3: a start joint
    # at 0 -> mixed. Errors: joint 1 of set-up 2 is a half turn (170 deg).
    for target, start in ((1, (20, -60, 40)), (2, (-20, 60, -40)), (3, (0, -60, 40))):
        for joint in range(1, 8):
            k = {2: 0, 4: 1, 6: 2}.get(joint)
            rows.append({"study": 0, "user": "u1", "mode": "ar", "target": target, "joint": joint,
                         "target_deg": (30, -70, 50)[k] if k is not None else 10.0,
                         "start_deg": start[k] if k is not None else 0.0,
                         "error_deg": 170.0 if (target == 2 and joint == 1) else 1.0})
    r = bands.by_relation(pd.DataFrame(rows))
    assert set(r) == {"same", "mirror", "mixed"}
    assert r["mirror"]["ar"]["setups"] == 1 and r["mirror"]["ar"]["half_turn_rate"] == pytest.approx(1 / 7)
    assert r["same"]["ar"]["half_turn_rate"] == 0 and r["same"]["ar"]["median_deg"] == 1.0
    assert r["mirror"]["ar"]["mean_deg"] == pytest.approx((170 + 6) / 7)
    assert bands.by_relation(pd.DataFrame(rows).drop(columns="start_deg")) is None
