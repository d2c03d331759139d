#include "sim/iiwa_status_check.h"

#include "lcmtypes/contract/validation.h"

namespace orbed::sim {

IiwaStatusProblem CheckIiwaStatus(const orbed::iiwa_status_t& msg, const RobotModel& model, double slack_rad,
                                  Eigen::VectorXd* q_rad) {
  std::string error = CheckSize(msg.num_joints, model.num_joints(), "num_joints");
  if (error.empty() && msg.joint_position_measured.size() != static_cast<size_t>(msg.num_joints)) {
    error = "joint_position_measured has " + std::to_string(msg.joint_position_measured.size()) + " entries";
  }
  if (!error.empty()) return {"num_joints", error};
  error = CheckFinite(msg.joint_position_measured, "joint_position_measured");
  if (!error.empty()) return {"non_finite", error};
  const Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(msg.joint_position_measured.data(),
                                                              msg.joint_position_measured.size());
  error = model.ValidateJointVector(q, slack_rad);
  if (!error.empty()) return {"limits", "joint_position_measured: " + error};
  *q_rad = q;
  return {};
}

}  // namespace orbed::sim
