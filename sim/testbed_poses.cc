#include "sim/testbed_poses.h"

#include "lcmtypes/contract/conversions.h"
#include "lcmtypes/contract/requests.h"
#include "lcmtypes/contract/validation.h"
#include "sim/guidance_messages.h"

namespace orbed::sim {

std::string TestbedPoseState::Update(const orbed::robot_state_t& msg) {
  const int n = model_->num_joints();
  std::string problem = CheckRobotState(msg, n);
  if (!problem.empty()) return problem;
  X_WR_ = FromPose(msg.X_WR);
  q_ = Eigen::Map<const Eigen::VectorXd>(msg.joint_position.data(), n);
  return "";
}

std::string TestbedPoseState::Update(const orbed::registration_t& msg, bool* used) {
  if (used) *used = false;
  if (!msg.valid) return "";  // no mean yet
  std::string problem = CheckWorldPose(msg.X_WV_mean, "REGISTRATION.X_WV_mean");
  if (!problem.empty()) return problem;
  X_WV_ = FromPose(msg.X_WV_mean);
  if (used) *used = true;
  return "";
}

std::string TestbedPoseState::Update(const orbed::guidance_t& msg) {
  std::string problem = guidance::CheckGuidance(msg, *model_, 0.01);
  if (!problem.empty()) return problem;
  q_target_ = Eigen::Map<const Eigen::VectorXd>(msg.target_position.data(), model_->num_joints());
  have_target_ = true;
  return "";
}

std::string TestbedPoseState::Update(const orbed::hmd_pose_t& msg) {
  std::string problem = CheckWorldPose(msg.X_WH, "X_WH");
  if (problem.empty()) problem = CheckWorldPose(msg.X_WC, "X_WC");
  if (!problem.empty()) return problem;
  X_WH_ = FromPose(msg.X_WH);
  X_WC_ = FromPose(msg.X_WC);
  return "";
}

TestbedPoses::TestbedPoses(Process* process, const RobotModel& model, const Channels& channels,
                           Callbacks callbacks)
    : TestbedPoseState(model) {
  if (!channels.robot_state.empty())
    process->Subscribe<orbed::robot_state_t>(
        channels.robot_state,
        [this, process](const orbed::robot_state_t& msg, const std::string& channel, int64_t) {
          const std::string problem = Update(msg);
          if (!problem.empty()) process->Reject(channel + "/field", problem);
        });
  if (!channels.registration.empty())
    process->Subscribe<orbed::registration_t>(
        channels.registration, [this, process, on = callbacks.on_registration](
                                   const orbed::registration_t& msg, const std::string& channel, int64_t) {
          bool used = false;
          const std::string problem = Update(msg, &used);
          if (!problem.empty()) return process->Reject(channel + "/pose", problem);
          if (used && on) on(msg);
        });
  if (!channels.guidance.empty())
    process->Subscribe<orbed::guidance_t>(
        channels.guidance, [this, process, on = callbacks.on_guidance](const orbed::guidance_t& msg,
                                                                       const std::string& channel, int64_t) {
          const std::string problem = Update(msg);
          if (!problem.empty()) return process->Reject(channel + "/field", problem);
          if (on) on(msg);
        });
  if (!channels.hmd_pose.empty())
    process->Subscribe<orbed::hmd_pose_t>(
        channels.hmd_pose,
        [this, process](const orbed::hmd_pose_t& msg, const std::string& channel, int64_t) {
          const std::string problem = Update(msg);
          if (!problem.empty()) process->Reject(channel + "/pose", problem);
        });
}

}  // namespace orbed::sim
