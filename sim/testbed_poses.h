#pragma once
/// @file
/// TestbedPoses: the testbed's latest poses as the bridges to other tools need them (Drake's
/// viewer, OpenIGTLink, Foxglove), subscribed and checked in one place:
///   ROBOT_STATE   X_WR and the real joints q (CheckRobotState); refused: "ROBOT_STATE/field"
///   REGISTRATION  the latest valid X_WV_mean (the registered virtual robot; a world pose,
///                 CheckWorldPose); invalid states (no mean yet) are skipped; refused: "REGISTRATION/pose"
///   GUIDANCE      its target configuration: the virtual robot's during a set-up (CheckGuidance
///                 with 0.01 rad of slack); refused: "GUIDANCE/field"
///   HMD_POSE      the headset X_WH and its camera X_WC (the SLAM estimate; world poses);
///                 refused: "HMD_POSE/pose"
/// Each optional callback runs after its message was stored (e.g. to forward it).
/// TestbedPoseState is the same without a bus (the messages handed in, each checked as above), for
/// what reads a log (orbed-log export --mcap).
///
/// Threading: handlers run on the Process::Run thread; read from that thread. TestbedPoseState: not
/// synchronised (one thread).

#include <functional>
#include <optional>
#include <string>

#include <Eigen/Geometry>
#include <orbed/guidance_t.hpp>
#include <orbed/hmd_pose_t.hpp>
#include <orbed/registration_t.hpp>
#include <orbed/robot_state_t.hpp>

#include "runtime/process.h"
#include "sim/robot_model.h"

namespace orbed::sim {

/// The latest poses from messages handed in. Each Update returns "" when the message was used or
/// skipped (a REGISTRATION without a mean yet), else why it was refused (nothing changes then).
class TestbedPoseState {
 public:
  /// `model` (which must outlive this) gives the joint count and limits.
  explicit TestbedPoseState(const RobotModel& model) : model_(&model) {}

  std::string Update(const orbed::robot_state_t& msg);
  /// *used: whether the message changed X_WV (false for an invalid state).
  std::string Update(const orbed::registration_t& msg, bool* used = nullptr);
  std::string Update(const orbed::guidance_t& msg);
  std::string Update(const orbed::hmd_pose_t& msg);

  const std::optional<Eigen::Isometry3d>& X_WR() const { return X_WR_; }
  const std::optional<Eigen::Isometry3d>& X_WV() const { return X_WV_; }
  const std::optional<Eigen::Isometry3d>& X_WH() const { return X_WH_; }
  const std::optional<Eigen::Isometry3d>& X_WC() const { return X_WC_; }
  /// The real joints (empty before the first good ROBOT_STATE).
  const Eigen::VectorXd& q() const { return q_; }
  /// The virtual robot's joints: GUIDANCE's target once one came, else the real joints.
  const Eigen::VectorXd& q_virtual() const { return have_target_ ? q_target_ : q_; }

 private:
  const RobotModel* model_;
  std::optional<Eigen::Isometry3d> X_WR_, X_WV_, X_WH_, X_WC_;
  Eigen::VectorXd q_, q_target_;
  bool have_target_{false};
};

class TestbedPoses : public TestbedPoseState {
 public:
  /// The channels (defaults: lcmtypes/contract/channels.h); one named "" is not subscribed.
  struct Channels {
    std::string robot_state{"ROBOT_STATE"};
    std::string registration{"REGISTRATION"};
    std::string guidance{"GUIDANCE"};
    std::string hmd_pose{"HMD_POSE"};
  };
  struct Callbacks {
    std::function<void(const orbed::registration_t&)> on_registration;
    std::function<void(const orbed::guidance_t&)> on_guidance;
  };
  /// Subscribes on `process` (which must outlive this); `model` gives the joint count and limits.
  TestbedPoses(Process* process, const RobotModel& model, const Channels& channels, Callbacks callbacks = {});
};

}  // namespace orbed::sim
