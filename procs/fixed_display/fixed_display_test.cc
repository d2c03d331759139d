// The fixed monitor. Oracles: the orbit's closed form (the camera at the configured point, looking
// at the centre), the keys' stated steps, the pinhole projection of the robot's wrist (link 6's
// origin) computed here from the model's forward kinematics (the picture shows a robot body exactly
// there), and
// procs/assistant/assistant.yaml (the emulated assistant's monitor camera is this default).
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <lcm/lcm-cpp.hpp>
#include <opencv2/imgcodecs.hpp>
#include <orbed/guidance_t.hpp>
#include <orbed/image_t.hpp>
#include <orbed/robot_state_t.hpp>

#include "base/source_paths.h"
#include "base/test_command.h"
#include "base/units.h"
#include "lcmtypes/contract/conversions.h"
#include "procs/fixed_display/fixed_display.h"
#include "procs/fixed_display/fixed_display_process.h"
#include "sim/guidance_messages.h"

namespace orbed::fixed_display {
namespace {

Eigen::VectorXd Deg(std::vector<double> q) {
  Eigen::VectorXd v = Eigen::Map<Eigen::VectorXd>(q.data(), q.size());
  return v * kDegToRad;
}

sim::RobotModel Model() {
  return sim::RobotModel::LoadFile(SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath));
}

TEST(FixedView, TheOrbitPassesThroughTheConfiguredCameraAndLooksAtTheCentre) {
  const Eigen::Vector3d c(0.25, -0.55, 1.25), p_WD(1.5, 0.3, 1.8);
  const OrbitView view = OrbitView::Through(p_WD, c);
  EXPECT_NEAR(view.distance_m, (p_WD - c).norm(), 1e-12);
  EXPECT_NEAR(view.elevation_rad, std::asin(0.55 / (p_WD - c).norm()), 1e-12);
  EXPECT_NEAR(view.azimuth_rad, std::atan2(0.85, 1.25), 1e-12);
  const Eigen::Isometry3d X_WD = view.X_WD(c);
  EXPECT_NEAR((X_WD.translation() - p_WD).norm(), 0.0, 1e-12);
  EXPECT_NEAR((X_WD.linear().col(2) - (c - p_WD).normalized()).norm(), 0.0, 1e-12);  // z toward c
  EXPECT_NEAR(X_WD.linear().col(0).z(), 0.0, 1e-12);                                 // x horizontal
  EXPECT_THROW(OrbitView::Through(c + Eigen::Vector3d(0.3, 0, 0), c), std::invalid_argument);
  EXPECT_THROW(OrbitView::Through(c + Eigen::Vector3d(0.1, 0, 2.0), c), std::invalid_argument);
}

TEST(FixedView, KeysTurnRaiseAndZoomByTheirStepsWithinTheLimits) {
  OrbitView home;
  home.azimuth_rad = 0.5;
  home.elevation_rad = 0.2;
  home.distance_m = 2.0;
  const OrbitView d = *ApplyKey('d', home, home);
  EXPECT_NEAR(d.azimuth_rad, 0.5 + 15 * kDegToRad, 1e-12);
  EXPECT_NEAR(ApplyKey('a', home, home)->azimuth_rad, 0.5 - 15 * kDegToRad, 1e-12);
  EXPECT_NEAR(ApplyKey('w', home, home)->elevation_rad, 0.2 + 10 * kDegToRad, 1e-12);
  EXPECT_NEAR(ApplyKey('+', home, home)->distance_m, 1.7, 1e-12);
  EXPECT_NEAR(ApplyKey('-', home, home)->distance_m, 2.0 / 0.85, 1e-12);
  OrbitView v = home;
  for (int i = 0; i < 20; ++i) v = *ApplyKey('w', v, home);
  EXPECT_EQ(v.elevation_rad, OrbitView::kMaxElevation_rad);
  for (int i = 0; i < 30; ++i) v = *ApplyKey('+', v, home);
  EXPECT_EQ(v.distance_m, OrbitView::kMinDistance_m);
  for (int i = 0; i < 30; ++i) v = *ApplyKey('d', v, home);  // 450 deg: wrapped into (-180, 180]
  EXPECT_NEAR(std::remainder(v.azimuth_rad - (0.5 + 450 * kDegToRad), 2 * M_PI), 0.0, 1e-9);
  EXPECT_LE(std::abs(v.azimuth_rad), M_PI);
  const OrbitView r = *ApplyKey('r', v, home);
  EXPECT_EQ(r.azimuth_rad, home.azimuth_rad);
  EXPECT_EQ(r.distance_m, home.distance_m);
  EXPECT_FALSE(ApplyKey('x', home, home).has_value());
  EXPECT_FALSE(ApplyKey(-1, home, home).has_value());  // cv::waitKey without a key
}

TEST(FixedView, TheDefaultCameraIsTheAssistantsMonitor) {
  const YAML::Node camera =
      YAML::LoadFile(SourceTreePath("procs/assistant/assistant.yaml"))["assistant"]["monitor"]["camera_m"];
  ASSERT_TRUE(camera.IsSequence());
  ASSERT_EQ(camera.size(), 3u);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(camera[i].as<double>(), kDefaultCamera_m[i]);
}

// Projects p_W with the monitor's pinhole camera at X_WD.
Eigen::Vector2d Project(const geometry::Intrinsics& K, const Eigen::Isometry3d& X_WD,
                        const Eigen::Vector3d& p_W) {
  const Eigen::Vector3d p_D = X_WD.inverse() * p_W;
  return {K.fx_px * p_D.x() / p_D.z() + K.cx_px, K.fy_px * p_D.y() / p_D.z() + K.cy_px};
}

TEST(FixedView, ThePictureShowsTheTargetConfigurationWhereTheCameraSeesIt) {
  const sim::RobotModel model = Model();
  FixedViewRenderer renderer(model, nullptr, PictureOptions{});
  const Eigen::Isometry3d X_WR = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d c = OrbitCentre(X_WR);
  const Eigen::Isometry3d X_WD = OrbitView::Through(Eigen::Vector3d(2.0, 0.0, 1.0), c).X_WD(c);
  // Two targets whose link-6 origins lie far apart (folded forward vs upright).
  const Eigen::VectorXd q_up = Deg({0, 0, 0, 0, 0, 0, 0}), q_bent = Deg({0, 60, 0, -90, 0, 0, 0});
  const int link6 = model.FindLink("iiwa_link_6");
  ASSERT_GE(link6, 0);
  auto pixel_of = [&](const Eigen::VectorXd& q) {
    const Eigen::Vector2d uv =
        Project(renderer.intrinsics(), X_WD, X_WR * model.CalcLinkPoses(q)[link6].translation());
    return cv::Point(static_cast<int>(std::lround(uv.x())), static_cast<int>(std::lround(uv.y())));
  };
  cv::Mat ids_up, ids_bent;
  const cv::Mat up = renderer.Render(q_up, X_WR, X_WD, "", &ids_up);
  renderer.Render(q_bent, X_WR, X_WD, "caption", &ids_bent);
  ASSERT_EQ(up.cols, 640);
  ASSERT_EQ(up.rows, 480);
  const cv::Point a = pixel_of(q_up), b = pixel_of(q_bent);
  ASSERT_GT(cv::norm(a - b), 40.0);
  const auto& bodies = renderer.geometry().bodies();
  auto is_robot = [&](const cv::Mat& ids, cv::Point p) {
    const int id = ids.at<int>(p);
    return id >= 0 && bodies[id].kind == render::BodyKind::kRealRobot;
  };
  EXPECT_TRUE(is_robot(ids_up, a));
  EXPECT_TRUE(is_robot(ids_bent, b));
  EXPECT_FALSE(is_robot(ids_up, b));  // nothing of the upright arm where the bent one's wrist is
  EXPECT_FALSE(is_robot(ids_bent, a));
}

orbed::robot_state_t State(const Eigen::Isometry3d& X_WR) {
  orbed::robot_state_t state{};
  state.X_WR = ToPose(X_WR);
  state.num_joints = 7;
  state.joint_position.assign(7, 0.0);
  state.joint_limit_hit.assign(7, false);
  return state;
}

orbed::guidance_t Guidance(const sim::RobotModel& model, int8_t mode, const Eigen::VectorXd& q_target) {
  orbed::guidance_t g{};
  g.mode = mode;
  g.num_joints = 7;
  g.target_position = FromVectorX(q_target);
  g.current_position.assign(7, 0.0);
  g.error_deg.assign(7, 0.0);
  g.joint_kind = guidance::JointKinds(model);
  g.next_joint = 0;
  return g;
}

TEST(FixedDisplayProcess, PublishesTheTargetInTheFixedModeRenderedOnceFromTheHomeCamera) {
  const sim::RobotModel model = Model();
  const sim::Scene scene = sim::LoadSceneFile(SourceTreePath(sim::kDefaultSceneRelativePath));
  CommonFlags flags("fixed-display-test");
  flags.lcm_url = "memq://";
  flags.duration_s = 2.0;  // counted from here: the messages below are queued and handled at Run's start
  FixedDisplayOptions options;
  options.stale_after_s = 3600;  // however slowly this machine runs
  FixedDisplay display(flags, options);
  struct Collector {
    std::vector<orbed::image_t> seen;
    void On(const lcm::ReceiveBuffer*, const std::string&, const orbed::image_t* msg) {
      seen.push_back(*msg);
    }
  } collector;
  lcm::LCM& lcm = display.process().lcm();
  lcm.subscribe("FIXED_VIEW", &Collector::On, &collector);
  auto state = State(scene.X_WR);
  lcm.publish("ROBOT_STATE", &state);
  auto bad = Guidance(model, orbed::guidance_t::MODE_FIXED_DISPLAY, Deg({0, 30, 0, -60, 0, 45, 0}));
  bad.target_position[3] = std::nan("");
  lcm.publish("GUIDANCE", &bad);
  auto good = Guidance(model, orbed::guidance_t::MODE_FIXED_DISPLAY, Deg({0, 30, 0, -60, 0, 45, 0}));
  lcm.publish("GUIDANCE", &good);
  EXPECT_EQ(display.Run(), 0);

  ASSERT_GE(collector.seen.size(), 1u);
  const orbed::image_t& first = collector.seen.front();
  EXPECT_EQ(first.pixel_format, int{orbed::image_t::FORMAT_JPEG});
  EXPECT_EQ(first.utime, first.pose_utime);
  EXPECT_NEAR((FromPose(first.X_WC).translation() - kDefaultCamera_m).norm(), 0.0, 1e-9);
  const cv::Mat decoded = cv::imdecode(first.data, cv::IMREAD_COLOR);
  EXPECT_EQ(decoded.cols, 640);
  EXPECT_EQ(decoded.rows, 480);
  EXPECT_EQ(display.process().rejections().counts().at("GUIDANCE/field"), 1);

  // The same target, base and view later: the same picture sent again with the new time, not
  // rendered again; a key moves the camera and renders anew.
  const int renders = display.renders();
  const int64_t later = first.utime + 5'000'000;
  const auto again = display.PictureNow(later);
  ASSERT_TRUE(again.has_value());
  EXPECT_EQ(display.renders(), renders);
  EXPECT_EQ(again->data, first.data);
  EXPECT_EQ(again->utime, later);
  display.PressKey('d');
  ASSERT_TRUE(display.PictureNow(later).has_value());
  EXPECT_EQ(display.renders(), renders + 1);
  EXPECT_NEAR(display.view().azimuth_rad,
              OrbitView::Through(kDefaultCamera_m, OrbitCentre(scene.X_WR)).azimuth_rad + 15 * kDegToRad,
              1e-12);
}

TEST(FixedDisplayProcess, NothingInTheHeadsetModesOrWithoutAFreshGuidance) {
  const sim::RobotModel model = Model();
  CommonFlags flags("fixed-display-test");
  flags.lcm_url = "memq://";
  flags.duration_s = 1.0;
  FixedDisplayOptions options;
  options.stale_after_s = 2.0;
  FixedDisplay display(flags, options);
  EXPECT_FALSE(display.PictureNow(NowMicros()).has_value());  // nothing yet
  lcm::LCM& lcm = display.process().lcm();
  auto state = State(Eigen::Isometry3d::Identity());
  lcm.publish("ROBOT_STATE", &state);
  auto ar = Guidance(model, orbed::guidance_t::MODE_AR, Deg({0, 30, 0, -60, 0, 45, 0}));
  lcm.publish("GUIDANCE", &ar);
  EXPECT_EQ(display.Run(), 0);
  ASSERT_EQ(display.process().messages_in(), 2);  // both handled
  EXPECT_FALSE(display.PictureNow(NowMicros()).has_value());
  EXPECT_EQ(display.renders(), 0);

  // The fixed mode: a picture while the GUIDANCE is fresh, none once it is older than stale_after_s.
  FixedDisplayOptions all = options;
  all.all_modes = true;
  flags.duration_s = 1.0;
  FixedDisplay every_mode(flags, all);
  every_mode.process().lcm().publish("ROBOT_STATE", &state);
  every_mode.process().lcm().publish("GUIDANCE", &ar);
  EXPECT_EQ(every_mode.Run(), 0);
  ASSERT_EQ(every_mode.process().messages_in(), 2);
  const int64_t now = NowMicros();
  EXPECT_TRUE(every_mode.PictureNow(now).has_value());
  EXPECT_FALSE(every_mode.PictureNow(now + 3'000'000).has_value());
}

TEST(FixedDisplayProcess, CommandLine) {
  const auto help = test::RunCommand(RunFixedDisplay, "orbed-fixed-display", {"--help"});
  EXPECT_EQ(help.code, 0);
  EXPECT_NE(help.out.find(kKeyHelp), std::string::npos);
  const auto two =
      test::RunCommand(RunFixedDisplay, "orbed-fixed-display", {"--camera-m", "1,2", "--lcm-url", "memq://"});
  EXPECT_EQ(two.code, 2);
  EXPECT_NE(two.err.find("x,y,z"), std::string::npos) << two.err;
  const auto inside = test::RunCommand(RunFixedDisplay, "orbed-fixed-display",
                                       {"--camera-m", "0.25,-0.55,1.3", "--lcm-url", "memq://"});
  EXPECT_EQ(inside.code, 1);
  EXPECT_NE(inside.err.find("from the robot's middle"), std::string::npos) << inside.err;
  EXPECT_EQ(test::RunCommand(RunFixedDisplay, "orbed-fixed-display",
                             {"--lcm-url", "memq://", "--duration-s", "0.05"})
                .code,
            0);
}

}  // namespace
}  // namespace orbed::fixed_display
