#!/usr/bin/python3
"""A registration server in Python, in orbed-registration's place on the bus for a ViRAAl run: sessions and
trials on SESSION_CONTROL and ALIGNMENT_TRIAL answered with the session's SE(3) mean on REGISTRATION,
gaze rays triangulated (LANDMARK_REQUEST -> LANDMARK), landmark pairs compared (MISALIGNMENT_REQUEST ->
MISALIGNMENT); the answers themselves are orbed.registration's.

    scripts/netns-exec bash -c 'build/bin/orbed-iiwa-sim & build/bin/orbed-hmd &
      PYTHONPATH=python /usr/bin/python3 examples/registration_server.py &
      build/bin/orbed-scenario --run-id pinned --results-dir logs/viraal-py; kill $(jobs -p)'
"""
import os
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python"))
from orbed import bus, registration, types  # noqa: E402


def main():
    lcm, b, session = types.lcm_types(), bus.Bus(), registration.Session()

    def answer(channel, produce):
        def callback(_, message):
            reply = produce(message)
            if reply is not None:
                b.publish(channel, reply)
        return callback

    b.subscribe("SESSION_CONTROL", lcm.session_control_t, answer("REGISTRATION", session.on_control))
    b.subscribe("ALIGNMENT_TRIAL", lcm.alignment_trial_t, answer("REGISTRATION", session.on_trial))
    b.subscribe("LANDMARK_REQUEST", lcm.landmark_request_t, answer("LANDMARK", registration.landmark))
    b.subscribe("MISALIGNMENT_REQUEST", lcm.misalignment_request_t, answer("MISALIGNMENT", registration.misalignment))
    print("registration server: answering on REGISTRATION, LANDMARK and MISALIGNMENT", flush=True)
    beat = 0.0
    while True:
        b.handle(timeout_s=1.0)  # refusals are counted in b.refused, logged and sent on the heartbeat
        if time.monotonic() >= beat:  # PROCESS_STATUS at 1 Hz, as orbed's processes (orbed-monitor shows it)
            b.publish("PROCESS_STATUS", b.status("py-registration"))
            beat = time.monotonic() + 1.0


if __name__ == "__main__":
    main()
