#!/usr/bin/python3
"""orbed-registration's answers in Python, in its place on the bus for a ViRAAl run: a trial or COMPUTE gets
the session's REGISTRATION (rotations: Karcher mean from the chordal one, eq. 2; positions: their mean, eq. 3),
a LANDMARK_REQUEST its rays' least-squares point, a MISALIGNMENT_REQUEST its pairs' errors (no checks here).
    PYTHONPATH=python scripts/orbed join /usr/bin/python3 examples/registration_server.py"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python"))
import numpy as np  # noqa: E402
from scipy.spatial.transform import Rotation  # noqa: E402

from orbed import bus, types  # noqa: E402

lcm, b, norm = types.lcm_types(), bus.Bus(), np.linalg.norm
session = {"id": "", "active": False, "trials": {}}  # trials: index -> (R_WV as a Rotation, p_WV [m])


def registration(utime, reason, request_id):
    m, trials = lcm.registration_t(), list(session["trials"].values())
    m.utime, m.session_id, m.reason, m.method, m.request_id = utime, session["id"], reason, 1, request_id
    m.num_trials = m.num_used = len(trials)
    if not trials:
        return m
    R, p = Rotation.concatenate([r for r, _ in trials]), np.array([p for _, p in trials])
    values, vectors = np.linalg.eigh(R.as_quat().T @ R.as_quat() / len(trials))  # chordal mean: top eigenvector
    mean, m.chordal_eigen_gap = Rotation.from_quat(vectors[:, 3]), values[3] - values[2]
    for m.iterations in range(1, 101):  # Karcher: step by the mean residual until the step is < 1e-12 rad
        step = (mean.inv() * R).as_rotvec().mean(axis=0)
        mean = mean * Rotation.from_rotvec(step)
        if norm(step) < 1e-12:
            break
    r, e, q = (mean.inv() * R).as_rotvec(), p - p.mean(axis=0), mean.as_quat()[[3, 0, 1, 2]]
    m.X_WV_mean.position_m, m.X_WV_mean.quaternion_wxyz = list(p.mean(axis=0)), list(q if q[0] >= 0 else -q)
    a = norm(r, axis=1)
    m.valid, m.converged, m.unique = True, bool(norm(step) < 1e-12), bool(a.max() < np.pi / 2 - 1e-9)
    m.rotation_rms_deg, m.rotation_median_deg, m.rotation_max_deg = np.degrees([np.sqrt(np.mean(a**2)), np.median(a), a.max()])
    m.rotation_covariance_rad2, m.translation_covariance_m2 = (r.T @ r / len(r)).tolist(), (e.T @ e / len(e)).tolist()
    m.translation_rms_m = np.sqrt(np.mean(np.sum(e**2, axis=1)))
    return m


def on_control(channel, m):
    if m.command == m.START and not (session["active"] and session["id"] == m.session_id):
        session.update(id=m.session_id, active=True, trials={})
    elif m.session_id == session["id"] and m.command in (m.RESET, m.STOP, m.COMPUTE):
        session.update({m.RESET: {"trials": {}}, m.STOP: {"active": False}}.get(m.command, {}))
        if m.command == m.COMPUTE:
            b.publish("REGISTRATION", registration(m.utime, lcm.registration_t.REASON_COMPUTE, m.request_id))


def on_trial(channel, m):
    if session["active"] and m.session_id == session["id"]:
        q = np.roll(m.X_WV.quaternion_wxyz, -1)  # (w, x, y, z) to scipy's (x, y, z, w)
        session["trials"].setdefault(m.trial_index, (Rotation.from_quat(q), np.array(m.X_WV.position_m)))
        b.publish("REGISTRATION", registration(m.utime, lcm.registration_t.REASON_TRIAL, m.request_id))


def on_landmark(channel, m):  # the point x closest to the rays h_i + s u_i: (sum P_i) x = sum P_i h_i
    h, u = np.array(m.origin_W_m), np.array(m.direction_W) / norm(m.direction_W, axis=1)[:, None]
    P = np.eye(3) - np.einsum("ni,nj->nij", u, u)
    x = h[0] + np.linalg.solve(P.sum(axis=0), np.einsum("nij,nj->i", P, h - h[0]))
    depth, angles = np.einsum("ni,ni->n", x - h, u), [np.arctan2(norm(np.cross(a, c)), a @ c) for i, a in enumerate(u) for c in u[i + 1:]]
    out = lcm.landmark_t()
    out.utime, out.request_id, out.name, out.p_W_m, out.ray_angle_deg = m.utime, m.request_id, m.name, list(x), np.degrees(max(angles))
    out.gap_m = np.sqrt(np.mean(np.sum((x - h - depth[:, None] * u) ** 2, axis=1)))
    out.valid = bool(np.degrees(max(min(a, np.pi - a) for a in angles)) >= 2.0 and depth.min() >= 0)
    out.reason = "" if out.valid else "near-parallel rays, or the point is behind a ray's origin"
    b.publish("LANDMARK", out)


def on_misalignment(channel, m):
    e, out = np.abs(np.array(m.p_W_virtual_m) - np.array(m.p_W_real_m)), lcm.misalignment_t()
    out.utime, out.request_id, out.session_id, out.valid, out.num_pairs = m.utime, m.request_id, m.session_id, True, m.num_pairs
    out.error_W_m, out.error_norm_m, out.mean_error_W_m = e.tolist(), list(norm(e, axis=1)), list(e.mean(axis=0))
    out.mean_error_norm_m, out.mean_pair_distance_m = norm(out.mean_error_W_m), np.mean(out.error_norm_m)
    b.publish("MISALIGNMENT", out)


for name, callback in (("SESSION_CONTROL", on_control), ("ALIGNMENT_TRIAL", on_trial),
                       ("LANDMARK_REQUEST", on_landmark), ("MISALIGNMENT_REQUEST", on_misalignment)):
    b.subscribe(name, getattr(lcm, name.lower() + "_t"), callback)
while True:
    b.handle()
