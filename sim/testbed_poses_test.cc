// TestbedPoses on memq://: good messages stored (the virtual joints are GUIDANCE's target once one
// came), bad ones refused under their keys and changing nothing, the
// callbacks called once per stored message.
#include "sim/testbed_poses.h"

#include <cmath>

#include <gtest/gtest.h>
#include <orbed/hmd_pose_t.hpp>
#include <orbed/robot_state_t.hpp>

#include "base/source_paths.h"
#include "lcmtypes/contract/conversions.h"
#include "sim/guidance_messages.h"

namespace orbed::sim {
namespace {

orbed::pose_t At(double x) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation().x() = x;
  return ToPose(X);
}

TEST(TestbedPoses, StoresGoodMessagesAndRefusesBadOnes) {
  const RobotModel model = RobotModel::LoadFile(SourceTreePath(RobotModel::kDefaultUrdfRelativePath));
  CommonFlags flags("testbed-poses-test");
  flags.lcm_url = "memq://";
  flags.duration_s = 0.5;  // the messages below are queued before Run and handled at its start
  Process process(flags);
  int registrations = 0, guidances = 0;
  TestbedPoses poses(&process, model, TestbedPoses::Channels{},
                     {[&](const orbed::registration_t&) { ++registrations; },
                      [&](const orbed::guidance_t&) { ++guidances; }});
  lcm::LCM& lcm = process.lcm();

  orbed::robot_state_t state{};
  state.X_WR = At(0.5);
  state.num_joints = 7;
  state.joint_position = {0.1, 0.2, 0, 0, 0, 0, 0};
  state.joint_limit_hit.assign(7, false);
  lcm.publish("ROBOT_STATE", &state);
  orbed::robot_state_t bad_state = state;
  bad_state.X_WR = At(9);
  bad_state.joint_position[0] = std::nan("");
  lcm.publish("ROBOT_STATE", &bad_state);

  orbed::registration_t none{};
  none.X_WV_mean = At(7);  // not valid: skipped, not refused
  lcm.publish("REGISTRATION", &none);
  orbed::registration_t registration{};
  registration.valid = true;
  registration.X_WV_mean = At(0.51);
  lcm.publish("REGISTRATION", &registration);
  orbed::registration_t bad_registration = registration;
  bad_registration.X_WV_mean.quaternion_wxyz[0] = 3;
  lcm.publish("REGISTRATION", &bad_registration);

  orbed::guidance_t guidance{};
  guidance.num_joints = 7;
  guidance.target_position = {0.3, 0.4, 0, -0.5, 0, 0.6, 0};
  guidance.current_position.assign(7, 0.0);
  guidance.error_deg.assign(7, 0.0);
  guidance.joint_kind = guidance::JointKinds(model);
  guidance.next_joint = 0;
  orbed::guidance_t bad_guidance = guidance;
  bad_guidance.target_position[1] = 3.0;  // beyond joint 2's limit (120 deg)
  lcm.publish("GUIDANCE", &bad_guidance);
  lcm.publish("GUIDANCE", &guidance);

  orbed::hmd_pose_t pose{};
  pose.X_WH = At(1);
  pose.X_WC = At(1.1);
  lcm.publish("HMD_POSE", &pose);
  EXPECT_EQ(process.Run(), 0);

  ASSERT_TRUE(poses.X_WR().has_value());
  EXPECT_EQ(poses.X_WR()->translation().x(), 0.5);
  EXPECT_EQ(poses.q()[1], 0.2);
  EXPECT_EQ(poses.q_virtual()[1], 0.4);  // GUIDANCE's target
  EXPECT_EQ(poses.X_WV()->translation().x(), 0.51);
  EXPECT_EQ(poses.X_WH()->translation().x(), 1.0);
  EXPECT_EQ(poses.X_WC()->translation().x(), 1.1);
  EXPECT_EQ(registrations, 1);
  EXPECT_EQ(guidances, 1);
  const auto counts = process.rejections().counts();
  EXPECT_EQ(counts.at("ROBOT_STATE/field"), 1);
  EXPECT_EQ(counts.at("REGISTRATION/pose"), 1);
  EXPECT_EQ(counts.at("GUIDANCE/field"), 1);
  EXPECT_EQ(counts.size(), 3u);
}

}  // namespace
}  // namespace orbed::sim
