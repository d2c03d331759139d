// The Drake viewer messages for the shipped model and scene. Oracles: the URDF's numbers
// (iiwa_link_2's cylinder: radius 0.07, length 0.11, at (0, -0.115, 0) turned by 90 deg about x), the
// scene's base pose (X_WR: (0.25, -0.55, 0.75), 90 deg about z) and joint 2's origin 0.34 m above
// the base, composed by hand.
#include "procs/drake_viewer/drake_viewer.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "base/source_paths.h"
#include "base/test_command.h"
#include "procs/drake_viewer/drake_viewer_process.h"

namespace orbed::viewer {
namespace {

struct Fixture {
  sim::Scene scene = sim::LoadSceneFile(SourceTreePath(sim::kDefaultSceneRelativePath));
  sim::RobotModel model =
      sim::RobotModel::LoadFile(SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath));
};

int Find(const orbed::viewer_draw_t& d, const std::string& name, int32_t robot) {
  for (int i = 0; i < d.num_links; ++i) {
    if (d.link_name[i] == name && d.robot_num[i] == robot) return i;
  }
  return -1;
}

TEST(DrakeViewer, LoadsBothRobotsAndTheSceneWithTheUrdfsGeometry) {
  const Fixture f;
  const orbed::viewer_load_robot_t load = MakeLoadRobot(f.model, &f.scene);
  EXPECT_EQ(load.num_links, 2 * f.model.num_links() + static_cast<int>(f.scene.objects.size()));
  EXPECT_EQ(load.num_links, static_cast<int>(load.link.size()));
  const orbed::viewer_link_data_t* link2 = nullptr;
  for (const auto& link : load.link) {
    if (link.name == "iiwa_link_2" && link.robot_num == kRealRobot) link2 = &link;
  }
  ASSERT_NE(link2, nullptr);
  ASSERT_EQ(link2->num_geom, 3);  // a cylinder and two spheres
  const orbed::viewer_geometry_data_t& cylinder = link2->geom[0];
  EXPECT_EQ(cylinder.type, int{orbed::viewer_geometry_data_t::CYLINDER});
  ASSERT_EQ(cylinder.num_float_data, 2);
  EXPECT_FLOAT_EQ(cylinder.float_data[0], 0.07f);
  EXPECT_FLOAT_EQ(cylinder.float_data[1], 0.11f);
  EXPECT_FLOAT_EQ(cylinder.position[1], -0.115f);
  const float c = static_cast<float>(std::sqrt(0.5));
  EXPECT_NEAR(std::abs(cylinder.quaternion[0]), c, 1e-6);
  EXPECT_NEAR(std::abs(cylinder.quaternion[1]), c, 1e-6);
  EXPECT_EQ(link2->geom[1].type, int{orbed::viewer_geometry_data_t::SPHERE});
  EXPECT_FLOAT_EQ(link2->geom[1].float_data[0], 0.07f);
  EXPECT_LT(link2->geom[1].color[3], 1.0f + 1e-6f);
}

TEST(DrakeViewer, DrawsTheRealRobotAtItsPosesAndTheVirtualOneAtTheRegistration) {
  const Fixture f;
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(7);
  Eigen::VectorXd q_target = q;
  q_target[0] = M_PI / 2;
  Eigen::Isometry3d X_WV = f.scene.X_WR;
  X_WV.translation().x() += 0.1;
  const orbed::viewer_draw_t d =
      MakeDraw(f.model, &f.scene, f.scene.X_WR, q, X_WV, q_target, 1'700'000'000'123'456);
  EXPECT_EQ(d.timestamp, 1'700'000'000'123);
  const int real2 = Find(d, "iiwa_link_2", kRealRobot);
  ASSERT_GE(real2, 0);
  EXPECT_NEAR(d.position[real2][0], 0.25, 1e-6);
  EXPECT_NEAR(d.position[real2][1], -0.55, 1e-6);
  EXPECT_NEAR(d.position[real2][2], 0.75 + 0.34, 1e-6);
  const int virtual2 = Find(d, "iiwa_link_2", kVirtualRobot);
  ASSERT_GE(virtual2, 0);
  EXPECT_NEAR(d.position[virtual2][0], 0.35, 1e-6);
  // The virtual link 1: the base's 90 deg and joint 1's 90 deg about z: half a turn about z.
  const int virtual1 = Find(d, "iiwa_link_1", kVirtualRobot);
  ASSERT_GE(virtual1, 0);
  EXPECT_NEAR(std::abs(d.quaternion[virtual1][3]), 1.0, 1e-6);
  // Every scene object at its pose.
  for (const sim::SceneObject& o : f.scene.objects) {
    const int k = Find(d, o.name, kScene);
    ASSERT_GE(k, 0) << o.name;
    EXPECT_NEAR(d.position[k][2], o.X_WO.translation().z(), 1e-6) << o.name;
  }
  // Before a registration the virtual robot is drawn where the real one is.
  const orbed::viewer_draw_t before = MakeDraw(f.model, nullptr, f.scene.X_WR, q, std::nullopt, q_target, 0);
  EXPECT_EQ(before.num_links, 2 * f.model.num_links());
  EXPECT_EQ(before.position[Find(before, "iiwa_link_2", kVirtualRobot)],
            before.position[Find(before, "iiwa_link_2", kRealRobot)]);
}

TEST(DrakeViewer, CommandLine) {
  EXPECT_EQ(test::RunCommand(RunViewerBridge, "orbed-drake-viewer", {"--rate-hz", "0"}).code == 0, false);
  const test::CommandRun bad_scene = test::RunCommand(
      RunViewerBridge, "orbed-drake-viewer", {"--scene", "/nonexistent.yaml", "--lcm-url", "memq://"});
  EXPECT_EQ(bad_scene.code, 1);
  EXPECT_NE(bad_scene.err.find("nonexistent"), std::string::npos) << bad_scene.err;
  EXPECT_EQ(test::RunCommand(RunViewerBridge, "orbed-drake-viewer",
                             {"--lcm-url", "memq://", "--duration-s", "0.05"})
                .code,
            0);
}

}  // namespace
}  // namespace orbed::viewer
