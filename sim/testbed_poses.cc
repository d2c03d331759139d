#include "sim/testbed_poses.h"

#include <orbed/hmd_pose_t.hpp>
#include <orbed/robot_state_t.hpp>

#include "lcmtypes/contract/conversions.h"
#include "lcmtypes/contract/requests.h"
#include "lcmtypes/contract/validation.h"
#include "sim/guidance_messages.h"

namespace orbed::sim {

TestbedPoses::TestbedPoses(Process* process, const RobotModel& model, const Channels& channels,
                           Callbacks callbacks) {
  const int n = model.num_joints();
  if (!channels.robot_state.empty())
    process->Subscribe<orbed::robot_state_t>(
        channels.robot_state,
        [this, process, n](const orbed::robot_state_t& msg, const std::string& channel, int64_t) {
          const std::string problem = CheckRobotState(msg, n);
          if (!problem.empty()) return process->Reject(channel + "/field", problem);
          X_WR_ = FromPose(msg.X_WR);
          q_ = Eigen::Map<const Eigen::VectorXd>(msg.joint_position.data(), n);
        });
  if (!channels.registration.empty())
    process->Subscribe<orbed::registration_t>(
        channels.registration, [this, process, on = callbacks.on_registration](
                                   const orbed::registration_t& msg, const std::string& channel, int64_t) {
          if (!msg.valid) return;  // no mean yet
          const std::string problem = CheckWorldPose(msg.X_WV_mean, "REGISTRATION.X_WV_mean");
          if (!problem.empty()) return process->Reject(channel + "/pose", problem);
          X_WV_ = FromPose(msg.X_WV_mean);
          if (on) on(msg);
        });
  if (!channels.guidance.empty())
    process->Subscribe<orbed::guidance_t>(
        channels.guidance, [this, process, &model, n, on = callbacks.on_guidance](
                               const orbed::guidance_t& msg, const std::string& channel, int64_t) {
          const std::string problem = guidance::CheckGuidance(msg, model, 0.01);
          if (!problem.empty()) return process->Reject(channel + "/field", problem);
          q_target_ = Eigen::Map<const Eigen::VectorXd>(msg.target_position.data(), n);
          have_target_ = true;
          if (on) on(msg);
        });
  if (!channels.hmd_pose.empty())
    process->Subscribe<orbed::hmd_pose_t>(
        channels.hmd_pose,
        [this, process](const orbed::hmd_pose_t& msg, const std::string& channel, int64_t) {
          std::string problem = CheckWorldPose(msg.X_WH, "X_WH");
          if (problem.empty()) problem = CheckWorldPose(msg.X_WC, "X_WC");
          if (!problem.empty()) return process->Reject(channel + "/pose", problem);
          X_WH_ = FromPose(msg.X_WH);
          X_WC_ = FromPose(msg.X_WC);
        });
}

}  // namespace orbed::sim
