"""orbed.runs on folders: the study files the tests keep (tests/testdata/study) and a made-up run
folder with a user's run inside it."""
import json
import os
import subprocess

import pandas as pd
import pytest

from orbed import runs

STUDY = os.path.join(runs.types.REPO, "tests", "testdata", "study")


def test_a_study_folder_reads_as_dicts_and_frames():
    run = runs.load(STUDY)
    with open(os.path.join(STUDY, "tables.json"), encoding="utf-8") as f:
        assert run.tables == json.load(f)
    assert sorted(run.csv) == ["alignment_means", "alignment_trials", "landmark_validation", "setup_docking",
                               "setup_joints", "setup_times"]
    pd.testing.assert_frame_equal(run.csv["setup_joints"], pd.read_csv(os.path.join(STUDY, "setup_joints.csv")))
    assert run.provenance is None and run.logs == [] and run.runs() == {}


def test_a_run_folder_with_a_run_inside(tmp_path):
    user = tmp_path / "viraal-u1"
    user.mkdir()
    (user / "results.json").write_text('{"trials": [1, 2]}')
    (user / "provenance.json").write_text('{"kind": "launch", "run": "viraal-u1"}')
    (user / "orbed-1.lcmlog").write_bytes(b"")
    (tmp_path / "provenance.json").write_text('{"kind": "study", "runs": ["viraal-u1"]}')
    run = runs.load(str(tmp_path))
    assert run.kind == "study" and run.results is None
    inner = run.runs()["viraal-u1"]
    assert inner.results == {"trials": [1, 2]} and inner.logs == [str(user / "orbed-1.lcmlog")]


def test_start_refuses_other_verbs_and_a_failed_command_raises(tmp_path):
    with pytest.raises(ValueError):
        runs.start("launch")
    started = runs.start("sweep", "--no-such-flag", env=dict(os.environ, ORBED_LOGS_DIR=str(tmp_path)),
                         output=subprocess.DEVNULL)
    with pytest.raises(subprocess.CalledProcessError):
        started.wait(timeout_s=60)
