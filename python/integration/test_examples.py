"""examples/ run as a user runs them: each exits 0 and what it prints or writes is checked against an
independent reading of the same input."""
import csv
import json
import math
import os
import subprocess
import sys
from collections import defaultdict

import cv2
import numpy as np

from conftest import ROOT, binary
from orbed import bus, types

EXAMPLES = os.path.join(ROOT, "examples")
STUDY = os.path.join(ROOT, "tests", "testdata", "study")


def example(name, *args, **kwargs):
    return subprocess.run([sys.executable, os.path.join(EXAMPLES, name), *args], capture_output=True, text=True,
                          check=True, timeout=180, **kwargs).stdout


def test_every_example_is_under_60_lines():
    for name in os.listdir(EXAMPLES):
        with open(os.path.join(EXAMPLES, name), encoding="utf-8") as f:
            assert len(f.readlines()) < 60, name


def test_plot_joint_errors_prints_the_mean_error_per_joint_and_mode(tmp_path):
    out = example("plot_joint_errors.py", STUDY, "--out", str(tmp_path / "errors.png"))
    errors = defaultdict(list)  # (joint, mode) -> |error| [deg], read with the csv module
    with open(os.path.join(STUDY, "setup_joints.csv"), newline="") as f:
        for row in csv.DictReader(f):
            errors[(int(row["joint"]), row["mode"])].append(float(row["error_deg"]))
    lines = out.splitlines()
    modes = lines[1].split()[1:]
    assert modes == ["ar", "ar_reflective", "fixed"]
    printed = {int(line.split()[0]): [float(v) for v in line.split()[1:]] for line in lines[3:10]}
    for joint in range(1, 8):
        for k, mode in enumerate(modes):
            assert abs(printed[joint][k] - sum(errors[(joint, mode)]) / len(errors[(joint, mode)])) < 1e-6
    assert cv2.imread(str(tmp_path / "errors.png")).shape == (400, 700, 3)


def test_hmd_camera_frames_reach_opencv(processes, tmp_path):
    env = dict(os.environ, ORBED_SOURCE_DIR=ROOT)
    processes.start([binary("orbed-iiwa-sim"), "--name", "sim", "--initial-q-deg", "0,30,0,-60,0,45,0"], env=env)
    processes.start([binary("orbed-hmd"), "--name", "hmd", "--displays", "1"], env=env)
    out = example("hmd_camera_opencv.py", "--frames", "3", "--out", str(tmp_path))
    for n, line in enumerate(out.splitlines()):
        frame = cv2.imread(str(tmp_path / f"frame_{n}.png"))
        edges = cv2.imread(str(tmp_path / f"edges_{n}.png"), cv2.IMREAD_GRAYSCALE)
        assert frame.shape == (720, 1280, 3) and frame.std() > 0  # the HoloLens PV size, not blank
        assert line == f"frame {n}: 1280x720, {np.count_nonzero(edges)} edges"
    assert n == 2


def same_numbers(got, want, path=""):
    """Where `got` differs from `want`: numbers within 1e-9 (relative) agree, the rest must be equal."""
    if isinstance(want, dict):
        return [d for k in want for d in same_numbers(got.get(k), want[k], f"{path}.{k}")] + \
            [f"{path}.{k}: not expected" for k in set(got) - set(want)]
    if isinstance(want, list):
        if not isinstance(got, list) or len(got) != len(want):
            return [f"{path}: {got} != {want}"]
        return [d for k, (g, w) in enumerate(zip(got, want)) for d in same_numbers(g, w, f"{path}[{k}]")]
    if isinstance(want, float) and isinstance(got, (int, float)):
        return [] if math.isclose(got, want, rel_tol=1e-9, abs_tol=1e-12) else [f"{path}: {got} != {want}"]
    return [] if got == want else [f"{path}: {got!r} != {want!r}"]


def test_a_python_registration_server_answers_a_viraal_run_as_orbed_registration_does(processes, tmp_path):
    env = dict(os.environ, ORBED_SOURCE_DIR=ROOT)
    processes.start([binary("orbed-iiwa-sim"), "--name", "sim"], env=env)
    processes.start([binary("orbed-hmd"), "--name", "hmd"], env=env)
    server = processes.start([sys.executable, os.path.join(EXAMPLES, "registration_server.py")], env=env)
    assert server.stdout.readline().startswith("registration server: answering")
    scenario = subprocess.run([binary("orbed-scenario"), "--name", "scenario", "--run-id", "pinned",
                               "--results-dir", str(tmp_path)], env=env, capture_output=True, text=True, timeout=240)
    assert scenario.returncode == 0, scenario.stdout[-2000:] + scenario.stderr[-2000:]
    with open(tmp_path / "results.json", encoding="utf-8") as f:
        results = json.load(f)
    # The run orbed-registration answers (orbed-user-study --trials 3 --run-id pinned), number for number.
    pinned_file = os.path.join(ROOT, "tests", "integration", "testdata", "viraal_pinned_results.json")
    with open(pinned_file, encoding="utf-8") as f:
        pinned = json.load(f)
    for key in ("started_utime", "duration_s"):
        results.pop(key)
    assert results["status"] == "ok" and same_numbers(results, pinned) == []
    # Its heartbeat: on PROCESS_STATUS like orbed's processes, nothing refused in the whole run.
    beats = []
    b = bus.Bus()
    b.subscribe("PROCESS_STATUS", types.lcm_types().process_status_t,
                lambda c, m: beats.append(m) if m.name == "py-registration" else None)
    assert b.handle_until(lambda: beats, 10)
    assert beats[0].rejected_inputs == 0 and beats[0].messages_in > 0 and beats[0].messages_out > 0
