// The long-throw depth camera against closed forms: the distance along a pixel's ray to the robot
// base's cylinder, the range limits, OpenCV's PNG decoder reading the payload back as the client
// does, and the client's unprojection (hl2ss_3dcv) from the mode-2 tables and the mode-1 pose.
#include "procs/hl2ss/rm_depth.h"

#include <cmath>
#include <cstring>
#include <optional>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "base/source_paths.h"
#include "procs/hl2ss/frames.h"
#include "render/room_mesh.h"
#include "sim/robot_model.h"

namespace orbed::hl2ss {
namespace {

constexpr double kBaseRadius = 0.1;   // iiwa_link_0's collision cylinder (sim/models/iiwa7.urdf)
constexpr double kBaseHeight = 0.15;  // from z_R = 0 to 0.15

class LongThrowTest : public ::testing::Test {
 protected:
  LongThrowTest()
      : robot_(sim::RobotModel::LoadFile(SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath))),
        room_(robot_, render::SceneGeometry{}) {
    X_WR_.translation() = Eigen::Vector3d(1.0, 0.5, 0.75);
    X_WR_.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    room_.PoseRobot(Eigen::VectorXd::Zero(robot_.num_joints()), X_WR_);
  }

  // The head that puts the depth camera at p_WZ looking at p_WT.
  Eigen::Isometry3d HeadFor(const Eigen::Vector3d& p_WZ, const Eigen::Vector3d& p_WT) const {
    return geometry::LookAt(p_WZ, p_WT) * options_.X_HZ.inverse();
  }

  // The distance from p_W along the unit direction d_W to the base cylinder's side, if it hits
  // the side between the rims (closed form: a quadratic in the base frame).
  std::optional<double> BaseSideDistance(const Eigen::Vector3d& p_W, const Eigen::Vector3d& d_W,
                                         double margin_m) const {
    const Eigen::Vector3d p = X_WR_.inverse() * p_W, d = X_WR_.linear().transpose() * d_W;
    const double a = d.x() * d.x() + d.y() * d.y();
    const double b = 2 * (p.x() * d.x() + p.y() * d.y());
    const double c = p.x() * p.x() + p.y() * p.y() - kBaseRadius * kBaseRadius;
    const double disc = b * b - 4 * a * c;
    if (a < 1e-12 || disc < 0) return std::nullopt;
    const double t = (-b - std::sqrt(disc)) / (2 * a);
    const double z = p.z() + t * d.z();
    if (t <= 0 || z < margin_m || z > kBaseHeight - margin_m) return std::nullopt;
    return t;
  }

  sim::RobotModel robot_;
  render::RoomMesh room_;
  Eigen::Isometry3d X_WR_{Eigen::Isometry3d::Identity()};
  LongThrowOptions options_;
};

TEST_F(LongThrowTest, DepthOnTheRobotBaseIsTheDistanceAlongTheRay) {
  const Eigen::Vector3d axis = X_WR_ * Eigen::Vector3d(0, 0, 0.075);
  const Eigen::Vector3d p_WZ = axis + Eigen::Vector3d(-1.1, -0.6, 0.25);
  const Eigen::Isometry3d X_WH = HeadFor(p_WZ, axis);
  LongThrowCamera camera(options_);
  LongThrowFrame frame;
  camera.Render(room_.mesh(), X_WH, &frame);
  const Eigen::Isometry3d X_WZ = camera.X_WZ(X_WH);
  ASSERT_TRUE(X_WZ.translation().isApprox(p_WZ, 1e-9));
  const geometry::Intrinsics& K = options_.intrinsics;
  int checked = 0;
  double worst_mm = 0;
  for (int v = 0; v < kLongThrowHeight; ++v) {
    for (int u = 0; u < kLongThrowWidth; ++u) {
      const Eigen::Vector3d d_W =
          X_WZ.linear() * Eigen::Vector3d((u - K.cx_px) / K.fx_px, (v - K.cy_px) / K.fy_px, 1).normalized();
      const auto t = BaseSideDistance(p_WZ, d_W, 0.01);
      if (!t) continue;
      // Off the silhouette, where the 24-gon the renderer draws stays within ~1 mm of the circle.
      const Eigen::Vector3d hit_R = X_WR_.inverse() * (p_WZ + *t * d_W);
      const Eigen::Vector3d normal_W = X_WR_.linear() * Eigen::Vector3d(hit_R.x(), hit_R.y(), 0).normalized();
      if (-normal_W.dot(d_W) < 0.7) continue;
      const double error_mm = std::abs(frame.depth_mm.at<std::uint16_t>(v, u) - 1000.0 * *t);
      worst_mm = std::max(worst_mm, error_mm);
      EXPECT_LT(error_mm, 2.0) << "pixel " << u << "," << v << " depth "
                               << frame.depth_mm.at<std::uint16_t>(v, u);
      ++checked;
    }
  }
  EXPECT_GT(checked, 200);
  std::printf("%d base pixels, worst error %.2f mm\n", checked, worst_mm);
  // Active brightness: 10 000 / r² at the principal pixel's neighbour on the base.
  const int u = 160, v = 144;
  const double r_m = frame.depth_mm.at<std::uint16_t>(v, u) / 1000.0;
  ASSERT_GT(r_m, 0);
  // (r is known to ±0.5 mm from the depth's rounding: d(AB)/dr = −2·10⁴/r³.)
  EXPECT_NEAR(frame.ab.at<std::uint16_t>(v, u), 10000.0 / (r_m * r_m),
              1.0 + 2e4 * 0.0005 / (r_m * r_m * r_m));
  // Nothing behind the robot (no scene objects): invalid.
  EXPECT_EQ(frame.depth_mm.at<std::uint16_t>(0, 0), 0);
  EXPECT_EQ(frame.ab.at<std::uint16_t>(0, 0), 0);
}

TEST_F(LongThrowTest, OutOfRangeIsTheInvalidValue) {
  const Eigen::Vector3d axis = X_WR_ * Eigen::Vector3d(0, 0, 0.075);
  LongThrowCamera camera(options_);
  LongThrowFrame frame;
  for (double distance_m : {0.3, 7.0}) {  // the surface at 0.2 m and 6.9 m: outside [0.5, 5.8] m
    const Eigen::Vector3d p_WZ = axis + Eigen::Vector3d(-distance_m, 0, 0);
    camera.Render(room_.mesh(), HeadFor(p_WZ, axis), &frame);
    EXPECT_EQ(cv::countNonZero(frame.depth_mm), 0) << distance_m;
    EXPECT_EQ(cv::countNonZero(frame.ab), 0) << distance_m;
  }
  camera.Render(room_.mesh(), HeadFor(axis + Eigen::Vector3d(-2.0, 0, 0), axis), &frame);
  EXPECT_GT(cv::countNonZero(frame.depth_mm), 100);  // and at 1.9 m it sees the base
}

TEST_F(LongThrowTest, PngPayloadDecodesToTheSameArrays) {
  const Eigen::Vector3d axis = X_WR_ * Eigen::Vector3d(0, 0, 0.3);
  LongThrowCamera camera(options_);
  LongThrowFrame frame;
  camera.Render(room_.mesh(), HeadFor(axis + Eigen::Vector3d(-1.5, 0.4, 0.3), axis), &frame);
  std::vector<std::uint8_t> payload;
  std::string error;
  const std::uint64_t ticks = 0x0123456789ABCDEFULL;
  ASSERT_TRUE(EncodeLongThrowPayload(frame, ticks, &payload, &error)) << error;
  ASSERT_GT(payload.size(), 8u + 8u);
  const std::uint8_t png_signature[8] = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
  EXPECT_EQ(std::memcmp(payload.data(), png_signature, 8), 0);
  std::uint64_t got_ticks = 0;
  std::memcpy(&got_ticks, payload.data() + payload.size() - 8, 8);
  EXPECT_EQ(got_ticks, ticks);
  // hl2ss.py: imdecode(payload[:-8], IMREAD_UNCHANGED); h, w, _ = shape; view as u16 (2h, w).
  const cv::Mat composite = cv::imdecode(
      cv::Mat(1, static_cast<int>(payload.size() - 8), CV_8UC1, payload.data()), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(composite.type(), CV_8UC4);
  ASSERT_EQ(composite.rows, kLongThrowHeight);
  ASSERT_EQ(composite.cols, kLongThrowWidth);
  ASSERT_TRUE(composite.isContinuous());
  const cv::Mat image(2 * kLongThrowHeight, kLongThrowWidth, CV_16UC1,
                      const_cast<std::uint8_t*>(composite.ptr<std::uint8_t>(0)));
  EXPECT_EQ(cv::norm(image.rowRange(0, kLongThrowHeight), frame.depth_mm, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(image.rowRange(kLongThrowHeight, 2 * kLongThrowHeight), frame.ab, cv::NORM_INF), 0);
  EXPECT_GT(cv::countNonZero(frame.depth_mm), 1000);
  LongThrowFrame bad;
  EXPECT_FALSE(EncodeLongThrowPayload(bad, 0, &payload, &error));
}

TEST_F(LongThrowTest, CalibrationRaysTimesDepthReproduceThePoint) {
  const std::vector<std::uint8_t> bytes = PackLongThrowCalibration(options_);
  constexpr int P = kLongThrowWidth * kLongThrowHeight;
  ASSERT_EQ(bytes.size(), static_cast<size_t>(4 * P + 16 + 1 + 4) * 4);
  std::vector<float> f(bytes.size() / 4);
  std::memcpy(f.data(), bytes.data(), bytes.size());
  const float* uv2x = f.data();
  const float* uv2y = uv2x + P;
  Eigen::Matrix4d E;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) E(r, c) = f[2 * P + 4 * r + c];
  const float scale = f[2 * P + 16];
  const float* mapx = f.data() + 2 * P + 17;
  const float* mapy = mapx + P;
  const float* k = mapy + P;
  EXPECT_EQ(scale, 1000.0f);
  const geometry::Intrinsics& K = options_.intrinsics;
  EXPECT_NEAR(k[0], K.fx_px, 1e-3);
  EXPECT_NEAR(k[1], K.fy_px, 1e-3);
  EXPECT_NEAR(k[2], K.cx_px, 1e-3);
  EXPECT_NEAR(k[3], K.cy_px, 1e-3);
  EXPECT_NEAR(mapx[5 * kLongThrowWidth + 7], 7.5, 1e-3);  // the sensor's corner convention
  EXPECT_NEAR(mapy[5 * kLongThrowWidth + 7], 5.5, 1e-3);

  // A head whose estimate equals the truth; the client's unprojection of every base pixel.
  const Eigen::Vector3d axis = X_WR_ * Eigen::Vector3d(0, 0, 0.075);
  const Eigen::Vector3d p_WZ = axis + Eigen::Vector3d(-0.9, 0.7, 0.3);
  const Eigen::Isometry3d X_WH = HeadFor(p_WZ, axis);
  LongThrowCamera camera(options_);
  LongThrowFrame frame;
  camera.Render(room_.mesh(), X_WH, &frame);
  const std::array<float, 16> pose_f = PoseMatrixRowMajor(RigNodePoseForClient(X_WH, options_));
  Eigen::Matrix4d pose;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) pose(r, c) = pose_f[4 * r + c];
  const Eigen::Matrix4d camera_to_world = E.inverse() * pose;  // camera_to_rignode @ reference_to_world
  const Eigen::Isometry3d X_WZ = camera.X_WZ(X_WH);
  int checked = 0;
  for (int v = 0; v < kLongThrowHeight; v += 3) {
    for (int u = 0; u < kLongThrowWidth; u += 3) {
      const std::uint16_t depth = frame.depth_mm.at<std::uint16_t>(v, u);
      const int i = v * kLongThrowWidth + u;
      const Eigen::Vector3d xy1(uv2x[i], uv2y[i], 1.0);
      const Eigen::Vector3d d_W = X_WZ.linear() * xy1.normalized();
      const auto t = BaseSideDistance(p_WZ, d_W, 0.01);
      if (depth == 0 || !t) continue;
      const Eigen::Vector3d hit_R = X_WR_.inverse() * (p_WZ + *t * d_W);
      if (-(X_WR_.linear() * Eigen::Vector3d(hit_R.x(), hit_R.y(), 0).normalized()).dot(d_W) < 0.7) continue;
      const double z = depth / (xy1.norm() * scale);  // rm_depth_normalize
      const Eigen::Vector3d p_Z = xy1 * z;            // rm_depth_to_points
      const Eigen::RowVector4d p_D = Eigen::RowVector4d(p_Z.x(), p_Z.y(), p_Z.z(), 1) * camera_to_world;
      const Eigen::Vector3d p_W = X_WD() * Eigen::Vector3d(p_D(0), p_D(1), p_D(2));
      EXPECT_LT((p_W - (p_WZ + *t * d_W)).norm(), 2e-3) << u << "," << v;
      ++checked;
    }
  }
  EXPECT_GT(checked, 20);
}

TEST(LongThrowOptionsTest, RefusesWrongSizeOrRange) {
  LongThrowOptions o;
  o.intrinsics.width_px = 640;
  EXPECT_THROW(LongThrowCamera{o}, std::invalid_argument);
  o = LongThrowOptions{};
  o.max_range_m = 0.4;
  EXPECT_THROW(LongThrowCamera{o}, std::invalid_argument);
  EXPECT_NEAR(LongThrowIntrinsics().fx_px, 160.0 / std::tan(37.5 * M_PI / 180.0), 1e-9);
}

}  // namespace
}  // namespace orbed::hl2ss
