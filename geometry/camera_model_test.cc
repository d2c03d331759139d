// Projection oracles for camera_model.h: the principal axis, and the paper's reversed frustum P_m
// against a mirror camera built by hand from plain matrices (no camera_model.h in the oracle).
#include "geometry/camera_model.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "base/units.h"

namespace orbed::geometry {
namespace {

// A generic camera pose: rotation from an axis-angle written out with Rodrigues' formula by hand.
Eigen::Matrix3d Rodrigues(Eigen::Vector3d axis, double angle) {
  axis.normalize();
  Eigen::Matrix3d k;
  k << 0, -axis.z(), axis.y(), axis.z(), 0, -axis.x(), -axis.y(), axis.x(), 0;
  return Eigen::Matrix3d::Identity() + std::sin(angle) * k + (1 - std::cos(angle)) * k * k;
}

struct Pose {
  Eigen::Matrix3d R_WC;
  Eigen::Vector3d p_WC;
  Eigen::Isometry3d Iso() const {
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.linear() = R_WC;
    X.translation() = p_WC;
    return X;
  }
};

Pose SomeCameraPose() {
  return {Rodrigues(Eigen::Vector3d(0.3, -0.8, 0.5), 2.1), Eigen::Vector3d(1.2, -0.7, 1.65)};
}

TEST(CameraModel, PointOnPrincipalAxisLandsOnPrincipalPoint) {
  const Intrinsics K = Intrinsics::HoloLensPv();
  const Pose c = SomeCameraPose();
  const CameraMatrix P = MakeCameraMatrix(K.K(), c.Iso());
  for (double z : {0.1, 0.5, 1.0, 2.5, 10.0}) {
    const Eigen::Vector3d p_W = c.p_WC + z * c.R_WC.col(2);  // on the principal ray
    Eigen::Vector2d uv;
    ASSERT_TRUE(Project(P, p_W, &uv));
    EXPECT_NEAR(uv.x(), 597.2, 1e-9);
    EXPECT_NEAR(uv.y(), 322.1, 1e-9);
  }
  // Behind the camera: not projected.
  Eigen::Vector2d uv(-1, -1);
  EXPECT_FALSE(Project(P, c.p_WC - c.R_WC.col(2), &uv));
  EXPECT_EQ(uv, Eigen::Vector2d(-1, -1));
}

TEST(CameraModel, OffAxisPointFollowsThePinholeEquations) {
  const Intrinsics K = Intrinsics::HoloLensPv();
  const Pose c = SomeCameraPose();
  const CameraMatrix P = MakeCameraMatrix(K.K(), c.Iso());
  // x right 0.2 m, y down 0.1 m at depth 2 m: u = cx + fx 0.1, v = cy + fy 0.05.
  const Eigen::Vector3d p_W = c.p_WC + c.R_WC * Eigen::Vector3d(0.2, 0.1, 2.0);
  Eigen::Vector2d uv;
  ASSERT_TRUE(Project(P, p_W, &uv));
  EXPECT_NEAR(uv.x(), 597.2 + 1545.4 * 0.1, 1e-9);
  EXPECT_NEAR(uv.y(), 322.1 + 1551.2 * 0.05, 1e-9);
}

// The reversed frustum by hand: M's centre is D along C's principal ray; its axes are C's turned π
// about x_C (x_M = x_C, y_M = -y_C, z_M = -z_C); the intrinsics have their second row negated.
TEST(CameraModel, MirrorMatrixEqualsHandBuiltReversedFrustumPointForPoint) {
  const double fx = 1545.4, fy = 1551.2, cx = 597.2, cy = 322.1;
  const Intrinsics K = Intrinsics::HoloLensPv();
  const Pose c = SomeCameraPose();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> lateral(-0.6, 0.6), depth_frac(0.05, 0.95);
  for (double D : {0.4, 1.3, 2.7}) {
    const Eigen::Vector3d x_C = c.R_WC.col(0), y_C = c.R_WC.col(1), z_C = c.R_WC.col(2);
    const Eigen::Vector3d centre_M = c.p_WC + D * z_C;
    Eigen::Matrix3d R_MW;  // rows: M's axes expressed in W
    R_MW.row(0) = x_C.transpose();
    R_MW.row(1) = -y_C.transpose();
    R_MW.row(2) = -z_C.transpose();
    Eigen::Matrix3d K_flip;
    K_flip << fx, 0, cx, 0, -fy, -cy, 0, 0, 1;

    const CameraMatrix P_m = MakeMirrorCameraMatrix(K.K(), c.Iso(), D);
    // The matrices agree (both have the same scale: last row of K is (0, 0, 1)).
    CameraMatrix P_hand;
    P_hand.leftCols<3>() = K_flip * R_MW;
    P_hand.col(3) = -K_flip * R_MW * centre_M;
    EXPECT_LT((P_m - P_hand).cwiseAbs().maxCoeff(), 1e-9 * P_hand.cwiseAbs().maxCoeff());

    for (int i = 0; i < 200; ++i) {
      // Points in front of M: between C and M, spread laterally.
      const Eigen::Vector3d p_W =
          c.p_WC + depth_frac(rng) * D * z_C + lateral(rng) * x_C + lateral(rng) * y_C;
      const Eigen::Vector3d p_M = R_MW * (p_W - centre_M);
      ASSERT_GT(p_M.z(), 0);
      const double u = fx * p_M.x() / p_M.z() + cx;
      const double v = -(fy * p_M.y() / p_M.z() + cy);
      Eigen::Vector2d uv;
      ASSERT_TRUE(Project(P_m, p_W, &uv));
      EXPECT_NEAR(uv.x(), u, 1e-6);
      EXPECT_NEAR(uv.y(), v, 1e-6);
    }
    // Beyond M (behind the reversed frustum) nothing projects.
    Eigen::Vector2d uv;
    EXPECT_FALSE(Project(P_m, c.p_WC + 1.5 * D * z_C, &uv));
  }
}

TEST(CameraModel, MirrorPoseIsHalfTurnAboutXThenDAlongTheRay) {
  const Eigen::Isometry3d X_CM = MirrorPoseInCamera(1.7);
  Eigen::Matrix3d R_expected;
  R_expected << 1, 0, 0, 0, std::cos(kPi), -std::sin(kPi), 0, std::sin(kPi), std::cos(kPi);
  EXPECT_LT((X_CM.linear() - R_expected).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((X_CM.translation() - Eigen::Vector3d(0, 0, 1.7)).norm(), 1e-12);
  const Eigen::Matrix3d K_m = MirrorIntrinsics(Intrinsics::HoloLensPv().K());
  EXPECT_DOUBLE_EQ(K_m(1, 1), -1551.2);
  EXPECT_DOUBLE_EQ(K_m(1, 2), -322.1);
  EXPECT_DOUBLE_EQ(K_m(0, 0), 1545.4);
  EXPECT_DOUBLE_EQ(K_m(0, 2), 597.2);
}

}  // namespace
}  // namespace orbed::geometry
