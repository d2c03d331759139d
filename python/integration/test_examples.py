"""examples/ run as a user runs them: each exits 0 and what it prints or writes is checked against an
independent reading of the same input."""
import csv
import os
import subprocess
import sys
from collections import defaultdict

import cv2
import numpy as np

from conftest import ROOT, binary

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
