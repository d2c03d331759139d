/// @file
/// orbed-render-snapshot: writes the pictures of what the testbed's headset shows, for the README:
///   <out>/camera_frame.png     an HMD_CAMERA frame: the shipped OR scene and the real iiwa, rendered
///                              from a bedside head pose (HoloLens PV intrinsics)
///   <out>/reflective_view.png  a REFLECTIVE_VIEW: a frame captured from the foot of the table (the
///                              real robot from the TRUE pose) with the virtual robot drawn as a
///                              hologram from the device's estimate of that pose (2 cm, 0.8 deg SLAM
///                              error) and a registration X_WV that is 3 cm / 2 deg off
/// Deterministic (no randomness). Usage: orbed-render-snapshot [--out DIR] (default docs/images under
/// the source tree, orbed::SourceDir(): $ORBED_SOURCE_DIR, else the tree it was built from).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "base/source_paths.h"
#include "base/units.h"
#include "hmd_emulator/gaze.h"
#include "hmd_emulator/reflective.h"
#include "hmd_emulator/renderer.h"
#include "hmd_emulator/scene_geometry.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace {

void Caption(cv::Mat* image, const std::string& text) {
  cv::rectangle(*image, cv::Rect(0, 0, image->cols, 34), cv::Scalar(30, 30, 30), cv::FILLED);
  cv::putText(*image, text, cv::Point(12, 24), cv::FONT_HERSHEY_SIMPLEX, 0.62, cv::Scalar(235, 235, 235), 1,
              cv::LINE_AA);
}

}  // namespace

int main(int argc, char** argv) {
  std::string out = orbed::SourceTreePath("docs/images");
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
      std::printf(
          "usage: orbed-render-snapshot [--out DIR]\n"
          "Writes camera_frame.png and reflective_view.png (default DIR: "
          "$ORBED_SOURCE_DIR/docs/images).\n");
      return 0;
    } else if (std::strcmp(argv[i], "--out") == 0 && i + 1 < argc) {
      out = argv[++i];
    } else {
      std::fprintf(stderr, "orbed-render-snapshot: unknown argument '%s' (try --help)\n", argv[i]);
      return 2;
    }
  }
  try {
    namespace geometry = orbed::geometry;
    namespace hmd = orbed::hmd;
    namespace sim = orbed::sim;
    const sim::Scene scene = sim::LoadSceneFile(orbed::SourceTreePath(sim::kDefaultSceneRelativePath));
    const sim::RobotModel robot =
        sim::LoadRobotForScene(orbed::SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath), scene);
    Eigen::VectorXd q_deg(7);
    q_deg << -10, 40, 0, -65, 0, 55, 0;
    const Eigen::VectorXd q = sim::DegToRad(q_deg);
    hmd::SceneGeometry g = hmd::SceneGeometry::MakeOperatingRoom(scene, robot, q, scene.X_WR);
    hmd::Mesh mesh;
    hmd::Tessellate(g, hmd::kRealWorld, {}, &mesh);
    const geometry::Intrinsics K = geometry::Intrinsics::HoloLensPv();
    hmd::Renderer renderer(K);

    // 1. A camera frame from the bedside.
    cv::Mat frame;
    renderer.Render(mesh, geometry::LookAt({1.75, -2.15, 1.7}, {0.2, -0.35, 1.05}), &frame);
    cv::Mat shown = frame.clone();
    Caption(&shown, "HMD_CAMERA  1280x720, HoloLens PV intrinsics, rendered from the true head pose");
    if (!cv::imwrite(out + "/camera_frame.png", shown)) throw std::runtime_error("cannot write " + out);

    // 2. A reflective view: captured from the foot of the table, SLAM error at capture, X_WV off.
    const Eigen::Isometry3d X_WC_true = geometry::LookAt({2.05, 0.55, 1.75}, {0.25, -0.4, 1.15});
    Eigen::Isometry3d X_CtrueCest = Eigen::Isometry3d::Identity();
    X_CtrueCest.linear() =
        Eigen::AngleAxisd(0.8 * orbed::kDegToRad, Eigen::Vector3d(0.3, 1, 0).normalized()).toRotationMatrix();
    X_CtrueCest.translation() = Eigen::Vector3d(0.015, -0.01, 0.008);
    hmd::CapturedFrame captured;
    renderer.Render(mesh, X_WC_true, &captured.bgr);
    captured.intrinsics = K;
    captured.X_WC_est = X_WC_true * X_CtrueCest;
    captured.q_rad = q;
    Eigen::Isometry3d X_RV = Eigen::Isometry3d::Identity();
    X_RV.linear() = Eigen::AngleAxisd(2.0 * orbed::kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    X_RV.translation() = Eigen::Vector3d(0.02, -0.015, 0.015);
    const Eigen::Isometry3d X_WV = scene.X_WR * X_RV;
    // D: the gaze from the capture position to the robot's elbow, hit on the spatial map.
    const int elbow = robot.FindLink("iiwa_link_4");
    const Eigen::Vector3d p_W_elbow = scene.X_WR * robot.CalcLinkPoses(q)[elbow].translation();
    const hmd::RayHit gaze =
        hmd::CastRay(g, captured.X_WC_est.translation(), p_W_elbow - captured.X_WC_est.translation());
    const double D = gaze.hit ? gaze.distance_m : (p_W_elbow - captured.X_WC_est.translation()).norm();
    hmd::Compositor compositor(robot);
    hmd::ReflectiveView view;
    compositor.ComposeReflective(captured, D, X_WV, &view);
    char text[200];
    std::snprintf(text, sizeof(text),
                  "REFLECTIVE_VIEW  hologram at X_WV over the captured frame, D = %.2f m (gaze on %s)", D,
                  gaze.hit ? gaze.body_name.c_str() : "-");
    Caption(&view.bgr, text);
    if (!cv::imwrite(out + "/reflective_view.png", view.bgr)) throw std::runtime_error("cannot write " + out);
    std::printf("wrote %s/camera_frame.png and %s/reflective_view.png\n", out.c_str(), out.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "orbed-render-snapshot: %s\n", e.what());
    return 1;
  }
  return 0;
}
