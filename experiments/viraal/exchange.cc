#include "experiments/viraal/exchange.h"

#include <algorithm>
#include <stdexcept>

#include "base/units.h"
#include "geometry/misalignment.h"
#include "lcmtypes/contract/conversions.h"

namespace orbed::viraal {

RobotPoints TrialPoints(const RobotPointSet& points, const orbed::alignment_trial_t& trial) {
  return points.At(ToVectorX(trial.joint_position));
}

AlignmentError TrialError(const orbed::pose_t& X_WR, const orbed::alignment_trial_t& trial,
                          const RobotPoints& points) {
  return EvaluateAlignment(FromPose(X_WR), FromPose(trial.X_WV), points);
}

AlignmentError MeanError(const orbed::pose_t& X_WR, const orbed::registration_t& mean,
                         const std::vector<RobotPoints>& session_points,
                         const std::vector<std::vector<Eigen::Vector3d>>& session_real_annotated,
                         const std::vector<std::optional<Eigen::Vector3d>>& session_eyes) {
  AlignmentError error = EvaluateOverConfigurations(FromPose(X_WR), FromPose(mean.X_WV_mean), session_points);
  if (!session_eyes.empty() && session_eyes.size() != session_points.size()) {
    throw std::invalid_argument("MeanError: " + std::to_string(session_eyes.size()) + " trials' eyes for " +
                                std::to_string(session_points.size()) + " trials");
  }
  const bool every_eye =
      !session_eyes.empty() &&
      std::all_of(session_eyes.begin(), session_eyes.end(), [](const auto& eye) { return eye.has_value(); });
  if (every_eye) {
    for (size_t i = 0; i < session_points.size(); ++i) {
      const AlignmentError trial = WithViewer(
          EvaluateAlignment(FromPose(X_WR), FromPose(mean.X_WV_mean), session_points[i]), *session_eyes[i]);
      error.R_WS.insert(error.R_WS.end(), trial.R_WS.begin(), trial.R_WS.end());
    }
  }
  if (session_real_annotated.empty()) return error;
  if (session_real_annotated.size() != session_points.size()) {
    throw std::invalid_argument("MeanError: " + std::to_string(session_real_annotated.size()) +
                                " trials' annotations for " + std::to_string(session_points.size()) +
                                " trials");
  }
  std::vector<Eigen::Vector3d> reals;
  for (size_t i = 0; i < session_real_annotated.size(); ++i) {
    const auto& trial = session_real_annotated[i];
    if (trial.empty()) return error;  // a trial nobody annotated: the truth's pairs alone
    if (trial.size() != session_points[i].p_RL.size()) {
      throw std::invalid_argument(
          "MeanError: trial " + std::to_string(i) + " has " + std::to_string(trial.size()) +
          " annotated landmarks, the scenario scores " + std::to_string(session_points[i].p_RL.size()));
    }
    reals.insert(reals.end(), trial.begin(), trial.end());
  }
  error.p_W_real_annotated = std::move(reals);
  error.p_W_virtual_annotated = error.p_W_virtual;  // X_WV_mean at each trial's q
  error.virtual_annotated = false;
  return error;
}

std::optional<Eigen::Vector3d> AlignmentViewpoint(const orbed::AlignmentTrial& trial) {
  if (trial.annotation.empty()) return std::nullopt;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (const auto& sides : trial.annotation) {
    for (const LandmarkRays& rays : sides) {
      if (rays.origin_W_m.empty()) continue;
      sum += rays.origin_W_m.front();
      ++count;
    }
  }
  if (count == 0) return std::nullopt;
  return Eigen::Vector3d(sum / count);
}

std::vector<std::optional<Eigen::Vector3d>> ViewerEyes(const SessionResult& session) {
  std::vector<std::optional<Eigen::Vector3d>> out;
  for (const TrialResult& t : session.trials) out.push_back(t.viewer_eye_W_m);
  return out;
}

std::vector<orbed::landmark_request_t> LandmarkRequests(const orbed::AlignmentTrial& trial, int64_t utime,
                                                        int64_t first_request_id) {
  std::vector<orbed::landmark_request_t> requests;
  for (size_t l = 0; l < trial.annotation.size(); ++l) {
    for (int side : {0, 1}) {
      const orbed::LandmarkRays& rays = trial.annotation[l][side];
      orbed::landmark_request_t request{};
      request.utime = utime;
      request.request_id = first_request_id + static_cast<int64_t>(requests.size());
      request.name = trial.msg.session_id + "/" + std::to_string(trial.msg.trial_index) +
                     (side == 0 ? "/real/" : "/virtual/") + std::to_string(l);
      request.num_rays = static_cast<int32_t>(rays.origin_W_m.size());
      for (size_t k = 0; k < rays.origin_W_m.size(); ++k) {
        const Eigen::Vector3d& o = rays.origin_W_m[k];
        const Eigen::Vector3d& u = rays.direction_W[k];
        request.origin_W_m.push_back({o.x(), o.y(), o.z()});
        request.direction_W.push_back({u.x(), u.y(), u.z()});
      }
      requests.push_back(request);
    }
  }
  return requests;
}

AlignmentError WithAnnotation(AlignmentError error, const std::vector<orbed::landmark_t>& answers) {
  if (answers.size() % 2 != 0 || answers.size() / 2 != error.p_W_real.size()) {
    throw std::invalid_argument(
        "the user annotated " + std::to_string(answers.size() / 2) + " landmark(s), the scenario scores " +
        std::to_string(error.p_W_real.size()) +
        " (hmd.annotation_landmarks and the scenario's landmarks must be the same list)");
  }
  error.p_W_real_annotated.clear();
  error.p_W_virtual_annotated.clear();
  for (size_t k = 0; k < answers.size(); ++k) {
    const orbed::landmark_t& a = answers[k];
    if (!a.valid)
      throw std::invalid_argument("landmark " + a.name + " could not be triangulated: " + a.reason);
    (k % 2 == 0 ? error.p_W_real_annotated : error.p_W_virtual_annotated).push_back(ToVector3(a.p_W_m));
  }
  return error;
}

orbed::misalignment_request_t MisalignmentRequest(const AlignmentError& error, const std::string& session_id,
                                                  int64_t utime, int64_t request_id) {
  const bool annotated = !error.p_W_real_annotated.empty();
  const std::vector<Eigen::Vector3d>& reals = annotated ? error.p_W_real_annotated : error.p_W_real;
  const std::vector<Eigen::Vector3d>& virtuals = annotated ? error.p_W_virtual_annotated : error.p_W_virtual;
  orbed::misalignment_request_t request{};
  request.utime = utime;
  request.request_id = request_id;
  request.session_id = session_id;
  request.num_pairs = static_cast<int32_t>(reals.size());
  for (size_t k = 0; k < reals.size(); ++k) {
    const Eigen::Vector3d& real = reals[k];
    const Eigen::Vector3d& virt = virtuals[k];
    request.p_W_real_m.push_back({real.x(), real.y(), real.z()});
    request.p_W_virtual_m.push_back({virt.x(), virt.y(), virt.z()});
  }
  return request;
}

ErrorMeasures Measures(const AlignmentError& error, const orbed::misalignment_t& misalignment) {
  ErrorMeasures m;
  m.translation_error_mm = error.centroid_translation_m * 1e3;
  m.rotation_error_deg = error.rotation_rad * kRadToDeg;
  m.base_translation_error_mm = error.base_translation_m * 1e3;
  m.flange_translation_error_mm = error.flange_translation_m * 1e3;
  m.misalignment_mm = misalignment.mean_error_norm_m * 1e3;
  m.misalignment_axes_mm = ToVector3(misalignment.mean_error_W_m) * 1e3;
  m.misalignment_mean_pair_distance_mm = misalignment.mean_pair_distance_m * 1e3;
  m.landmarks = error.p_W_real_annotated.empty() ? "truth" : error.virtual_annotated ? "gaze" : "gaze_real";
  m.truth_misalignment_mm =
      geometry::EvaluateMisalignment(error.p_W_real, error.p_W_virtual).mean_error_norm_m * 1e3;
  if (!error.R_WS.empty()) {
    const bool annotated = !error.p_W_real_annotated.empty();
    m.viewer_axes_mm =
        1e3 * ViewerAxesError(annotated ? error.p_W_real_annotated : error.p_W_real,
                              annotated ? error.p_W_virtual_annotated : error.p_W_virtual, error.R_WS);
  }
  return m;
}

std::vector<std::vector<Eigen::Vector3d>> AnnotatedRealLandmarks(const SessionResult& session) {
  std::vector<std::vector<Eigen::Vector3d>> out;
  for (const TrialResult& t : session.trials) out.push_back(t.annotated_real_W_m);
  return out;
}

TrialResult TrialResultFrom(const orbed::alignment_trial_t& trial, const orbed::pose_t& X_WR,
                            const ErrorMeasures& errors,
                            const std::vector<Eigen::Vector3d>& annotated_real_W_m,
                            const std::optional<Eigen::Vector3d>& viewer_eye_W_m) {
  TrialResult result;
  result.annotated_real_W_m = annotated_real_W_m;
  result.viewer_eye_W_m = viewer_eye_W_m;
  result.index = trial.trial_index;
  for (double q : trial.joint_position) result.q_deg.push_back(q * kRadToDeg);
  result.errors = errors;
  result.user_duration_s = trial.duration_s;
  result.user_id = trial.user_id;
  result.tracking_faults.losses = trial.tracking_losses;
  result.tracking_faults.relocalizations = trial.relocalizations;
  result.tracking_faults.wait_s = trial.tracking_wait_s;
  result.tracking_faults.repeats = trial.alignment_repeats;
  result.X_WV = FromPose(trial.X_WV);
  result.X_WR = FromPose(X_WR);
  return result;
}

orbed::alignment_trial_t TrialMessageFrom(const TrialResult& trial, const SessionResult& session,
                                          int64_t utime) {
  orbed::alignment_trial_t msg{};
  msg.utime = utime;
  msg.session_id = session.session_id;
  msg.trial_index = trial.index;
  msg.display_mode = static_cast<int8_t>(session.display_mode);
  msg.num_mirrors = session.num_mirrors;
  msg.num_joints = static_cast<int32_t>(trial.q_deg.size());
  for (double q : trial.q_deg) msg.joint_position.push_back(q * kDegToRad);
  msg.X_WV = ToPose(trial.X_WV);
  msg.duration_s = trial.user_duration_s;
  msg.user_id = trial.user_id;
  msg.tracking_losses = trial.tracking_faults.losses;
  msg.relocalizations = trial.tracking_faults.relocalizations;
  msg.tracking_wait_s = trial.tracking_faults.wait_s;
  msg.alignment_repeats = trial.tracking_faults.repeats;
  return msg;
}

MeanResult MeanResultFrom(const orbed::registration_t& reg, const ErrorMeasures& errors) {
  MeanResult mean;
  mean.errors = errors;
  mean.X_WV = FromPose(reg.X_WV_mean);
  mean.num_used = reg.num_used;
  mean.rejected_indices.assign(reg.rejected_indices.begin(), reg.rejected_indices.end());
  mean.rotation_rms_deg = reg.rotation_rms_deg;
  mean.translation_rms_mm = reg.translation_rms_m * 1e3;
  mean.iterations = reg.iterations;
  mean.converged = reg.converged;
  mean.unique = reg.unique;
  return mean;
}

}  // namespace orbed::viraal
