#include "procs/common/alignment_trial.h"

#include "procs/common/conversions.h"
#include "procs/common/validation.h"

namespace orbed {

std::variant<AlignmentTrial, Refusal> CheckAlignmentTrial(const orbed::alignment_trial_t& msg,
                                                          int max_joints) {
  using AT = orbed::alignment_trial_t;
  if (msg.session_id.empty() || msg.session_id.size() > kMaxSessionIdLength) {
    return Refusal{"session_id", "ALIGNMENT_TRIAL.session_id is " + std::to_string(msg.session_id.size()) +
                                     " bytes, expected 1.." + std::to_string(kMaxSessionIdLength)};
  }
  if (msg.trial_index < 0) {
    return Refusal{"trial_index",
                   "ALIGNMENT_TRIAL.trial_index " + std::to_string(msg.trial_index) + " is negative"};
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
  trial.msg = msg;
  trial.X_WV = FromPose(msg.X_WV);
  trial.q_rad = ToVectorX(msg.joint_position);
  return trial;
}

}  // namespace orbed
