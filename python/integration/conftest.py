# Real processes over real LCM for the Python package's tests. Run inside a private network namespace
# (ctest: python_bus_integration, through scripts/netns-exec); the build tree is $ORBED_BUILD_DIR.
import os
import subprocess
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "python"))

from orbed import types  # noqa: E402


def pytest_configure(config):
    if os.environ.get("ORBED_IN_NETNS") != "1":
        raise pytest.UsageError("run inside a private network namespace: scripts/netns-exec python3 -m pytest ...")


def binary(name):
    return os.path.join(types.build_dir(), "bin", name)


class Processes:
    """Processes a test starts, stopped (SIGTERM by pid, then SIGKILL) at its end."""

    def __init__(self):
        self.started = []

    def start(self, args, **kwargs):
        p = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, **kwargs)
        self.started.append(p)
        return p

    def stop(self, p, timeout_s=20):
        if p.poll() is None:
            p.terminate()
        try:
            return p.wait(timeout_s)
        except subprocess.TimeoutExpired:
            p.kill()
            return p.wait()

    def stop_all(self):
        for p in reversed(self.started):
            self.stop(p)


@pytest.fixture
def processes():
    ps = Processes()
    yield ps
    ps.stop_all()


@pytest.fixture(scope="module")
def sim():
    """orbed-iiwa-sim at 200 Hz, all joints at 0."""
    ps = Processes()
    p = ps.start([binary("orbed-iiwa-sim"), "--period-s", "0.005", "--name", "py-test-sim"],
                 env=dict(os.environ, ORBED_SOURCE_DIR=ROOT))
    yield p
    ps.stop_all()
