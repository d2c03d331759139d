#include "lcmtypes/contract/alignment_trial.h"

#include <cmath>

#include "lcmtypes/contract/conversions.h"
#include "lcmtypes/contract/validation.h"

namespace orbed {
namespace {

// The annotation fields (contract change 5) decoded by landmark and side; "" or the reason.
std::string ReadAnnotation(const orbed::alignment_trial_t& msg,
                           std::vector<std::array<LandmarkRays, 2>>* out) {
  using AT = orbed::alignment_trial_t;
  const int32_t n = msg.num_annotation_rays;
  if (n < 0 || n > kMaxAnnotationRays || static_cast<size_t>(n) != msg.annotation_landmark.size() ||
      static_cast<size_t>(n) != msg.annotation_side.size() ||
      static_cast<size_t>(n) != msg.annotation_origin_W_m.size() ||
      static_cast<size_t>(n) != msg.annotation_direction_W.size()) {
    return "ALIGNMENT_TRIAL.num_annotation_rays " + std::to_string(n) + " is outside [0, " +
           std::to_string(kMaxAnnotationRays) + "] or does not match its four arrays";
  }
  out->clear();
  for (int32_t i = 0; i < n; ++i) {
    const std::string at = "[" + std::to_string(i) + "]";
    const int32_t l = msg.annotation_landmark[i];
    if (l < 0 || l >= kMaxAnnotatedLandmarks) {
      return "ALIGNMENT_TRIAL.annotation_landmark" + at + " " + std::to_string(l) + " is outside [0, " +
             std::to_string(kMaxAnnotatedLandmarks) + ")";
    }
    std::string error = CheckEnum(msg.annotation_side[i], AT::ANNOTATION_REAL, AT::ANNOTATION_VIRTUAL,
                                  "ALIGNMENT_TRIAL.annotation_side" + at);
    if (!error.empty()) return error;
    const std::vector<double>& origin = msg.annotation_origin_W_m[i];
    const std::vector<double>& direction = msg.annotation_direction_W[i];
    if (origin.size() != 3 || direction.size() != 3)
      return "ALIGNMENT_TRIAL.annotation ray" + at + ": expected 3 values";
    error = FirstError({CheckBounded(origin.data(), 3, kMaxAlignmentCoordinate_m,
                                     "ALIGNMENT_TRIAL.annotation_origin_W_m" + at),
                        CheckFinite(direction.data(), 3, "ALIGNMENT_TRIAL.annotation_direction_W" + at)});
    if (!error.empty()) return error;
    const Eigen::Vector3d u(direction[0], direction[1], direction[2]);
    if (!(std::abs(u.norm() - 1.0) <= 1e-6)) {
      return "ALIGNMENT_TRIAL.annotation_direction_W" + at + " has norm " + std::to_string(u.norm()) +
             ", expected a unit vector";
    }
    if (static_cast<size_t>(l) >= out->size()) out->resize(l + 1);
    LandmarkRays& rays = (*out)[l][msg.annotation_side[i]];
    rays.origin_W_m.emplace_back(origin[0], origin[1], origin[2]);
    rays.direction_W.push_back(u);
  }
  for (size_t l = 0; l < out->size(); ++l) {
    for (int side : {0, 1}) {
      if ((*out)[l][side].origin_W_m.size() < 2) {
        return "ALIGNMENT_TRIAL annotation: landmark " + std::to_string(l) + " has " +
               std::to_string((*out)[l][side].origin_W_m.size()) + " ray(s) on the " +
               (side == 0 ? "real" : "virtual") + " robot, expected >= 2";
      }
    }
  }
  return "";
}

}  // namespace

std::variant<AlignmentTrial, Refusal> CheckAlignmentTrial(const orbed::alignment_trial_t& msg,
                                                          int max_joints) {
  using AT = orbed::alignment_trial_t;
  if (msg.session_id.empty() || msg.session_id.size() > kMaxSessionIdLength) {
    return Refusal{"session_id", "ALIGNMENT_TRIAL.session_id is " + std::to_string(msg.session_id.size()) +
                                     " bytes, expected 1.." + std::to_string(kMaxSessionIdLength)};
  }
  if (msg.trial_index < 0 || msg.trial_index >= kMaxTrialsPerSession) {
    return Refusal{"trial_index", "ALIGNMENT_TRIAL.trial_index " + std::to_string(msg.trial_index) +
                                      " is outside 0.." + std::to_string(kMaxTrialsPerSession - 1)};
  }
  std::string error =
      CheckEnum(msg.display_mode, AT::MODE_AR, AT::MODE_AR_REFLECTIVE, "ALIGNMENT_TRIAL.display_mode");
  if (!error.empty()) return Refusal{"display_mode", error};
  if (msg.display_mode == AT::MODE_AR ? msg.num_mirrors != 0
                                      : (msg.num_mirrors < 1 || msg.num_mirrors > kMaxMirrors)) {
    return Refusal{"num_mirrors",
                   "ALIGNMENT_TRIAL.num_mirrors " + std::to_string(msg.num_mirrors) +
                       (msg.display_mode == AT::MODE_AR
                            ? " with MODE_AR, expected 0"
                            : " with MODE_AR_REFLECTIVE, expected 1.." + std::to_string(kMaxMirrors))};
  }
  error = CheckLength(msg.num_joints, msg.joint_position.size(), max_joints, "ALIGNMENT_TRIAL.num_joints");
  if (!error.empty()) return Refusal{"num_joints", error};
  error = CheckFinite(msg.joint_position, "ALIGNMENT_TRIAL.joint_position");
  if (!error.empty()) return Refusal{"joint_position", error};
  error = FirstError(
      {CheckPose(msg.X_WV, "ALIGNMENT_TRIAL.X_WV"),
       CheckBounded(msg.X_WV.position_m, 3, kMaxAlignmentCoordinate_m, "ALIGNMENT_TRIAL.X_WV.position_m")});
  if (!error.empty()) return Refusal{"X_WV", error};
  error = CheckFinite(&msg.duration_s, 1, "ALIGNMENT_TRIAL.duration_s");
  if (error.empty() && msg.duration_s < 0) error = "ALIGNMENT_TRIAL.duration_s is negative";
  if (!error.empty()) return Refusal{"duration_s", error};
  error = CheckFinite(&msg.tracking_wait_s, 1, "ALIGNMENT_TRIAL.tracking_wait_s");
  if (error.empty() && (msg.tracking_losses < 0 || msg.relocalizations < 0 || msg.alignment_repeats < 0)) {
    error = "ALIGNMENT_TRIAL.tracking_losses, relocalizations and alignment_repeats must be >= 0, got " +
            std::to_string(msg.tracking_losses) + ", " + std::to_string(msg.relocalizations) + ", " +
            std::to_string(msg.alignment_repeats);
  }
  if (error.empty() && !(msg.tracking_wait_s >= 0 && msg.tracking_wait_s <= msg.duration_s)) {
    error = "ALIGNMENT_TRIAL.tracking_wait_s " + std::to_string(msg.tracking_wait_s) +
            " s is not in [0, duration_s " + std::to_string(msg.duration_s) + " s]";
  }
  if (!error.empty()) return Refusal{"tracking_faults", error};
  AlignmentTrial trial;
  error = ReadAnnotation(msg, &trial.annotation);
  if (!error.empty()) return Refusal{"annotation", error};
  trial.msg = msg;
  trial.X_WV = FromPose(msg.X_WV);
  trial.q_rad = ToVectorX(msg.joint_position);
  return trial;
}

}  // namespace orbed
