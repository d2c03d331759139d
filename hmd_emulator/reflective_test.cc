// Reflective-AR display and AR view: the hologram lands where geometry::Project() says (with the capture
// pose the device believes), SLAM error at capture shows up as misalignment against the real robot
// in the captured image, D never changes the pixels, and the display panel's geometry (X_WM, K_m,
// P_m) is the paper's reversed frustum.
#include "hmd_emulator/reflective.h"

#include <cmath>
#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

#include "base/source_paths.h"
#include "geometry/camera_model.h"
#include "hmd_emulator/gaze.h"
#include "render/renderer.h"
#include "render/scene_geometry.h"
#include "sim/scene.h"

namespace orbed::hmd {
namespace {

// Centroid of the pixels carrying `id`; (-1, -1) if none.
Eigen::Vector2d Centroid(const cv::Mat& ids, int id, int* count = nullptr) {
  double su = 0, sv = 0, n = 0;
  for (int v = 0; v < ids.rows; ++v)
    for (int u = 0; u < ids.cols; ++u)
      if (ids.at<int>(v, u) == id) su += u, sv += v, n += 1;
  if (count) *count = static_cast<int>(n);
  return n > 0 ? Eigen::Vector2d(su / n, sv / n) : Eigen::Vector2d(-1, -1);
}

class ReflectiveTest : public ::testing::Test {
 protected:
  ReflectiveTest()
      : robot_(sim::RobotModel::LoadFile(orbed::SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath))),
        scene_(sim::LoadSceneFile(orbed::SourceTreePath(sim::kDefaultSceneRelativePath))) {
    Eigen::VectorXd q_deg(7);
    q_deg << 20, 40, 0, -60, 0, 50, 0;
    q_ = sim::DegToRad(q_deg);
    X_WC_true_ = geometry::LookAt({1.6, -2.0, 1.7}, {0.25, -0.45, 1.2});
  }

  // The frame the camera captures: the real scene from the TRUE pose; ids of the real bodies.
  CapturedFrame Capture(const Eigen::Isometry3d& X_WC_est, cv::Mat* real_ids) {
    render::SceneGeometry g = render::SceneGeometry::MakeOperatingRoom(scene_, robot_, q_, scene_.X_WR);
    real_geometry_ = g;
    render::Mesh mesh;
    render::Tessellate(g, render::kRealWorld, {}, &mesh);
    render::Renderer renderer(geometry::Intrinsics::HoloLensPv());
    CapturedFrame f;
    renderer.Render(mesh, X_WC_true_, &f.bgr, nullptr, real_ids);
    f.intrinsics = geometry::Intrinsics::HoloLensPv();
    f.X_WC_est = X_WC_est;
    f.q_rad = q_;
    f.utime = 123456789;
    return f;
  }

  // Sphere centre of the wrist (iiwa_link_6's only primitive) in W for base pose X_WB.
  Eigen::Vector3d WristCentre(const Eigen::Isometry3d& X_WB) const {
    const int l6 = robot_.FindLink("iiwa_link_6");
    return X_WB * robot_.CalcLinkPoses(q_)[l6] * robot_.links()[l6].collision[0].X_LG.translation();
  }

  sim::RobotModel robot_;
  sim::Scene scene_;
  render::SceneGeometry real_geometry_;
  Eigen::VectorXd q_;
  Eigen::Isometry3d X_WC_true_;
};

TEST_F(ReflectiveTest, HologramLandsWhereProjectSaysWithTheEstimatedCapturePose) {
  // SLAM error at capture: 1.5 deg of yaw and 2 cm sideways.
  Eigen::Isometry3d X_CtrueCest = Eigen::Isometry3d::Identity();
  X_CtrueCest.linear() = Eigen::AngleAxisd(0.026, Eigen::Vector3d::UnitY()).toRotationMatrix();
  X_CtrueCest.translation() = Eigen::Vector3d(0.02, 0, 0);
  const Eigen::Isometry3d X_WC_est = X_WC_true_ * X_CtrueCest;
  cv::Mat real_ids;
  const CapturedFrame frame = Capture(X_WC_est, &real_ids);
  const Eigen::Isometry3d X_WV = scene_.X_WR;  // a perfect registration

  Compositor compositor(robot_, render::OverlayStyle{}, render::TessellationOptions{24, 40, 20});
  ReflectiveView view;
  cv::Mat holo_ids;
  compositor.ComposeReflective(frame, 1.8, X_WV, &view, &holo_ids);
  EXPECT_EQ(view.source_utime, 123456789);
  EXPECT_TRUE(view.X_WV.isApprox(X_WV));
  ASSERT_EQ(view.bgr.size(), frame.bgr.size());

  // Every virtual primitive's centre, projected with the device's belief P_o(X_WC_est), lands on a
  // hologram pixel showing the body that an analytic ray from X_WC_est through that pixel hits.
  const render::SceneGeometry& holo = compositor.virtual_geometry();
  const geometry::CameraMatrix P_est = geometry::MakeCameraMatrix(frame.intrinsics.K(), X_WC_est);
  int agree = 0, total = 0;
  for (const render::Primitive& p : holo.primitives()) {
    Eigen::Vector2d uv;
    ASSERT_TRUE(geometry::Project(P_est, p.X_WG.translation(), &uv));
    const int u = static_cast<int>(std::lround(uv.x())), v = static_cast<int>(std::lround(uv.y()));
    if (u < 0 || v < 0 || u >= holo_ids.cols || v >= holo_ids.rows) continue;
    const Eigen::Vector3d ray_C((u - frame.intrinsics.cx_px) / frame.intrinsics.fx_px,
                                (v - frame.intrinsics.cy_px) / frame.intrinsics.fy_px, 1.0);
    const RayHit hit = CastRay(holo, X_WC_est.translation(), X_WC_est.linear() * ray_C, render::kVirtualOnly);
    ASSERT_TRUE(hit.hit);
    ++total;
    if (holo_ids.at<int>(v, u) == hit.body) ++agree;
  }
  EXPECT_GE(total, 9);
  EXPECT_GE(agree, total - 1) << agree << " of " << total;

  // The real robot in the captured image sits where the TRUE pose projects it, the hologram where the
  // estimate does: the SLAM error shows up as a misalignment of tens of pixels.
  const int holo_wrist = holo.FindBody("virtual/iiwa_link_6");
  const int real_wrist = real_geometry_.FindBody("iiwa_link_6");
  ASSERT_GE(holo_wrist, 0);
  ASSERT_GE(real_wrist, 0);
  Eigen::Vector2d uv_est, uv_true;
  ASSERT_TRUE(geometry::Project(P_est, WristCentre(X_WV), &uv_est));
  ASSERT_TRUE(geometry::Project(geometry::MakeCameraMatrix(frame.intrinsics.K(), X_WC_true_),
                                WristCentre(scene_.X_WR), &uv_true));
  int n_holo = 0, n_real = 0;
  const Eigen::Vector2d c_holo = Centroid(holo_ids, holo_wrist, &n_holo);
  const Eigen::Vector2d c_real = Centroid(real_ids, real_wrist, &n_real);
  ASSERT_GT(n_holo, 500);
  ASSERT_GT(n_real, 500);
  EXPECT_GT((uv_est - uv_true).norm(), 20.0);
  EXPECT_LT(((c_holo - c_real) - (uv_est - uv_true)).norm(), 2.0)
      << (c_holo - c_real).transpose() << " vs " << (uv_est - uv_true).transpose();
  // The composed image differs from the frame only where the hologram is.
  cv::Mat diff;
  cv::absdiff(view.bgr, frame.bgr, diff);
  cv::Mat ch[3];
  cv::split(diff, ch);
  const cv::Mat changed = ch[0] | ch[1] | ch[2];
  EXPECT_EQ(cv::countNonZero((changed > 0) & (holo_ids < 0)), 0);
  EXPECT_GT(cv::countNonZero(holo_ids >= 0), 5000);
}

TEST_F(ReflectiveTest, WithoutSlamErrorTheHologramCoversTheRealRobot) {
  cv::Mat real_ids;
  const CapturedFrame frame = Capture(X_WC_true_, &real_ids);
  Compositor compositor(robot_);
  ReflectiveView view;
  cv::Mat holo_ids;
  compositor.ComposeReflective(frame, 1.8, scene_.X_WR, &view, &holo_ids);
  // Same tessellation, same pose: every link's hologram pixels are that link's real pixels.
  for (const char* link : {"iiwa_link_2", "iiwa_link_4", "iiwa_link_6"}) {
    const int h = compositor.virtual_geometry().FindBody(std::string("virtual/") + link);
    const int r = real_geometry_.FindBody(link);
    int nh = 0, nr = 0;
    const Eigen::Vector2d ch = Centroid(holo_ids, h, &nh), cr = Centroid(real_ids, r, &nr);
    ASSERT_GT(nh, 200) << link;
    // The real link can be partly hidden by scene objects, the hologram never is.
    EXPECT_GE(nh, nr) << link;
    if (nh == nr) {
      EXPECT_LT((ch - cr).norm(), 1e-9) << link;
    }
  }
}

TEST_F(ReflectiveTest, DistanceChangesThePanelNotThePixels) {
  cv::Mat real_ids;
  const CapturedFrame frame = Capture(X_WC_true_, &real_ids);
  Compositor compositor(robot_);
  ReflectiveView a, b;
  compositor.ComposeReflective(frame, 0.9, scene_.X_WR, &a);
  compositor.ComposeReflective(frame, 2.4, scene_.X_WR, &b);
  EXPECT_EQ(cv::norm(a.bgr, b.bgr, cv::NORM_INF), 0);
  EXPECT_DOUBLE_EQ(a.geometry.distance_m, 0.9);
  EXPECT_DOUBLE_EQ(b.geometry.distance_m, 2.4);
  EXPECT_FALSE(a.geometry.X_WM.isApprox(b.geometry.X_WM));
  EXPECT_THROW(compositor.ComposeReflective(frame, 0.0, scene_.X_WR, &a), std::invalid_argument);
  EXPECT_THROW(compositor.ComposeReflective(frame, std::nan(""), scene_.X_WR, &a), std::invalid_argument);
}

TEST(ReflectiveGeometry, IsThePapersReversedFrustum) {
  const geometry::Intrinsics K = geometry::Intrinsics::HoloLensPv();
  const Eigen::Isometry3d X_WC = geometry::LookAt({1.0, -1.5, 1.6}, {0.2, 0.3, 1.0});
  const double D = 1.7;
  const ReflectiveGeometry g = MakeReflectiveGeometry(K, X_WC, D);
  // M: at the gaze point D along the principal ray, x kept, y and z reversed.
  const Eigen::Vector3d z_C = X_WC.linear().col(2);
  EXPECT_LT((g.X_WM.translation() - (X_WC.translation() + D * z_C)).norm(), 1e-12);
  EXPECT_LT((g.X_WM.linear().col(0) - X_WC.linear().col(0)).norm(), 1e-12);
  EXPECT_LT((g.X_WM.linear().col(1) + X_WC.linear().col(1)).norm(), 1e-12);
  EXPECT_LT((g.X_WM.linear().col(2) + z_C).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(g.K_m(1, 1), -K.fy_px);
  EXPECT_DOUBLE_EQ(g.K_m(1, 2), -K.cy_px);
  EXPECT_DOUBLE_EQ(g.distance_m, D);
  EXPECT_TRUE(g.X_WC.isApprox(X_WC));
}

TEST(ReflectiveGeometry, PanelPixelsLieOnTheirCaptureRaysAndThroughTheReversedFrustum) {
  const geometry::Intrinsics K = geometry::Intrinsics::HoloLensPv();
  const Eigen::Isometry3d X_WC = geometry::LookAt({1.0, -1.5, 1.6}, {0.2, 0.3, 1.0});
  for (double D : {0.8, 2.0}) {
    const ReflectiveGeometry g = MakeReflectiveGeometry(K, X_WC, D);
    for (const Eigen::Vector2d& px : {Eigen::Vector2d(0, 0), Eigen::Vector2d(597.2, 322.1),
                                      Eigen::Vector2d(1279, 719), Eigen::Vector2d(100, 600)}) {
      // The mirror plane (default): half way between C and M.
      const Eigen::Vector3d p_W = DisplayPanelPoint(g, px.x(), px.y());
      EXPECT_NEAR((X_WC.inverse() * p_W).z(), D / 2, 1e-12);
      Eigen::Vector2d uv;
      ASSERT_TRUE(geometry::Project(g.P_o, p_W, &uv));  // seen from the capture position: its own ray
      EXPECT_LT((uv - px).norm(), 1e-9);
      ASSERT_TRUE(geometry::Project(g.P_m, p_W, &uv));  // through P_m: the same pixel, row axis negated
      EXPECT_NEAR(uv.x(), px.x(), 1e-9);
      EXPECT_NEAR(uv.y(), px.y() - 2 * K.cy_px, 1e-9);
      // Any other panel depth in M keeps both properties.
      const Eigen::Vector3d q_W = DisplayPanelPoint(g, px.x(), px.y(), 0.3 * D);
      ASSERT_TRUE(geometry::Project(g.P_m, q_W, &uv));
      EXPECT_NEAR(uv.y(), px.y() - 2 * K.cy_px, 1e-9);
    }
  }
}

TEST_F(ReflectiveTest, ArViewEqualsTheReflectiveContentForTheSameInputs) {
  cv::Mat real_ids;
  const CapturedFrame frame = Capture(X_WC_true_, &real_ids);
  Eigen::Isometry3d X_WV = scene_.X_WR;
  X_WV.translation() += Eigen::Vector3d(0.03, -0.02, 0.01);
  Compositor compositor(robot_);
  ReflectiveView view;
  compositor.ComposeReflective(frame, 1.5, X_WV, &view);
  cv::Mat ar;
  compositor.ComposeArView(frame.bgr, frame.intrinsics, frame.X_WC_est, q_, X_WV, &ar);
  EXPECT_EQ(cv::norm(ar, view.bgr, cv::NORM_INF), 0);
  cv::Mat in_place = frame.bgr.clone();
  compositor.ComposeArView(in_place, frame.intrinsics, frame.X_WC_est, q_, X_WV, &in_place);
  EXPECT_EQ(cv::norm(in_place, view.bgr, cv::NORM_INF), 0);
  EXPECT_THROW(compositor.ComposeArView(frame.bgr, frame.intrinsics, frame.X_WC_est, Eigen::VectorXd::Zero(3),
                                        X_WV, &ar),
               std::invalid_argument);
}

}  // namespace
}  // namespace orbed::hmd
