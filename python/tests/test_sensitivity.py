"""The sensitivity sweep's pieces (orbed.study.sensitivity): the settings list, the one-key assistant
file, the outputs of a run by hand."""
import pandas as pd
import pytest
import yaml

from orbed.study import sensitivity


def test_settings_start_with_the_baseline_and_cover_every_value():
    s = sensitivity.settings()
    assert s[0] == ("baseline", None, None)
    with open(sensitivity.SWEEP) as f:
        spec = yaml.safe_load(f)["parameters"]
    assert len(s) == 1 + sum(len(p["values"]) for p in spec)
    assert all(name == "%s=%s" % (key, value) for name, key, value in s[1:])


def test_overlay_is_the_dotted_key_as_nested_mappings():
    assert yaml.safe_load(sensitivity.overlay("assistant.acting.choice", "best")) == \
        {"assistant": {"acting": {"choice": "best"}}}


def test_every_swept_key_exists_in_the_shipped_assistant_file():
    with open(sensitivity.ROOT + "/procs/assistant/assistant.yaml") as f:
        shipped = yaml.safe_load(f)
    for _, key, _ in sensitivity.settings()[1:]:
        node = shipped
        for part in key.split("."):
            node = node[part]


def test_outputs_by_hand():
    joints = pd.DataFrame({"mode": ["ar"] * 4 + ["ar_reflective"] * 2,
                           "error_deg": [1.0, 3.0, 170.0, 2.0, 10.0, 20.0]})
    times = pd.DataFrame({"mode": ["ar", "ar_reflective"], "execution_s": [60.0, 90.0]})
    o = sensitivity.outputs(joints, times)
    assert o["ar.mean_error_deg"] == pytest.approx(44.0)
    assert o["ar.median_error_deg"] == pytest.approx(2.5)
    assert o["ar.half_turn_rate"] == pytest.approx(0.25)
    assert o["ar_reflective-ar.mean_error_deg"] == pytest.approx(15.0 - 44.0)
    assert "fixed.mean_error_deg" not in o and "fixed-ar.mean_error_deg" not in o
