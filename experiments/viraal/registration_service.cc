#include "experiments/viraal/registration_service.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "geometry/misalignment.h"
#include "geometry/se3_mean.h"
#include "lcmtypes/contract/alignment_trial.h"
#include "lcmtypes/contract/conversions.h"
#include "lcmtypes/contract/requests.h"
#include "lcmtypes/contract/session_control.h"
#include "lcmtypes/contract/validation.h"

namespace orbed::registration {

RegistrationService::RegistrationService(RegistrationServiceOptions options, RejectFn reject)
    : options_(std::move(options)), reject_(std::move(reject)) {}

void RegistrationService::Reject(const std::string& key, const std::string& reason) const {
  if (reject_) reject_(key, reason);
}

std::optional<orbed::registration_t> RegistrationService::HandleSessionControl(
    const orbed::session_control_t& msg) {
  const auto checked = CheckSessionControl(msg);
  if (const auto* refusal = std::get_if<Refusal>(&checked)) {
    Reject("SESSION_CONTROL/" + refusal->key, refusal->reason);
    return std::nullopt;
  }
  const SessionCommand& command = std::get<SessionCommand>(checked);
  using Kind = SessionCommand::Kind;
  // A trial request is for the user, not for the server.
  if (command.kind == Kind::kRequestTrial) return std::nullopt;
  // A request acted on before: its first answer, and nothing changes.
  if (const auto* answer = command_answers_.Find(command.request_id)) return *answer;
  std::optional<orbed::registration_t> answer;
  if (command.kind == Kind::kStart) {
    // A repeated START of the active session changes nothing (its trials stay).
    if (!(active_ && command.RepeatsStartOf(session_id_, display_mode_, num_mirrors_))) {
      has_session_ = true;
      active_ = true;
      session_id_ = command.session_id;
      display_mode_ = command.display_mode;
      num_mirrors_ = command.num_mirrors;
      method_ = command.method;
      trials_.clear();
      latest_trial_state_.reset();
      last_utime_ = command.utime;
      ++changes_;
    }
  } else if (!has_session_ || command.session_id != session_id_) {
    Reject("SESSION_CONTROL/session", std::string("SESSION_CONTROL ") + SessionCommandName(command.kind) +
                                          " for session '" + command.session_id + "', but the session is '" +
                                          (has_session_ ? session_id_ : std::string("<none>")) + "'");
    return std::nullopt;  // refused: not remembered, so a retry is judged afresh
  } else if (command.kind == Kind::kReset) {
    if (!trials_.empty()) {  // an empty RESET changes nothing
      trials_.clear();
      latest_trial_state_.reset();
      last_utime_ = command.utime;
      ++changes_;
    }
  } else if (command.kind == Kind::kStop) {
    if (active_) {  // a repeated STOP changes nothing
      active_ = false;
      last_utime_ = command.utime;
      ++changes_;
    }
  } else {  // COMPUTE
    answer = MakeState(command.utime, orbed::registration_t::REASON_COMPUTE, command.request_id);
  }
  command_answers_.Remember(command.request_id, answer);
  return answer;
}

const RegistrationService::Trial* RegistrationService::FindRepeat(const orbed::alignment_trial_t& msg) const {
  if (!has_session_ || msg.session_id != session_id_) return nullptr;
  for (const Trial& t : trials_) {
    if (t.trial_index == msg.trial_index && t.utime == msg.utime && t.request_id == msg.request_id &&
        std::equal(t.X_WV.position_m, t.X_WV.position_m + 3, msg.X_WV.position_m) &&
        std::equal(t.X_WV.quaternion_wxyz, t.X_WV.quaternion_wxyz + 4, msg.X_WV.quaternion_wxyz)) {
      return &t;
    }
  }
  return nullptr;
}

std::optional<orbed::registration_t> RegistrationService::HandleTrial(const orbed::alignment_trial_t& msg) {
  if (const Trial* repeat = FindRepeat(msg)) {
    if (repeat == &trials_.back() && latest_trial_state_) return latest_trial_state_;
    return std::nullopt;
  }
  if (!active_ || msg.session_id != session_id_) {
    Reject("ALIGNMENT_TRIAL/session",
           "trial " + std::to_string(msg.trial_index) + " for session '" + msg.session_id + "', but " +
               (active_ ? "the active session is '" + session_id_ + "'"
                        : std::string("no session is active (send SESSION_CONTROL START)")));
    return std::nullopt;
  }
  const auto checked = CheckAlignmentTrial(msg, options_.max_joints);
  if (const auto* refusal = std::get_if<Refusal>(&checked)) {
    Reject("ALIGNMENT_TRIAL/" + refusal->key, refusal->reason);
    return std::nullopt;
  }
  if (msg.display_mode != display_mode_) {
    Reject("ALIGNMENT_TRIAL/session_mode", "trial " + std::to_string(msg.trial_index) + " has display_mode " +
                                               std::to_string(msg.display_mode) + " but the session's is " +
                                               std::to_string(display_mode_));
    return std::nullopt;
  }
  for (const Trial& t : trials_) {
    if (t.trial_index == msg.trial_index) {
      Reject("ALIGNMENT_TRIAL/trial_index", "trial_index " + std::to_string(msg.trial_index) +
                                                " already received in session '" + session_id_ + "'");
      return std::nullopt;
    }
  }
  if (static_cast<int>(trials_.size()) >= options_.max_trials_per_session) {
    Reject("ALIGNMENT_TRIAL/capacity",
           "session '" + session_id_ + "' already holds " + std::to_string(trials_.size()) + " trials");
    return std::nullopt;
  }
  trials_.push_back({msg.trial_index, QuaternionFromWxyz(msg.X_WV.quaternion_wxyz).normalized(),
                     ToVector3(msg.X_WV.position_m), msg.utime, msg.request_id, msg.X_WV});
  last_utime_ = msg.utime;
  ++changes_;
  latest_trial_state_ = MakeState(msg.utime, orbed::registration_t::REASON_TRIAL, msg.request_id);
  return latest_trial_state_;
}

std::optional<orbed::registration_t> RegistrationService::PeriodicState() const {
  if (!has_session_) return std::nullopt;
  return MakeState(last_utime_, orbed::registration_t::REASON_PERIODIC, 0);
}

orbed::registration_t RegistrationService::MakeState(int64_t utime, int8_t reason, int64_t request_id) const {
  orbed::registration_t out{};
  out.utime = utime;
  out.request_id = request_id;
  out.session_id = session_id_;
  out.reason = reason;
  out.method = method_;
  out.valid = false;
  out.X_WV_mean = ToPose(Eigen::Isometry3d::Identity());
  out.num_trials = static_cast<int32_t>(trials_.size());
  out.num_used = 0;
  out.num_rejected = 0;
  if (trials_.empty()) return out;

  std::vector<Eigen::Quaterniond> q;
  std::vector<Eigen::Vector3d> p;
  for (const Trial& t : trials_) {
    q.push_back(t.quat_WV);
    p.push_back(t.p_WV);
  }
  geometry::Se3MeanOptions options;
  options.method = static_cast<geometry::AveragingMethod>(method_);
  options.p_VC = options_.p_VC;
  options.outlier = options_.outlier;
  const geometry::Se3MeanResult mean = geometry::ComputeSe3Mean(q, p, options);
  if (!mean.valid) return out;  // cannot happen for validated trials; left invalid if it does

  Eigen::Isometry3d X_WV_mean = Eigen::Isometry3d::Identity();
  X_WV_mean.linear() = mean.q_WV_mean.toRotationMatrix();
  X_WV_mean.translation() = mean.p_WV_mean;
  out.valid = true;
  out.X_WV_mean = ToPose(X_WV_mean);
  out.num_used = mean.dispersion.num_used;
  for (const geometry::RejectedTrial& r : mean.rejected)
    out.rejected_indices.push_back(trials_[r.index].trial_index);
  out.num_rejected = static_cast<int32_t>(out.rejected_indices.size());
  out.rotation_rms_deg = mean.dispersion.rotation_rms_deg;
  out.rotation_median_deg = mean.dispersion.rotation_median_deg;
  out.rotation_max_deg = mean.dispersion.rotation_max_deg;
  FromMatrix3(mean.dispersion.rotation_covariance_rad2, out.rotation_covariance_rad2);
  out.translation_rms_m = mean.dispersion.translation_rms_m;
  FromMatrix3(mean.dispersion.translation_covariance_m2, out.translation_covariance_m2);
  out.iterations = mean.iterations;
  out.converged = mean.converged;
  out.unique = mean.unique;
  out.chordal_eigen_gap = mean.chordal_eigen_gap;
  return out;
}

orbed::landmark_t RegistrationService::HandleLandmarkRequest(const orbed::landmark_request_t& msg) {
  orbed::landmark_t out{};
  out.utime = msg.utime;
  out.request_id = msg.request_id;
  out.name = msg.name;
  out.valid = false;
  const auto checked = CheckLandmarkRequest(msg, options_.max_rays);
  const auto* refusal = std::get_if<Refusal>(&checked);
  std::string problem = refusal ? refusal->reason : "";
  if (problem.empty()) {
    const LandmarkRequest& request = std::get<LandmarkRequest>(checked);
    const geometry::TriangulationResult r =
        geometry::TriangulateRays(request.origin_W_m, request.direction_W, options_.triangulation);
    FromVector3(r.p_W, out.p_W_m);
    out.ray_angle_deg = r.ray_angle_deg;
    out.gap_m = r.gap_m;
    out.valid = r.valid;
    if (!r.valid) problem = "LANDMARK_REQUEST '" + msg.name + "': " + r.reason;
  }
  if (!problem.empty()) {
    out.reason = problem;
    Reject("LANDMARK_REQUEST/invalid", problem);
  }
  return out;
}

orbed::misalignment_t RegistrationService::HandleMisalignmentRequest(
    const orbed::misalignment_request_t& msg) {
  orbed::misalignment_t out{};
  out.utime = msg.utime;
  out.request_id = msg.request_id;
  out.session_id = msg.session_id;
  out.valid = false;
  out.num_pairs = 0;
  const auto checked = CheckMisalignmentRequest(msg, options_.max_pairs);
  const auto* refusal = std::get_if<Refusal>(&checked);
  std::string problem = refusal ? refusal->reason : "";
  if (problem.empty()) {
    const MisalignmentRequest& request = std::get<MisalignmentRequest>(checked);
    const geometry::MisalignmentResult r =
        geometry::EvaluateMisalignment(request.p_W_real_m, request.p_W_virtual_m);
    if (r.valid) {
      out.valid = true;
      out.num_pairs = static_cast<int32_t>(r.error_W_m.size());
      for (size_t k = 0; k < r.error_W_m.size(); ++k) {
        out.error_W_m.push_back({r.error_W_m[k].x(), r.error_W_m[k].y(), r.error_W_m[k].z()});
        out.error_norm_m.push_back(r.error_norm_m[k]);
      }
      FromVector3(r.mean_error_W_m, out.mean_error_W_m);
      out.mean_error_norm_m = r.mean_error_norm_m;
      out.mean_pair_distance_m = r.mean_pair_distance_m;
    } else {
      problem = "MISALIGNMENT_REQUEST: " + r.reason;
    }
  }
  if (!problem.empty()) {
    out.reason = problem;
    Reject("MISALIGNMENT_REQUEST/invalid", problem);
  }
  return out;
}

}  // namespace orbed::registration
