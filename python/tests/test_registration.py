"""orbed.registration against closed forms: the Karcher mean of rotations about one axis is the
rotation by the mean angle; two perpendicular rays meet at a known point; misalignment by hand.
(The whole server against orbed-registration's answers: python/integration/test_examples.py.)"""
import math

import numpy as np
import pytest

from orbed import registration, types

lcm = types.lcm_types()


def trial(session_id, index, angle_deg, p):
    m = lcm.alignment_trial_t()
    m.session_id, m.trial_index, m.utime, m.request_id = session_id, index, 100 + index, 7 + index
    half = math.radians(angle_deg) / 2
    m.X_WV.quaternion_wxyz, m.X_WV.position_m = [math.cos(half), 0.0, 0.0, math.sin(half)], p
    return m


def control(command, session_id="s"):
    m = lcm.session_control_t()
    m.command, m.session_id, m.utime, m.request_id = command, session_id, 5, 99
    return m


def test_the_mean_of_rotations_about_one_axis_is_the_rotation_by_the_mean_angle():
    s = registration.Session()
    assert s.on_trial(trial("s", 0, 10, [0, 0, 0])) is None  # no session yet
    s.on_control(control(lcm.session_control_t.START))
    for k, (angle, p) in enumerate([(10, [1, 0, 0]), (20, [0, 2, 0]), (60, [0, 0, 3])]):
        reply = s.on_trial(trial("s", k, angle, p))
        assert reply.num_trials == k + 1 and reply.utime == 100 + k and reply.request_id == 7 + k
    s.on_control(control(lcm.session_control_t.START))  # a repeated START keeps the trials
    mean = s.on_control(control(lcm.session_control_t.COMPUTE))
    assert mean.reason == lcm.registration_t.REASON_COMPUTE and mean.valid and mean.num_trials == 3
    half = math.radians(15)
    assert mean.X_WV_mean.quaternion_wxyz == pytest.approx([math.cos(half), 0, 0, math.sin(half)], abs=1e-12)
    assert mean.X_WV_mean.position_m == pytest.approx([1 / 3, 2 / 3, 1])
    assert mean.rotation_rms_deg == pytest.approx(math.sqrt((20**2 + 10**2 + 30**2) / 3), abs=1e-9)
    assert (mean.rotation_median_deg, mean.rotation_max_deg) == pytest.approx((20, 30), abs=1e-9)
    assert mean.converged and mean.unique
    # Residuals (-20, -10, 30) deg about z: the covariance's zz entry is their mean square [rad^2].
    assert mean.rotation_covariance_rad2[2][2] == pytest.approx(math.radians(1) ** 2 * 1400 / 3)
    s.on_control(control(lcm.session_control_t.RESET))
    assert not s.on_control(control(lcm.session_control_t.COMPUTE)).valid


def landmark_request(origins, directions):
    m = lcm.landmark_request_t()
    m.name, m.num_rays, m.origin_W_m, m.direction_W = "L", len(origins), origins, directions
    return m


def test_two_perpendicular_rays_meet_where_they_cross():
    out = registration.landmark(landmark_request([[0, 1, 0], [1, 0, 0]], [[1, 0, 0], [0, 1, 0]]))
    assert out.valid and out.p_W_m == pytest.approx([1, 1, 0]) and out.gap_m == pytest.approx(0, abs=1e-15)
    assert out.ray_angle_deg == pytest.approx(90)
    # Skew rays 2 m apart in z: the midpoint, 1 m from each.
    out = registration.landmark(landmark_request([[0, 1, 0], [1, 0, 2]], [[1, 0, 0], [0, 1, 0]]))
    assert out.p_W_m == pytest.approx([1, 1, 1]) and out.gap_m == pytest.approx(1)
    assert not registration.landmark(landmark_request([[0, 1, 0], [1, 0, 0]], [[-1, 0, 0], [0, 1, 0]])).valid
    assert not registration.landmark(landmark_request([[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 0, 0]])).valid


def test_misalignment_by_hand():
    m = lcm.misalignment_request_t()
    m.num_pairs, m.p_W_real_m, m.p_W_virtual_m = 2, [[0, 0, 0], [1, 1, 1]], [[0.003, -0.004, 0], [1, 1, 1.01]]
    out = registration.misalignment(m)
    assert out.error_norm_m == pytest.approx([0.005, 0.01])
    assert out.mean_error_W_m == pytest.approx([0.0015, 0.002, 0.005])
    assert out.mean_error_norm_m == pytest.approx(np.linalg.norm([0.0015, 0.002, 0.005]))
    assert out.mean_pair_distance_m == pytest.approx(0.0075)
