// Tests of the scene loader: the shipped scene and the error messages for bad files.
#include "sim/scene.h"
#include "base/source_paths.h"

#include <cmath>
#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

namespace orbed::sim {
namespace {

TEST(SceneTest, ShippedSceneLoads) {
  const Scene s = LoadSceneFile(orbed::SourceTreePath(kDefaultSceneRelativePath));
  EXPECT_EQ(s.name, "trocar_or");
  EXPECT_NEAR(s.tool_length_m, 0.25, 1e-12);
  EXPECT_TRUE(s.X_WR.translation().isApprox(Eigen::Vector3d(0.25, -0.55, 0.75)));
  // yaw 90 deg: the base's x axis is W's y.
  EXPECT_TRUE(s.X_WR.linear().col(0).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  EXPECT_NEAR(s.trocar.insertion_direction_W.norm(), 1.0, 1e-12);
  // The docking point is 0.05 m back along the insertion direction from the umbilicus on the torso.
  const Eigen::Vector3d skin = s.trocar.p_WT + 0.05 * s.trocar.insertion_direction_W;
  EXPECT_NEAR(skin.z(), 1.02, 1e-4);
  bool has_table = false, has_column = false, has_cart = false;
  for (const auto& o : s.objects) {
    has_table |= o.name == "table_top";
    has_column |= o.name == "second_arm_column" && o.shape == SceneObject::Shape::kCylinder;
    has_cart |= o.name == "anaesthesia_cart";
  }
  EXPECT_TRUE(has_table && has_column && has_cart);
}

TEST(SceneTest, RpyIsFixedAxisRollPitchYaw) {
  const Eigen::Matrix3d R = RotationFromRpyDeg(Eigen::Vector3d(90, 0, 90));
  // Rx(90) first: y -> z; then Rz(90): x -> y.
  EXPECT_TRUE((R * Eigen::Vector3d::UnitY()).isApprox(Eigen::Vector3d::UnitZ(), 1e-12));
  EXPECT_TRUE((R * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
}

std::string Error(const std::string& yaml) {
  try {
    LoadSceneString(yaml, "bad.yaml");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no error)";
}

const char* kGood = R"(robot:
  base_pose: {position_m: [0, 0, 0]}
  tool_length_m: 0.2
trocar:
  position_m: [0.5, 0, 0.5]
  insertion_direction: [0, 0, -1]
)";

TEST(SceneTest, ErrorsNameFileLineKeyAndExpectation) {
  EXPECT_EQ(Error(kGood), "(no error)");
  std::string e = Error(std::string(kGood) +
                        "objects:\n  - name: t\n    shape: box\n    size_m: [1, 2]\n"
                        "    pose: {position_m: [0, 0, 0]}\n");
  EXPECT_NE(e.find("bad.yaml:10: objects[0].size_m: expected a list of 3 numbers > 0"), std::string::npos)
      << e;
  e = Error(std::string(kGood) +
            "objects:\n  - name: t\n    shape: cone\n    pose: {position_m: [0, 0, 0]}\n");
  EXPECT_NE(e.find("objects[0].shape: expected box, cylinder or sphere, got 'cone'"), std::string::npos) << e;
  e = Error(
      "robot:\n  base_pose: {position_m: [0, 0, 0]}\ntrocar: {position_m: [0,0,0], insertion_direction: "
      "[0,0,-1]}\n");
  EXPECT_NE(e.find("robot.tool_length_m: missing"), std::string::npos) << e;
  e = Error("robot:\n  base_pose: {position_m: [0, 0, x]}\n  tool_length_m: 0.2\n");
  EXPECT_NE(e.find("robot.base_pose.position_m[2]"), std::string::npos) << e;
  e = Error(std::string(kGood) + "extra: 1\n");
  EXPECT_NE(e.find("extra: unknown key"), std::string::npos) << e;
  e = Error("robot:\n  base_pose: {position_m: [0, 0, 0]}\n  tool_length_m: -0.2\n");
  EXPECT_NE(e.find("robot.tool_length_m: expected a number > 0"), std::string::npos) << e;
  e = Error(
      "robot:\n  base_pose: {position_m: [0, 0, 0]}\n  tool_length_m: 0.2\n"
      "trocar: {position_m: [0,0,0], insertion_direction: [0,0,-2]}\n");
  EXPECT_NE(e.find("trocar.insertion_direction: expected a unit vector"), std::string::npos) << e;
  e = Error("robot: [1, 2\n");
  EXPECT_NE(e.find("bad.yaml:"), std::string::npos) << e;
  EXPECT_NE(e.find("not valid YAML"), std::string::npos) << e;
  e = Error(std::string(kGood) +
            "objects:\n  - {name: a, shape: sphere, radius_m: 1, pose: {position_m: [0,0,0]}}\n"
            "  - {name: a, shape: sphere, radius_m: 1, pose: {position_m: [0,0,0]}}\n");
  EXPECT_NE(e.find("objects[1].name"), std::string::npos) << e;
  e = Error(
      std::string(kGood) +
      "objects:\n  - {name: a, shape: sphere, radius_m: 1, length_m: 2, pose: {position_m: [0,0,0]}}\n");
  EXPECT_NE(e.find("objects[0].length_m: not used by a sphere"), std::string::npos) << e;
  EXPECT_THROW(LoadSceneFile("/nonexistent.yaml"), std::runtime_error);
}

}  // namespace
}  // namespace orbed::sim
