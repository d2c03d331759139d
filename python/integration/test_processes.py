"""orbed.bus and orbed.log against real processes over real LCM (one private network namespace for
the module): orbed-iiwa-sim, orbed-logger, orbed-log and the C++ peer orbed-py-peer."""
import hashlib
import os
import struct
import subprocess
import time

import numpy as np
import pandas as pd

from conftest import binary
from orbed import bus, log, runs, types

lcm = types.lcm_types()
SIM_RATE_HZ = 200.0  # --period-s 0.005


def test_a_python_subscriber_receives_the_sims_iiwa_status_at_its_rate(sim):
    b = bus.Bus()
    stamps = []  # (wall [s], sim utime [us])
    b.subscribe("IIWA_STATUS", lcm.iiwa_status_t, lambda c, m: stamps.append((time.monotonic(), m.utime)))
    assert b.handle_until(lambda: stamps, 30), "no IIWA_STATUS from the sim"
    stamps.clear()
    b.handle_until(lambda: len(stamps) > 1 and stamps[-1][0] - stamps[0][0] >= 2.0, 10)
    wall_s = stamps[-1][0] - stamps[0][0]
    rate_hz = (len(stamps) - 1) / wall_s
    steps_us = np.diff([u for _, u in stamps])
    assert abs(rate_hz - SIM_RATE_HZ) < 0.1 * SIM_RATE_HZ, rate_hz
    assert np.median(steps_us) == 5000  # one tick of the sim clock between two statuses
    assert b.refused == {}


def command(q):
    m = lcm.iiwa_command_t()
    m.utime, m.num_joints, m.joint_position, m.num_torques, m.joint_torque = int(time.time() * 1e6), 7, q, 0, []
    return m


def test_a_python_iiwa_command_moves_the_sims_arm(sim):
    b = bus.Bus()
    target = [0.3, 0.0, 0.0, 0.0, 0.0, 0.0, -0.5]
    latest = {}
    b.subscribe("IIWA_STATUS", lcm.iiwa_status_t, lambda c, m: latest.update(m=m))
    assert b.handle_until(lambda: "m" in latest, 30)
    start_q = list(latest["m"].joint_position_measured)
    assert np.allclose(start_q, 0.0, atol=1e-9)
    deadline = time.monotonic() + 30
    reached = False
    while not reached and time.monotonic() < deadline:
        b.publish("IIWA_COMMAND", command(target))  # 10 Hz, as a controller would
        b.handle_until(lambda: False, 0.1)
        q = np.array(latest["m"].joint_position_measured)
        reached = np.allclose(q, target, atol=1e-4)
    assert reached, latest["m"].joint_position_measured
    assert np.allclose(latest["m"].joint_position_commanded, target, atol=0)


def test_a_300_kB_image_goes_from_python_to_cpp_and_back_whole(processes):
    peer = processes.start([os.path.join(types.build_dir(), "tests", "orbed-py-peer"), "echo", "PY_IMAGE", "CPP_IMAGE"])
    assert peer.stdout.readline().strip() == "subscribed"
    image = lcm.image_t()
    image.width, image.height, image.row_stride, image.pixel_format = 400, 250, 1200, lcm.image_t.FORMAT_BGR8
    image.data = np.random.default_rng(7).integers(0, 256, 300000, dtype=np.uint8).tobytes()
    image.num_bytes = len(image.data)
    b = bus.Bus()
    echoed = []
    b.subscribe("CPP_IMAGE", lcm.image_t, lambda c, m: echoed.append(m))
    b.publish("PY_IMAGE", image)
    assert b.handle_until(lambda: echoed, 30), "no echo from orbed-py-peer"
    assert peer.stdout.readline().split() == ["300000", hashlib.sha256(image.data).hexdigest()]
    assert echoed[0].data == image.data and echoed[0].width == 400 and b.refused == {}
    assert peer.wait(30) == 0


def strings_status():
    m = lcm.process_status_t()
    m.name, m.host = 'py, "quoted"', " padded "
    m.last_error, m.reject_reason, m.drop_reason = "line\nbreak", [], []
    return m


def trial(rays):
    m = lcm.alignment_trial_t()
    m.session_id, m.user_id, m.num_joints, m.joint_position = "s", "u", 2, [0.1, -2.5e-7]
    m.X_WV.position_m, m.X_WV.quaternion_wxyz = [1e16, 123456.0, 0.0001], [1.0, 0.0, -0.0, float("nan")]
    m.num_annotation_rays = rays
    m.annotation_landmark, m.annotation_side = list(range(rays)), [-1] * rays
    m.annotation_origin_W_m = [[0.5, 1.5, 1e-300]] * rays
    m.annotation_direction_W = [[float("inf"), 1 / 3, 2.0]] * rays
    return m


def draw():
    m = lcm.viewer_draw_t()
    m.num_links, m.link_name, m.robot_num = 2, ["a", "b"], [0, 1]
    m.position = [[0.1, 1e-5, 3.4028235e38], [1.0, 2.0, 16777217.0]]
    m.quaternion = [[1.0, 0.0, 0.0, 0.1], [0.5, 0.5, 0.5, 0.5]]
    return m


def test_a_log_read_in_python_equals_orbed_log_csv_export_cell_for_cell(sim, processes, tmp_path):
    path = tmp_path / "run.lcmlog"
    logger = processes.start([binary("orbed-logger"), "--file", str(path), "--flush-interval-s", "0.05"])
    b = bus.Bus()
    sent = []
    b.subscribe("LOGGER_STATUS", None, lambda c, m: sent.append(c))
    assert b.handle_until(lambda: sent, 30), "the logger does not run"
    hostile = bytearray(lcm.iiwa_status_t().encode())
    hostile[16:20] = struct.pack(">i", 2**31 - 1)
    for channel, message in (("PY_TRIAL", trial(1)), ("PY_TRIAL", trial(3)), ("PY_TRIAL", trial(0)),
                                            ("PY_STATUS", strings_status()), ("PY_DRAW", draw()),
                                            ("IIWA_STATUS", bytes(hostile)), ("PY_JUNK", b"\0" * 12)):
        b.publish(channel, message)
    b.publish("PY_DONE", b"")

    def done():  # the logger has written the last message (flushed every 0.05 s)
        return path.exists() and any(e.channel == "PY_DONE" for e in log.events(str(path)))
    deadline = time.monotonic() + 30
    while not done() and time.monotonic() < deadline:
        b.handle(0.05)
    assert done()
    assert processes.stop(logger) == 0
    out = tmp_path / "csv"
    subprocess.run([binary("orbed-log"), "export", "--csv", str(path), str(out)], check=True, capture_output=True)
    text = log.export(str(path), text=True)
    typed = log.tables(str(path))
    files = sorted(p.name for p in out.iterdir())
    assert files == sorted(log.csv_file_stem(c) + ".csv" for c in text.frames)
    assert {"PY_TRIAL", "PY_STATUS", "PY_DRAW", "IIWA_STATUS", "ROBOT_STATE"} <= set(text.frames)
    assert text.refused["IIWA_STATUS"] == {"count": 1} and text.unknown["PY_JUNK"] == 1
    for channel, frame in text.frames.items():
        csv = out / (log.csv_file_stem(channel) + ".csv")
        expected = pd.read_csv(csv, dtype=str, keep_default_na=False)
        assert list(frame.columns) == list(expected.columns), channel
        assert frame.shape == expected.shape and (frame.values == expected.values).all(), channel
        assert log.csv_text(frame).encode() == csv.read_bytes(), channel
        numbers = pd.read_csv(csv, float_precision="round_trip")
        numeric = [c for c in numbers.columns if pd.api.types.is_numeric_dtype(typed[channel][c])]
        pd.testing.assert_frame_equal(typed[channel][numeric].astype(float), numbers[numeric].astype(float),
                                      check_exact=True)
    trial_columns = list(text.frames["PY_TRIAL"].columns)
    assert trial_columns.index("annotation_landmark[2]") < trial_columns.index("annotation_side[0]")


def first_difference(channel, python, cpp):
    """Where two CSV texts part: the line numbers and the two lines, for a failure message."""
    a, b = python.split(b"\n"), cpp.split(b"\n")
    for i, (x, y) in enumerate(zip(a, b)):
        if x != y:
            return f"{channel}: {len(a)} lines in Python, {len(b)} in C++; line {i}:\n  {x[:400]}\n  {y[:400]}"
    return f"{channel}: {len(a)} lines in Python, {len(b)} in C++, equal up to the shorter"


def test_a_viraal_run_started_from_python_and_its_folder_and_log(tmp_path):
    folder = runs.run("run", "--run-id", "pinned", "--arg", "trials=1", env=dict(os.environ, ORBED_LOGS_DIR=str(tmp_path)),
                      output=subprocess.DEVNULL, timeout_s=600)
    run = runs.load(folder)
    assert os.path.dirname(folder) == str(tmp_path) and run.kind == "launch"
    assert run.provenance["command_line"][-5:] == ["run", "--run-id", "pinned", "--arg", "trials=1"] and run.provenance["exit_code"] == 0
    assert run.results["status"] == "ok" and run.results["run_id"] == "pinned" and len(run.logs) == 1
    # The whole run's log, every channel (images, strings, the sim's 200 Hz), equal to the C++ export.
    out = tmp_path / "csv"
    subprocess.run([binary("orbed-log"), "export", "--csv", run.logs[0], str(out)], check=True, capture_output=True)
    text = log.export(run.logs[0], text=True)
    assert len(text.frames) >= 15 and text.damage == []
    for channel, frame in text.frames.items():
        python, cpp = log.csv_text(frame).encode(), (out / (log.csv_file_stem(channel) + ".csv")).read_bytes()
        assert python == cpp, first_difference(channel, python, cpp)
    assert sorted(p.name for p in out.iterdir()) == sorted(log.csv_file_stem(c) + ".csv" for c in text.frames)
