#pragma once
/// @file
/// The one check of ALIGNMENT_TRIAL (alignment_trial_t), which the registration server and the
/// conductor both read: the message's own contract, before either applies its own rules (the
/// server: the active session, unique indices, the session's mode; the conductor: the trial it
/// asked for, the robot model's joint count and limits).
///
/// The contract:
///   - session_id: 1..kMaxSessionIdLength bytes; trial_index in [0, kMaxTrialsPerSession);
///   - display_mode MODE_AR with num_mirrors 0, or MODE_AR_REFLECTIVE with 1..kMaxMirrors;
///   - num_joints == joint_position's length, at most `max_joints`; every joint angle finite [rad];
///   - X_WV: finite position within kMaxAlignmentCoordinate_m of the origin, unit quaternion;
///   - duration_s: finite and >= 0;
///   - tracking faults (contract change 2): tracking_losses, relocalizations, alignment_repeats
///     >= 0; tracking_wait_s finite, >= 0 and at most duration_s (the wait is part of it).
///   - the landmark annotation (contract change 5): num_annotation_rays in [0, kMaxAnnotationRays]
///     and equal to the four arrays' lengths; landmark indices in [0, kMaxAnnotatedLandmarks), sides
///     ANNOTATION_REAL or ANNOTATION_VIRTUAL; origins finite within kMaxAlignmentCoordinate_m;
///     directions finite with a norm within 1e-6 of 1; with any rays, every landmark 0..L-1 (L = the
///     largest index + 1) has at least 2 rays on each side.
/// Refusal keys are the field names (session_id, trial_index, display_mode, num_mirrors,
/// num_joints, joint_position, X_WV, duration_s), tracking_faults for the four fault fields and
/// annotation for the five annotation fields;
/// processes count them as "<channel>/<key>".
///
/// Threading: pure functions.

#include <array>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Geometry>
#include <orbed/alignment_trial_t.hpp>

#include "lcmtypes/contract/session_control.h"

namespace orbed {

/// A base pose farther than this from the world origin is not an operating room [m].
inline constexpr double kMaxAlignmentCoordinate_m = 1e4;

/// The most trials one session holds (orbed-scenario's --trials goes up to 1000). Bounds the work a
/// trial index costs: the headset rebuilds a session's map by replaying its earlier walks.
inline constexpr std::int32_t kMaxTrialsPerSession = 1000;

/// Bounds of the landmark annotation: rays per trial, landmarks per trial.
inline constexpr int kMaxAnnotationRays = 256;
inline constexpr int kMaxAnnotatedLandmarks = 16;

/// The gaze rays aimed at one landmark on one side, in the headset's map [m].
struct LandmarkRays {
  std::vector<Eigen::Vector3d> origin_W_m;
  std::vector<Eigen::Vector3d> direction_W;
};

/// A checked ALIGNMENT_TRIAL: the message (as received) with its pose and joint vector decoded.
struct AlignmentTrial {
  orbed::alignment_trial_t msg;
  Eigen::Isometry3d X_WV{Eigen::Isometry3d::Identity()};
  Eigen::VectorXd q_rad;
  /// The annotation by landmark: [l][0] the real robot's rays, [l][1] the virtual one's; empty =
  /// not annotated.
  std::vector<std::array<LandmarkRays, 2>> annotation;
};

std::variant<AlignmentTrial, Refusal> CheckAlignmentTrial(const orbed::alignment_trial_t& msg,
                                                          int max_joints);

}  // namespace orbed
