#include "viraal/exchange.h"

#include "base/units.h"
#include "procs/common/conversions.h"

namespace orbed::viraal {

RobotPoints TrialPoints(const RobotPointSet& points, const orbed::alignment_trial_t& trial) {
  return points.At(ToVectorX(trial.joint_position));
}

AlignmentError TrialError(const orbed::pose_t& X_WR, const orbed::alignment_trial_t& trial,
                          const RobotPoints& points) {
  return EvaluateAlignment(FromPose(X_WR), FromPose(trial.X_WV), points);
}

AlignmentError MeanError(const orbed::pose_t& X_WR, const orbed::registration_t& mean,
                         const std::vector<RobotPoints>& session_points) {
  return EvaluateOverConfigurations(FromPose(X_WR), FromPose(mean.X_WV_mean), session_points);
}

orbed::misalignment_request_t MisalignmentRequest(const AlignmentError& error, const std::string& session_id,
                                                  int64_t utime, int64_t request_id) {
  orbed::misalignment_request_t request{};
  request.utime = utime;
  request.request_id = request_id;
  request.session_id = session_id;
  request.num_pairs = static_cast<int32_t>(error.p_W_real.size());
  for (size_t k = 0; k < error.p_W_real.size(); ++k) {
    const Eigen::Vector3d& real = error.p_W_real[k];
    const Eigen::Vector3d& virt = error.p_W_virtual[k];
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
  return m;
}

TrialResult TrialResultFrom(const orbed::alignment_trial_t& trial, const orbed::pose_t& X_WR,
                            const ErrorMeasures& errors) {
  TrialResult result;
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
