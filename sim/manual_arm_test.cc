// The sim's motion law without a bus: speeds from the iiwa 7 data sheet (not from the URDF), synchronised
// straight joint-space moves, commands clamped to the joint limits, steps refused before a
// collision in the trocar OR scene, and the way back out of a stop.
#include "sim/manual_arm.h"
#include "base/source_paths.h"
#include "base/units.h"

#include <cmath>
#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

namespace orbed::sim {
namespace {

constexpr double kPeriodS = 0.005;
// iiwa 7 R800 joint speeds [deg/s] and limits [deg] as published in the iiwa 7 R800 data sheet.
const double kSpeedDegPerS[7] = {98, 98, 100, 130, 140, 180, 180};
const double kLimitDeg[7] = {170, 120, 170, 120, 170, 120, 175};

struct Fixture {
  Fixture()
      : model(RobotModel::LoadFile(orbed::SourceTreePath("sim/models/iiwa7.urdf"))),
        scene(LoadSceneFile(orbed::SourceTreePath("sim/models/scenes/trocar_or.yaml"))) {
    model.SetToolLength(scene.tool_length_m);
  }
  RobotModel model;
  Scene scene;
};

Eigen::VectorXd Deg(std::initializer_list<double> q_deg) {
  Eigen::VectorXd q(static_cast<Eigen::Index>(q_deg.size()));
  int i = 0;
  for (double v : q_deg) q[i++] = v * kDegToRad;
  return q;
}

// Runs until the arm stops changing (or max_ticks); checks every tick's step against the
// published speeds. Returns the number of ticks taken.
int RunToRest(ManualArm* arm, int max_ticks) {
  int ticks = 0;
  for (; ticks < max_ticks; ++ticks) {
    const Eigen::VectorXd before = arm->q_rad();
    arm->Step(kPeriodS);
    const Eigen::VectorXd step = arm->q_rad() - before;
    for (int i = 0; i < 7; ++i) {
      EXPECT_LE(std::abs(step[i]), kSpeedDegPerS[i] * kDegToRad * kPeriodS * (1 + 1e-9)) << "joint " << i + 1;
      EXPECT_LE(std::abs(arm->q_rad()[i]), kLimitDeg[i] * kDegToRad * (1 + 1e-12)) << "joint " << i + 1;
    }
    if (step.cwiseAbs().maxCoeff() == 0.0) break;
  }
  return ticks;
}

TEST(ManualArm, OneJointMovesAtItsPublishedSpeed) {
  Fixture f;
  ManualArm arm(f.model, &f.scene, Eigen::VectorXd::Zero(7), {});
  EXPECT_EQ(arm.state(), MotionState::kIdle);
  arm.SetCommand(Deg({0, 0, 0, 0, 0, 0, 90}));
  // 180 deg/s for 10 ticks of 5 ms: 9 deg, exactly.
  for (int k = 0; k < 10; ++k) arm.Step(kPeriodS);
  EXPECT_NEAR(arm.q_rad()[6], 9.0 * kDegToRad, 1e-12);
  EXPECT_NEAR(arm.velocity_rad_per_s()[6], 180.0 * kDegToRad, 1e-9);
  EXPECT_EQ(arm.state(), MotionState::kMoving);
  // 90 deg at 180 deg/s = 0.5 s = 100 ticks in all; then at rest exactly on the command.
  const int ticks = RunToRest(&arm, 1000);
  EXPECT_EQ(ticks + 10, 100);
  EXPECT_NEAR(arm.q_rad()[6], 90.0 * kDegToRad, 1e-15);
  EXPECT_EQ(arm.state(), MotionState::kIdle);
  EXPECT_EQ(arm.stop_reason(), "");
}

TEST(ManualArm, JointsArriveTogetherOnAStraightJointSpaceLine) {
  Fixture f;
  ManualArm arm(f.model, &f.scene, Eigen::VectorXd::Zero(7), {});
  // Joint 1 needs 49/98 = 0.5 s, joint 7 needs 45/180 = 0.25 s: joint 1 sets the pace.
  const Eigen::VectorXd target = Deg({49, 0, 0, 0, 0, 0, 45});
  arm.SetCommand(target);
  for (int k = 0; k < 50; ++k) arm.Step(kPeriodS);  // 0.25 s: half way
  EXPECT_NEAR(arm.q_rad()[0], 24.5 * kDegToRad, 1e-12);
  EXPECT_NEAR(arm.q_rad()[6], 22.5 * kDegToRad, 1e-12);
  EXPECT_NEAR(arm.velocity_rad_per_s()[0], 98 * kDegToRad, 1e-9);
  EXPECT_NEAR(arm.velocity_rad_per_s()[6], 90 * kDegToRad, 1e-9);
  EXPECT_EQ(RunToRest(&arm, 1000) + 50, 100);
  EXPECT_EQ(arm.q_rad(), target);
}

TEST(ManualArm, CommandBeyondALimitStopsOnTheLimit) {
  Fixture f;
  ManualArm arm(f.model, &f.scene, Eigen::VectorXd::Zero(7), {});
  arm.SetCommand(Deg({0, -130, 0, 0, 0, 0, 200}));
  EXPECT_EQ(arm.command_rad()[6], 200 * kDegToRad);  // kept as sent
  RunToRest(&arm, 2000);
  EXPECT_NEAR(arm.q_rad()[1], -120 * kDegToRad, 1e-12);
  EXPECT_NEAR(arm.q_rad()[6], 175 * kDegToRad, 1e-12);
  EXPECT_EQ(arm.state(), MotionState::kStoppedAtLimit);
  EXPECT_NE(arm.stop_reason().find("iiwa_joint_2"), std::string::npos) << arm.stop_reason();
  EXPECT_NE(arm.stop_reason().find("iiwa_joint_7"), std::string::npos) << arm.stop_reason();
  EXPECT_NE(arm.stop_reason().find("lower limit -120.0 deg"), std::string::npos) << arm.stop_reason();
  const std::vector<int> hits = arm.LimitHits();
  EXPECT_EQ(hits, (std::vector<int>{0, -1, 0, 0, 0, 0, +1}));
}

// Start upright; the target (orbed-robot check) puts the tool 0.135 m into the table top, and the
// straight joint-space path first touches the table top at about 91 % of the way.
TEST(ManualArm, StopsBeforeTheTableAndCanBeGuidedBackOut) {
  Fixture f;
  ManualArmOptions options;
  options.stop_margin_m = 0.01;
  ManualArm arm(f.model, &f.scene, Eigen::VectorXd::Zero(7), options);
  const Eigen::VectorXd target = Deg({-30, 80, 0, -30, 0, 60, 0});
  ASSERT_TRUE(arm.Check(target).in_collision);
  arm.SetCommand(target);
  double min_seen = arm.collision().min_distance_m;
  for (int k = 0; k < 400; ++k) {
    arm.Step(kPeriodS);
    min_seen = std::min(min_seen, arm.collision().min_distance_m);
  }
  EXPECT_EQ(arm.state(), MotionState::kStoppedBeforeCollision);
  EXPECT_NE(arm.stop_reason().find("table_top"), std::string::npos) << arm.stop_reason();
  EXPECT_GE(min_seen, options.stop_margin_m - 1e-9);
  // At rest within a fraction of a step of the margin, not a whole step (~1.5 cm) before it.
  EXPECT_LT(arm.collision().min_distance_m, options.stop_margin_m + 0.005);
  // Still on the straight line from 0 to the target, short of it.
  const double fraction = arm.q_rad()[1] / target[1];
  EXPECT_GT(fraction, 0.5);
  EXPECT_LT(fraction, 0.95);
  EXPECT_LT((arm.q_rad() - fraction * target).cwiseAbs().maxCoeff(), 1e-12);
  // A blocked arm with the same target does not query again.
  const int64_t checks = arm.num_checks();
  for (int k = 0; k < 10; ++k) arm.Step(kPeriodS);
  EXPECT_EQ(arm.num_checks(), checks);
  EXPECT_EQ(arm.velocity_rad_per_s().cwiseAbs().maxCoeff(), 0.0);
  // Guided back up, it moves again and the clearance grows.
  const double stopped_at = arm.collision().min_distance_m;
  arm.SetCommand(Eigen::VectorXd::Zero(7));
  arm.Step(kPeriodS);
  EXPECT_EQ(arm.state(), MotionState::kMoving);
  for (int k = 0; k < 20; ++k) arm.Step(kPeriodS);
  EXPECT_GT(arm.collision().min_distance_m, stopped_at + 0.01);
}

TEST(ManualArm, AnArmStartedInCollisionMayOnlyMoveOut) {
  Fixture f;
  const Eigen::VectorXd inside = Deg({-30, 80, 0, -30, 0, 60, 0});
  ManualArm arm(f.model, &f.scene, inside, {});
  EXPECT_EQ(arm.state(), MotionState::kInCollision);
  const double depth = arm.collision().min_distance_m;
  ASSERT_LT(depth, 0);
  arm.SetCommand(Deg({-30, 100, 0, -30, 0, 60, 0}));  // further down
  arm.Step(kPeriodS);
  EXPECT_GE(arm.collision().min_distance_m, depth - 1e-9);
  arm.SetCommand(Eigen::VectorXd::Zero(7));  // back up
  RunToRest(&arm, 2000);
  EXPECT_EQ(arm.q_rad(), Eigen::VectorXd::Zero(7));
  EXPECT_EQ(arm.state(), MotionState::kIdle);
}

TEST(ManualArm, RejectsBadInputs) {
  Fixture f;
  EXPECT_THROW(ManualArm(f.model, &f.scene, Eigen::VectorXd::Zero(6), {}), std::invalid_argument);
  EXPECT_THROW(ManualArm(f.model, &f.scene, Deg({0, 121, 0, 0, 0, 0, 0}), {}), std::invalid_argument);
  ManualArmOptions bad;
  bad.stop_margin_m = -1;
  EXPECT_THROW(ManualArm(f.model, &f.scene, Eigen::VectorXd::Zero(7), bad), std::invalid_argument);
  ManualArm arm(f.model, &f.scene, Eigen::VectorXd::Zero(7), {});
  EXPECT_THROW(arm.SetCommand(Eigen::VectorXd::Zero(6)), std::invalid_argument);
  Eigen::VectorXd nan = Eigen::VectorXd::Zero(7);
  nan[3] = std::nan("");
  EXPECT_THROW(arm.SetCommand(nan), std::invalid_argument);
  EXPECT_THROW(arm.Step(0.0), std::invalid_argument);
  EXPECT_EQ(arm.q_rad(), Eigen::VectorXd::Zero(7));
}

}  // namespace
}  // namespace orbed::sim
