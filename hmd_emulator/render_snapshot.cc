#include "hmd_emulator/render_snapshot.h"

#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include "base/command_line.h"

#include "base/source_paths.h"
#include "base/units.h"
#include "geometry/camera_model.h"
#include "hmd_emulator/gaze.h"
#include "hmd_emulator/reflective.h"
#include "render/renderer.h"
#include "render/scene_geometry.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::hmd {
namespace {

void Caption(cv::Mat* image, const std::string& text) {
  cv::rectangle(*image, cv::Rect(0, 0, image->cols, 34), cv::Scalar(30, 30, 30), cv::FILLED);
  cv::putText(*image, text, cv::Point(12, 24), cv::FONT_HERSHEY_SIMPLEX, 0.62, cv::Scalar(235, 235, 235), 1,
              cv::LINE_AA);
}

// Renders both pictures into `dir`; throws when they cannot be made or written.
void WriteSnapshots(const std::string& dir) {
  const sim::Scene scene = sim::LoadSceneFile(SourceTreePath(sim::kDefaultSceneRelativePath));
  const sim::RobotModel robot =
      sim::LoadRobotForScene(SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath), scene);
  Eigen::VectorXd q_deg(7);
  q_deg << -10, 40, 0, -65, 0, 55, 0;
  const Eigen::VectorXd q = sim::DegToRad(q_deg);
  render::SceneGeometry g = render::SceneGeometry::MakeOperatingRoom(scene, robot, q, scene.X_WR);
  render::Mesh mesh;
  render::Tessellate(g, render::kRealWorld, {}, &mesh);
  const geometry::Intrinsics K = geometry::Intrinsics::HoloLensPv();
  render::Renderer renderer(K);

  // 1. A camera frame from the bedside.
  cv::Mat frame;
  renderer.Render(mesh, geometry::LookAt({1.75, -2.15, 1.7}, {0.2, -0.35, 1.05}), &frame);
  cv::Mat shown = frame.clone();
  Caption(&shown, "HMD_CAMERA  1280x720, HoloLens PV intrinsics, rendered from the true head pose");
  if (!cv::imwrite(dir + "/camera_frame.png", shown)) throw std::runtime_error("cannot write " + dir);

  // 2. A reflective view: captured from the foot of the table, SLAM error at capture, X_WV off.
  const Eigen::Isometry3d X_WC_true = geometry::LookAt({2.05, 0.55, 1.75}, {0.25, -0.4, 1.15});
  Eigen::Isometry3d X_CtrueCest = Eigen::Isometry3d::Identity();
  X_CtrueCest.linear() =
      Eigen::AngleAxisd(0.8 * kDegToRad, Eigen::Vector3d(0.3, 1, 0).normalized()).toRotationMatrix();
  X_CtrueCest.translation() = Eigen::Vector3d(0.015, -0.01, 0.008);
  CapturedFrame captured;
  renderer.Render(mesh, X_WC_true, &captured.bgr);
  captured.intrinsics = K;
  captured.X_WC_est = X_WC_true * X_CtrueCest;
  captured.q_rad = q;
  Eigen::Isometry3d X_RV = Eigen::Isometry3d::Identity();
  X_RV.linear() = Eigen::AngleAxisd(2.0 * kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X_RV.translation() = Eigen::Vector3d(0.02, -0.015, 0.015);
  const Eigen::Isometry3d X_WV = scene.X_WR * X_RV;
  // D: the gaze from the capture position to the robot's elbow, hit on the spatial map.
  const int elbow = robot.FindLink("iiwa_link_4");
  const Eigen::Vector3d p_W_elbow = scene.X_WR * robot.CalcLinkPoses(q)[elbow].translation();
  const RayHit gaze =
      CastRay(g, captured.X_WC_est.translation(), p_W_elbow - captured.X_WC_est.translation());
  const double D = gaze.hit ? gaze.distance_m : (p_W_elbow - captured.X_WC_est.translation()).norm();
  Compositor compositor(robot);
  ReflectiveView view;
  compositor.ComposeReflective(captured, D, X_WV, &view);
  char text[200];
  std::snprintf(text, sizeof(text),
                "REFLECTIVE_VIEW  hologram at X_WV over the captured frame, D = %.2f m (gaze on %s)", D,
                gaze.hit ? gaze.body_name.c_str() : "-");
  Caption(&view.bgr, text);
  if (!cv::imwrite(dir + "/reflective_view.png", view.bgr)) throw std::runtime_error("cannot write " + dir);
}

}  // namespace

int RunRenderSnapshot(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-render-snapshot: write camera_frame.png (an HMD_CAMERA frame) and reflective_view.png (a\n"
      "REFLECTIVE_VIEW with a hologram 3 cm / 2 deg off), the README's pictures. Deterministic."};
  AddVersionFlag(&app);
  std::string dir = SourceTreePath("docs/images");
  app.add_option("--out", dir,
                 "Existing folder for the pictures (default: docs/images under $ORBED_SOURCE_DIR, else "
                 "under the source tree it was built from)")
      ->check(CLI::ExistingDirectory);
  if (const auto code = ParseArguments(&app, argc, argv, out, err)) return *code;
  try {
    WriteSnapshots(dir);
  } catch (const std::exception& e) {
    err << "orbed-render-snapshot: " << e.what() << "\n";
    return 1;
  }
  out << "wrote " << dir << "/camera_frame.png and " << dir << "/reflective_view.png\n";
  return 0;
}

}  // namespace orbed::hmd
