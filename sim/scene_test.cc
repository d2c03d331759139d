// Tests of the scene loader: the shipped scene and the error messages for bad files.
#include "sim/scene.h"

#include <cmath>
#include <cstdlib>
#include <set>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "base/source_paths.h"
#include "base/yaml_fields.h"

namespace orbed::sim {
namespace {

const SceneObject& Find(const Scene& s, const std::string& name) {
  for (const SceneObject& o : s.objects) {
    if (o.name == name) return o;
  }
  throw std::runtime_error("no object " + name);
}

// The shipped scene is consistent with itself: the robot stands on its cart facing the table, and
// the docking point is 0.05 m out of the patient's skin along the insertion direction.
TEST(SceneTest, ShippedSceneHangsTogether) {
  const Scene s = LoadSceneFile(orbed::SourceTreePath(kDefaultSceneRelativePath));
  const SceneObject& cart = Find(s, "robot_cart");
  const Eigen::Vector3d cart_top = cart.X_WO.translation() + Eigen::Vector3d(0, 0, cart.size_m.z() / 2);
  EXPECT_TRUE(s.X_WR.translation().isApprox(cart_top, 1e-12));
  // The base's x axis points at the table: along it the base reaches the table's long axis within
  // the table's length.
  const SceneObject& table = Find(s, "table_top");
  const Eigen::Vector3d x_axis = s.X_WR.linear().col(0);
  const Eigen::Vector3d to_table = table.X_WO.translation() - s.X_WR.translation();
  ASSERT_GT(x_axis.dot(to_table), 0);
  const Eigen::Vector3d reach = s.X_WR.translation() + to_table.y() / x_axis.y() * x_axis;
  EXPECT_LT(std::abs(reach.x() - table.X_WO.translation().x()), table.size_m.x() / 2);
  EXPECT_TRUE(s.X_WR.linear().col(2).isApprox(Eigen::Vector3d::UnitZ(), 1e-12));
  EXPECT_NEAR(s.trocar.insertion_direction_W.norm(), 1.0, 1e-12);
  // The skin point is on the top face of the torso.
  const SceneObject& torso = Find(s, "patient_torso");
  const Eigen::Vector3d skin = s.trocar.p_WT + 0.05 * s.trocar.insertion_direction_W;
  const Eigen::Vector3d skin_O = torso.X_WO.inverse() * skin;
  EXPECT_NEAR(skin_O.z(), torso.size_m.z() / 2, 1e-4);
  EXPECT_LT(std::abs(skin_O.x()), torso.size_m.x() / 2);
  EXPECT_LT(std::abs(skin_O.y()), torso.size_m.y() / 2);
}

// scene.h documents the format with the shipped scene's values; Scene's tool length is the URDF's
// tool and the shipped scene's. Fails when one of them is edited without the others.
TEST(SceneTest, HeaderStructUrdfAndShippedSceneAgree) {
  const std::string path = orbed::SourceTreePath(kDefaultSceneRelativePath);
  const YAML::Node doc = YamlFields::LoadDocBlock(orbed::SourceTreePath("sim/scene.h"));
  const std::set<std::string> documented = YamlFields::KeyPaths(doc);
  for (const std::string& k : YamlFields::KeyPaths(YamlFields::LoadFile(path))) {
    EXPECT_TRUE(documented.count(k)) << k << ": set in " << path << ", not documented in scene.h";
  }
  const Scene from_doc = LoadSceneString(YAML::Dump(doc), "scene.h");
  const Scene shipped = LoadSceneFile(path);
  const RobotModel robot = RobotModel::LoadFile(orbed::SourceTreePath(RobotModel::kDefaultUrdfRelativePath));
  EXPECT_EQ(Scene{}.tool_length_m, robot.tool_length_m());
  EXPECT_EQ(shipped.tool_length_m, Scene{}.tool_length_m);
  EXPECT_EQ(from_doc.tool_length_m, Scene{}.tool_length_m);
  // The header shows the shipped values.
  EXPECT_EQ(from_doc.name, shipped.name);
  EXPECT_TRUE(from_doc.X_WR.isApprox(shipped.X_WR, 0));
  EXPECT_TRUE(from_doc.trocar.p_WT.isApprox(shipped.trocar.p_WT, 0));
  EXPECT_TRUE(from_doc.trocar.insertion_direction_W.isApprox(shipped.trocar.insertion_direction_W, 0));
  for (const SceneObject& o : from_doc.objects) {
    const SceneObject& s = Find(shipped, o.name);
    EXPECT_EQ(o.shape, s.shape) << o.name;
    EXPECT_TRUE(o.X_WO.isApprox(s.X_WO, 0)) << o.name;
    EXPECT_EQ(o.size_m, s.size_m) << o.name;
    EXPECT_EQ(o.radius_m, s.radius_m) << o.name;
    EXPECT_EQ(o.length_m, s.length_m) << o.name;
    EXPECT_EQ(o.ignore_links, s.ignore_links) << o.name;
  }
  // The documented defaults of the optional keys: no name, rpy 0, no ignored links, no objects.
  const Scene bare = LoadSceneString(
      "robot: {base_pose: {position_m: [0, 0, 0]}, tool_length_m: 0.2}\n"
      "trocar: {position_m: [0, 0, 0], insertion_direction: [0, 0, -1]}\n",
      "bare.yaml");
  EXPECT_EQ(bare.name, Scene{}.name);
  EXPECT_TRUE(bare.X_WR.linear().isIdentity(0));
  EXPECT_TRUE(bare.objects.empty());
  // The shipped scene is named after its file.
  EXPECT_EQ(shipped.name + ".yaml", path.substr(path.rfind('/') + 1));
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

// Several arms: four_arms_or.yaml's four bases, a0 where the single arm stands; names are checked
// (they name channels), unique, and at most kMaxSceneArms.
TEST(SceneTest, ArmsHaveNamesAndBases) {
  const Scene four = LoadSceneFile(orbed::SourceTreePath("sim/models/scenes/four_arms_or.yaml"));
  ASSERT_EQ(four.arms.size(), 4u);
  EXPECT_EQ(four.arms[3].name, "a3");
  EXPECT_TRUE(four.FindArm("a0")->X_WR.isApprox(four.X_WR, 0));
  EXPECT_TRUE(four.FindArm("a1")->X_WR.translation().isApprox(Eigen::Vector3d(-0.45, -0.55, 0.75), 0));
  // a3 faces -y: its x axis is W's -y.
  EXPECT_TRUE((four.FindArm("a3")->X_WR.linear() * Eigen::Vector3d::UnitX())
                  .isApprox(-Eigen::Vector3d::UnitY(), 1e-12));
  EXPECT_EQ(four.FindArm("a4"), nullptr);
  EXPECT_TRUE(LoadSceneFile(orbed::SourceTreePath(kDefaultSceneRelativePath)).arms.empty());
  const std::string arm = "  - {name: a0, base_pose: {position_m: [0, 0, 0]}}\n";
  std::string e = Error(std::string(kGood) + "arms:\n  - {name: Left, base_pose: {position_m: [0, 0, 0]}}\n");
  EXPECT_NE(e.find("arms[0].name: expected 1..32 characters of a-z, 0-9 and _"), std::string::npos) << e;
  e = Error(std::string(kGood) + "arms:\n" + arm + arm);
  EXPECT_NE(e.find("arms[1].name: expected a name not used by another arm, got 'a0'"), std::string::npos)
      << e;
  std::string many = std::string(kGood) + "arms:\n";
  for (int i = 0; i < 17; ++i)
    many += "  - {name: a" + std::to_string(i) + ", base_pose: {position_m: [0, 0, 0]}}\n";
  e = Error(many);
  EXPECT_NE(e.find("arms: expected a list of 1..16"), std::string::npos) << e;
  e = Error(std::string(kGood) + "arms:\n  - {name: a0}\n");
  EXPECT_NE(e.find("arms[0].base_pose: missing"), std::string::npos) << e;
}

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
