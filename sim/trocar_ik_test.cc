// Tests of the trocar IK on the shipped scene: the tool docks at the trocar within tolerance, along
// the insertion direction, within the joint limits, collision-free; and it fails honestly.
#include "sim/trocar_ik.h"

#include <cmath>
#include <cstdlib>
#include <string>

#include <cstdio>

#include <gtest/gtest.h>

#include "base/source_paths.h"
#include "sim/collision_world.h"
#include "sim/scene.h"
#include "sim/trocar_clearance.h"

namespace orbed::sim {
namespace {

TEST(TrocarIkTest, DocksAtTheTrocarCollisionFree) {
  RobotModel model = RobotModel::LoadFile(orbed::SourceTreePath(RobotModel::kDefaultUrdfRelativePath));
  const Scene scene = LoadSceneFile(orbed::SourceTreePath(kDefaultSceneRelativePath));
  model.SetToolLength(scene.tool_length_m);
  const TrocarIkResult r = SolveTrocarIk(model, TrocarTargetInBase(scene), TrocarIkOptions{},
                                         MakeTrocarClearanceFunction(model, scene));
  ASSERT_TRUE(r.success) << r.message;
  EXPECT_EQ(model.ValidateJointVector(r.q_rad), "");
  // Independent residuals: FK in W against the scene's trocar.
  const Eigen::Isometry3d X_WT = scene.X_WR * model.CalcToolTipPose(r.q_rad);
  EXPECT_LT((X_WT.translation() - scene.trocar.p_WT).norm(), 1e-4);
  EXPECT_GT(X_WT.linear().col(2).dot(scene.trocar.insertion_direction_W), std::cos(1e-3));
  // The full check (tool included) is free, and the optimised arm clearance is substantial.
  CollisionWorld world(model, &scene);
  const CollisionResult c = world.Check(r.q_rad);
  EXPECT_FALSE(c.in_collision);
  EXPECT_GT(c.min_distance_m, 0.0);
  EXPECT_GT(MakeTrocarArmClearanceFunction(model, scene)(r.q_rad), 0.05);
  // The null-space refinement on its own: from one start, it must end at least as high as the
  // start's projection onto the trocar pose, and for this start (seed 4: 0.093 m) clearly higher.
  TrocarIkOptions one_start;
  one_start.num_seeds = 1;
  one_start.seed = 4;
  TrocarIkOptions one_start_plain = one_start;
  one_start_plain.max_refine_steps = 0;
  const ClearanceFunction objective = MakeTrocarClearanceFunction(model, scene);
  const TrocarIkResult plain = SolveTrocarIk(model, TrocarTargetInBase(scene), one_start_plain, objective);
  const TrocarIkResult refined = SolveTrocarIk(model, TrocarTargetInBase(scene), one_start, objective);
  ASSERT_FALSE(plain.q_rad.size() == 0) << plain.message;
  std::printf("one start: objective %.5f m -> refined %.5f m\n", plain.clearance_m, refined.clearance_m);
  EXPECT_GE(refined.clearance_m, plain.clearance_m);
  EXPECT_GT(refined.clearance_m, plain.clearance_m + 0.02);
}

TEST(TrocarIkTest, UnreachableTargetFailsHonestly) {
  const RobotModel model = RobotModel::LoadFile(orbed::SourceTreePath(RobotModel::kDefaultUrdfRelativePath));
  TrocarIkTarget far;
  far.p_RT = Eigen::Vector3d(3.0, 0, 0.5);
  far.axis_R = -Eigen::Vector3d::UnitZ();
  TrocarIkOptions opt;
  opt.num_seeds = 8;
  const TrocarIkResult r = SolveTrocarIk(model, far, opt, nullptr);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.message.find("converged"), std::string::npos) << r.message;
  far.axis_R = Eigen::Vector3d(0, 0, 2);
  EXPECT_THROW(SolveTrocarIk(model, far, opt, nullptr), std::invalid_argument);
}

TEST(TrocarIkTest, ReachableWithoutScoreSucceedsOnlyIfAllowed) {
  const RobotModel model = RobotModel::LoadFile(orbed::SourceTreePath(RobotModel::kDefaultUrdfRelativePath));
  TrocarIkTarget t;
  t.p_RT = Eigen::Vector3d(0.5, 0.1, 0.3);
  t.axis_R = -Eigen::Vector3d::UnitZ();
  TrocarIkOptions opt;
  opt.num_seeds = 8;
  opt.min_clearance_m = -1.0;
  const TrocarIkResult r = SolveTrocarIk(model, t, opt, nullptr);
  ASSERT_TRUE(r.success) << r.message;
  EXPECT_LT(r.position_error_m, opt.position_tolerance_m);
  EXPECT_LT((model.CalcToolTipPose(r.q_rad).translation() - t.p_RT).norm(), 1e-4);
}

}  // namespace
}  // namespace orbed::sim
