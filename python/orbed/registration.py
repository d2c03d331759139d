"""orbed.registration: the answers orbed-registration gives, in Python, without a bus (the example
examples/registration_server.py puts them on one). Pure; not thread-safe (one session).

- Session: SESSION_CONTROL START / RESET / STOP / COMPUTE and ALIGNMENT_TRIALs; a trial and a COMPUTE
  are answered with the session's REGISTRATION (method Karcher, no robust rejection, no model centroid:
  orbed-registration's defaults). A repeated START of the active session keeps its trials, a repeated
  trial index keeps the first trial (both are answered again), as the C++ server does.
- mean_se3: rotations by the Karcher (geodesic L2) mean started from the chordal one (paper eq. 2;
  geometry/rotation_mean.h: step by the mean residual log(R_mean^T R_i) until the step is below
  1e-12 rad, at most 100 steps), positions by their mean (eq. 3); the dispersion of
  geometry/se3_mean.h (residual angles' RMS, median, max [deg], covariances about the mean).
- landmark: the point closest in least squares to N >= 2 gaze rays h_i + s u_i (geometry/triangulation.h),
  (sum P_i) x = sum P_i h_i with P_i = I - u_i u_i^T; invalid when the lines are within 2 deg of
  parallel or the point is behind an origin.
- misalignment: per pair |p_virtual - p_real| per axis [m] and its norm, their means, and the norm of
  the mean per-axis error (paper Table 1; geometry/misalignment.h).
Requests are not validated here (orbed-registration checks them and counts refusals).
"""
import numpy as np
from scipy.spatial.transform import Rotation

from orbed import types

STEP_TOLERANCE_RAD = 1e-12
MAX_ITERATIONS = 100
MIN_RAY_ANGLE_DEG = 2.0


def mean_se3(R, p):
    """The mean of the poses (R_WV_i: a scipy Rotation of N, p_WV_i: N x 3 [m]) as a dict of
    registration_t's fields."""
    values, vectors = np.linalg.eigh(R.as_quat().T @ R.as_quat() / len(R))  # chordal: the top eigenvector
    mean, out = Rotation.from_quat(vectors[:, 3]), {"chordal_eigen_gap": values[3] - values[2]}
    for out["iterations"] in range(1, MAX_ITERATIONS + 1):
        step = (mean.inv() * R).as_rotvec().mean(axis=0)
        mean = mean * Rotation.from_rotvec(step)
        if np.linalg.norm(step) < STEP_TOLERANCE_RAD:
            break
    r, e, q = (mean.inv() * R).as_rotvec(), p - p.mean(axis=0), mean.as_quat()[[3, 0, 1, 2]]
    a = np.linalg.norm(r, axis=1)
    out.update(position_m=list(p.mean(axis=0)), quaternion_wxyz=list(q if q[0] >= 0 else -q),
               converged=bool(np.linalg.norm(step) < STEP_TOLERANCE_RAD), unique=bool(a.max() < np.pi / 2 - 1e-9),
               rotation_rms_deg=np.degrees(np.sqrt(np.mean(a**2))), rotation_median_deg=np.degrees(np.median(a)),
               rotation_max_deg=np.degrees(a.max()), rotation_covariance_rad2=(r.T @ r / len(r)).tolist(),
               translation_rms_m=np.sqrt(np.mean(np.sum(e**2, axis=1))),
               translation_covariance_m2=(e.T @ e / len(e)).tolist())
    return out


class Session:
    """One registration session's state and its REGISTRATIONs (see the module doc)."""

    def __init__(self):
        self.lcm = types.lcm_types()
        self.id, self.active, self.trials = "", False, {}  # trials: index -> (R_WV quaternion xyzw, p_WV [m])

    def registration(self, utime, reason, request_id):
        m = self.lcm.registration_t()
        m.utime, m.session_id, m.reason, m.request_id = utime, self.id, reason, request_id
        m.method, m.num_trials, m.num_used = m.METHOD_KARCHER, len(self.trials), len(self.trials)
        if self.trials:
            q, p = zip(*self.trials.values())
            fields = mean_se3(Rotation.from_quat(q), np.array(p))
            m.X_WV_mean.position_m = fields.pop("position_m")
            m.X_WV_mean.quaternion_wxyz = fields.pop("quaternion_wxyz")
            m.valid = True
            for name, value in fields.items():
                setattr(m, name, value)
        return m

    def on_control(self, m):
        """The REGISTRATION a SESSION_CONTROL asks for (COMPUTE), else None."""
        if m.command == m.START and not (self.active and self.id == m.session_id):
            self.id, self.active, self.trials = m.session_id, True, {}
        elif m.session_id == self.id and m.command == m.RESET:
            self.trials = {}
        elif m.session_id == self.id and m.command == m.STOP:
            self.active = False
        elif m.session_id == self.id and m.command == m.COMPUTE:
            return self.registration(m.utime, self.lcm.registration_t.REASON_COMPUTE, m.request_id)
        return None

    def on_trial(self, m):
        """The REGISTRATION answering an ALIGNMENT_TRIAL of the active session, else None."""
        if not (self.active and m.session_id == self.id):
            return None
        w, x, y, z = m.X_WV.quaternion_wxyz
        self.trials.setdefault(m.trial_index, ((x, y, z, w), tuple(m.X_WV.position_m)))
        return self.registration(m.utime, self.lcm.registration_t.REASON_TRIAL, m.request_id)


def landmark(m):
    """The LANDMARK answering a LANDMARK_REQUEST."""
    h = np.array(m.origin_W_m)
    u = np.array(m.direction_W) / np.linalg.norm(m.direction_W, axis=1)[:, None]
    angles = [np.arctan2(np.linalg.norm(np.cross(a, c)), a @ c) for i, a in enumerate(u) for c in u[i + 1:]]
    out = types.lcm_types().landmark_t()
    out.utime, out.request_id, out.name = m.utime, m.request_id, m.name
    out.ray_angle_deg = np.degrees(max(angles))
    if np.degrees(max(min(a, np.pi - a) for a in angles)) < MIN_RAY_ANGLE_DEG:
        out.reason = f"rays are near-parallel: largest angle between lines below {MIN_RAY_ANGLE_DEG} deg"
        return out
    P = np.eye(3) - np.einsum("ni,nj->nij", u, u)
    x = h[0] + np.linalg.solve(P.sum(axis=0), np.einsum("nij,nj->i", P, h - h[0]))
    depth = np.einsum("ni,ni->n", x - h, u)
    out.p_W_m, out.gap_m = list(x), np.sqrt(np.mean(np.sum((x - h - depth[:, None] * u) ** 2, axis=1)))
    out.valid = bool(depth.min() >= 0)
    out.reason = "" if out.valid else "the point is behind the origin of a ray"
    return out


def misalignment(m):
    """The MISALIGNMENT answering a MISALIGNMENT_REQUEST."""
    e = np.abs(np.array(m.p_W_virtual_m) - np.array(m.p_W_real_m))
    out = types.lcm_types().misalignment_t()
    out.utime, out.request_id, out.session_id, out.valid, out.num_pairs = (m.utime, m.request_id, m.session_id,
                                                                          True, m.num_pairs)
    out.error_W_m, out.error_norm_m = e.tolist(), list(np.linalg.norm(e, axis=1))
    out.mean_error_W_m = list(e.mean(axis=0))
    out.mean_error_norm_m, out.mean_pair_distance_m = np.linalg.norm(out.mean_error_W_m), np.mean(out.error_norm_m)
    return out
