// The set-up targets (trocar_plan.h) checked independently of the planner: each docks the tool at the
// trocar (forward kinematics: tool tip at the docking point, tool axis along the insertion
// direction), is within the joint limits and collision-free in the full check (tool included), has
// the arm clearance asked for, and every two differ by the separation asked for; impossible requests
// are refused naming the target; the command prints the same targets.
#include "sim/trocar_plan.h"

#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/source_paths.h"
#include "base/test_command.h"
#include "base/units.h"
#include "sim/collision_world.h"
#include "sim/robot_tool.h"
#include "sim/scene.h"

namespace orbed::sim {
namespace {

struct Shipped {
  Scene scene = LoadSceneFile(SourceTreePath(kDefaultSceneRelativePath));
  RobotModel model = LoadRobotForScene(SourceTreePath(RobotModel::kDefaultUrdfRelativePath), scene);
};

// A branch: the shortfall by hand, and a planned target in the branch the former plan's first
// target is the mirror of (joints 2, 4, 6 of signs +, -, +).
TEST(TrocarPlan, ABranchIsPlannedInsideItsSigns) {
  Eigen::VectorXd q(7);
  q << 0, 20, 0, -5, 0, -30, 0;
  q *= kDegToRad;
  const std::vector<int> signs = {0, 1, 0, -1, 0, 1, 0};
  // Joint 2: 20 >= 10, none; joint 4: -(-5) = 5, short by 5; joint 6: -30, short by 40.
  EXPECT_NEAR(BranchShortfallDeg(q, signs, 10), 45.0, 1e-9);
  EXPECT_EQ(BranchShortfallDeg(q, {}, 10), 0.0);
  const Shipped s;
  for (const std::vector<int>& branch : {signs, std::vector<int>{0, -1, 0, 1, 0, -1, 0}}) {
    TrocarPlanOptions options;
    options.num_targets = 1;
    options.joint_signs = branch;
    const std::vector<PlannedTarget> plan = PlanTrocarTargets(s.model, s.scene, options);
    ASSERT_EQ(plan.size(), 1u);
    for (int j : {1, 3, 5}) EXPECT_GE(branch[j] * plan[0].q_rad[j] * kRadToDeg, 10.0) << "joint " << j + 1;
    const Eigen::Isometry3d X_WT = s.scene.X_WR * s.model.CalcToolTipPose(plan[0].q_rad);
    EXPECT_LT((X_WT.translation() - s.scene.trocar.p_WT).norm(), 1e-4);
  }
  TrocarPlanOptions bad;
  bad.joint_signs = {0, 2, 0, 0, 0, 0, 0};
  EXPECT_THROW(PlanTrocarTargets(s.model, s.scene, bad), std::invalid_argument);
}

TEST(TrocarPlan, ThreeDistinctDockingConfigurationsWithClearance) {
  const Shipped s;
  TrocarPlanOptions options;
  const std::vector<PlannedTarget> plan = PlanTrocarTargets(s.model, s.scene, options);
  ASSERT_EQ(plan.size(), 3u);
  CollisionWorld world(s.model, &s.scene);
  for (size_t k = 0; k < plan.size(); ++k) {
    const Eigen::VectorXd& q = plan[k].q_rad;
    EXPECT_EQ(s.model.ValidateJointVector(q), "") << "target " << k + 1;
    const Eigen::Isometry3d X_WT = s.scene.X_WR * s.model.CalcToolTipPose(q);
    EXPECT_LT((X_WT.translation() - s.scene.trocar.p_WT).norm(), 1e-4) << "target " << k + 1;
    EXPECT_GT(X_WT.linear().col(2).dot(s.scene.trocar.insertion_direction_W), std::cos(0.01 * kDegToRad));
    EXPECT_FALSE(world.Check(q).in_collision) << "target " << k + 1;
    EXPECT_GE(plan[k].clearance_m, options.min_clearance_m);
    for (size_t j = 0; j < k; ++j) {
      // Apart in the arm's pose, not only in the flange's roll (joint 7).
      const double apart_deg = (q.head(6) - plan[j].q_rad.head(6)).cwiseAbs().maxCoeff() * kRadToDeg;
      EXPECT_GE(apart_deg, options.min_separation_deg) << "targets " << j + 1 << " and " << k + 1;
    }
  }
}

TEST(TrocarPlan, ImpossibleRequestsAreRefusedNamingTheTarget) {
  const Shipped s;
  TrocarPlanOptions options;
  options.num_targets = 2;
  options.min_clearance_m = 5.0;  // no arm in this OR is 5 m from everything
  try {
    PlanTrocarTargets(s.model, s.scene, options);
    FAIL() << "accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("target 1 of 2"), std::string::npos) << e.what();
  }
  options = {};
  options.num_targets = 0;
  EXPECT_THROW(PlanTrocarTargets(s.model, s.scene, options), std::invalid_argument);
  Eigen::VectorXd roll_only = Eigen::VectorXd::Zero(7);
  roll_only[6] = 1.0;
  roll_only[2] = 0.5;
  EXPECT_NEAR(LargestJointDifferenceDeg(Eigen::VectorXd::Zero(7), roll_only), 1.0 * kRadToDeg, 1e-12);
  EXPECT_NEAR(LargestJointDifferenceDeg(Eigen::VectorXd::Zero(7), roll_only, 6), 0.5 * kRadToDeg, 1e-12);
}

TEST(TrocarPlan, TheCommandPrintsThePlan) {
  const std::string scene = SourceTreePath(kDefaultSceneRelativePath);
  const test::CommandRun r =
      test::RunCommand(RunRobotTool, "orbed-robot", {"plan", "--scene", scene, "--targets", "2"});
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json plan = nlohmann::json::parse(r.out);
  ASSERT_EQ(plan["targets"].size(), 2u);
  EXPECT_EQ(plan["targets"][0]["q_deg"].size(), 7u);
  EXPECT_GE(plan["targets"][1]["separation_deg"].get<double>(), 20.0);
  const test::CommandRun bad =
      test::RunCommand(RunRobotTool, "orbed-robot", {"plan", "--scene", scene, "--min-clearance-m", "5"});
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.err.find("target 1 of 3"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace orbed::sim
