#pragma once
/// @file
/// The ViRAAl protocol's messages turned into its results, one definition for every program that
/// scores a run: the conductor (orbed-scenario, from the bus) and the offline study (orbed-user-study,
/// from the same messages built in-process). Given the same messages, both get the same numbers.
///
///   trial:  ALIGNMENT_TRIAL (q, X_WV) and the truth X_WR (ROBOT_STATE) → TrialError (point errors
///           and the truth's landmark pairs); if the user annotated the landmarks (the message's
///           gaze rays), LandmarkRequests → orbed-registration's LANDMARKs → WithAnnotation: the
///           triangulated pairs (the paper's measurement, Sec. III-B); → the pairs as a
///           MISALIGNMENT_REQUEST (annotated ones if any, else the truth's) → MISALIGNMENT →
///           TrialResultFrom;
///   mean:   REGISTRATION (reason COMPUTE, X_WV_mean) → MeanError over the session's configurations
///           (with the real landmarks the user annotated in the session's trials, when every trial
///           has them) → MISALIGNMENT_REQUEST → MISALIGNMENT → MeanResultFrom.
///
/// Frames and units as in metrics.h: W world, R real base, V virtual base; messages in SI, results in
/// mm and deg as results.h names them.
/// Threading: pure functions.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <orbed/alignment_trial_t.hpp>
#include <orbed/landmark_request_t.hpp>
#include <orbed/landmark_t.hpp>
#include <orbed/misalignment_request_t.hpp>
#include <orbed/misalignment_t.hpp>
#include <orbed/pose_t.hpp>
#include <orbed/registration_t.hpp>

#include "experiments/viraal/metrics.h"
#include "experiments/viraal/results.h"
#include "lcmtypes/contract/alignment_trial.h"

namespace orbed::viraal {

/// The robot points at the trial's own q (its joint_position [rad]).
RobotPoints TrialPoints(const RobotPointSet& points, const orbed::alignment_trial_t& trial);

/// The errors of a trial's X_WV at its points against the truth X_WR (as the messages carry them).
AlignmentError TrialError(const orbed::pose_t& X_WR, const orbed::alignment_trial_t& trial,
                          const RobotPoints& points);

/// The errors of a session mean (REGISTRATION.X_WV_mean) over the session's trial points. Nobody
/// annotates a mean: when every trial of the session has the real robot's landmarks as the user
/// annotated them (session_real_annotated[i] = trial i's TrialResult::annotated_real_W_m, in the
/// headset's map), the mean is measured against those, its virtual landmarks placed by X_WV_mean
/// at each trial's q (virtual_annotated = false); otherwise (a trial without annotation) with the
/// truth's pairs alone. Throws std::invalid_argument when session_real_annotated is not empty and
/// its size or a trial's landmark count does not match.
/// The viewer frames: when session_eyes (ViewerEyes) has an eye for every trial, the pairs at trial
/// i's q get trial i's frame (ViewerFrame from its eye to the centroid of its real landmarks):
/// the mean's error as each trial's viewer would see it. Otherwise none (R_WS empty). Throws
/// std::invalid_argument when session_eyes is not empty and its size does not match.
AlignmentError MeanError(const orbed::pose_t& X_WR, const orbed::registration_t& mean,
                         const std::vector<RobotPoints>& session_points,
                         const std::vector<std::vector<Eigen::Vector3d>>& session_real_annotated = {},
                         const std::vector<std::optional<Eigen::Vector3d>>& session_eyes = {});

/// Where the person stood when aligning, in the headset's map [m]: the mean of the origins of the
/// first gaze ray aimed at each landmark on each side. The emulated person annotates from where
/// they aligned first, then from a second position (hmd_emulator/viraal_trial.h), so these rays
/// start at the alignment viewpoint, as the headset estimated its head there. Unset without
/// annotation.
std::optional<Eigen::Vector3d> AlignmentViewpoint(const orbed::AlignmentTrial& trial);

/// Each trial's viewer_eye_W_m, in order: MeanError's session_eyes.
std::vector<std::optional<Eigen::Vector3d>> ViewerEyes(const SessionResult& session);

/// The annotation of a checked trial (lcmtypes/contract/alignment_trial.h) as LANDMARK_REQUESTs: for each
/// landmark l, the real robot's rays then the virtual one's, named "<session>/<index>/real/<l>" and
/// ".../virtual/<l>", request ids first_request_id, +1, ... Empty for a trial without annotation.
std::vector<orbed::landmark_request_t> LandmarkRequests(const orbed::AlignmentTrial& trial, int64_t utime,
                                                        int64_t first_request_id);

/// `error` with the annotated pairs from the LANDMARK answers to LandmarkRequests(), in its order.
/// Throws std::invalid_argument when an answer is invalid (naming its landmark and reason), or when
/// there is an odd number of answers, or as many landmarks as error's truth pairs do not match
/// (the user annotated other landmarks than the scenario scores).
AlignmentError WithAnnotation(AlignmentError error, const std::vector<orbed::landmark_t>& answers);

/// The landmark pairs of `error` as a request to orbed-registration: the annotated pairs when there
/// are, else the truth's.
orbed::misalignment_request_t MisalignmentRequest(const AlignmentError& error, const std::string& session_id,
                                                  int64_t utime, int64_t request_id);

/// The measures of one pose: point errors from `error`, the paper's misalignment from `misalignment`
/// (landmarks "gaze" when `error` has annotated pairs, "gaze_real" when only their real side was
/// annotated), truth_misalignment_mm from error's truth
/// pairs (geometry/misalignment.h, as orbed-registration computes it); viewer_axes_mm, when error
/// has viewer frames, from the same pairs as the misalignment (ViewerAxesError).
ErrorMeasures Measures(const AlignmentError& error, const orbed::misalignment_t& misalignment);

/// One row of results.json for a trial; `annotated_real_W_m`: error's p_W_real_annotated;
/// `viewer_eye_W_m`: error's p_WE.
TrialResult TrialResultFrom(const orbed::alignment_trial_t& trial, const orbed::pose_t& X_WR,
                            const ErrorMeasures& errors,
                            const std::vector<Eigen::Vector3d>& annotated_real_W_m = {},
                            const std::optional<Eigen::Vector3d>& viewer_eye_W_m = std::nullopt);

/// Each trial's annotated_real_W_m, in order: MeanError's session_real_annotated.
std::vector<std::vector<Eigen::Vector3d>> AnnotatedRealLandmarks(const SessionResult& session);

/// The ALIGNMENT_TRIAL a row of results.json came from (TrialResultFrom's inverse, up to the round
/// trips of X_WV through a rotation matrix and q through degrees), stamped `utime`: how a resumed
/// conductor hands the trials it kept back to the registration server and the headset.
orbed::alignment_trial_t TrialMessageFrom(const TrialResult& trial, const SessionResult& session,
                                          int64_t utime);

/// The "mean" of a session in results.json.
MeanResult MeanResultFrom(const orbed::registration_t& mean, const ErrorMeasures& errors);

}  // namespace orbed::viraal
