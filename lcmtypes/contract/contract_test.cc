// Unit tests of the message contract's helpers: message <-> Eigen conversions and the validators
// with their rejection counting.

#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "lcmtypes/contract/conversions.h"
#include "lcmtypes/contract/validation.h"

namespace orbed {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(Conversions, RotationAboutZByNinetyDegreesHasHandComputedQuaternion) {
  Eigen::Isometry3d X_AB = Eigen::Isometry3d::Identity();
  X_AB.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X_AB.translation() = Eigen::Vector3d(1.0, -2.0, 0.5);
  const pose_t pose = ToPose(X_AB);
  // q = (cos 45°, 0, 0, sin 45°)
  EXPECT_NEAR(pose.quaternion_wxyz[0], std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(pose.quaternion_wxyz[1], 0.0, 1e-15);
  EXPECT_NEAR(pose.quaternion_wxyz[2], 0.0, 1e-15);
  EXPECT_NEAR(pose.quaternion_wxyz[3], std::sqrt(0.5), 1e-15);
  EXPECT_EQ(pose.position_m[0], 1.0);
  EXPECT_EQ(pose.position_m[1], -2.0);
  EXPECT_EQ(pose.position_m[2], 0.5);
  // A point on x maps to y.
  const Eigen::Vector3d p = FromPose(pose) * Eigen::Vector3d(1, 0, 0);
  EXPECT_NEAR(p.x(), 1.0, 1e-15);
  EXPECT_NEAR(p.y(), -1.0, 1e-15);
  EXPECT_NEAR(p.z(), 0.5, 1e-15);
}

TEST(Conversions, RoundTripAndCanonicalSign) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(3.0, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(0.1, 0.2, 0.3);
  const pose_t pose = ToPose(X);
  EXPECT_GE(pose.quaternion_wxyz[0], 0.0);
  EXPECT_TRUE(FromPose(pose).isApprox(X, 1e-14));
  // -q encodes the same rotation; ToPose picks the same bytes.
  pose_t flipped = pose;
  for (double& c : flipped.quaternion_wxyz) c = -c;
  const pose_t again = ToPose(FromPose(flipped));
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(again.quaternion_wxyz[i], pose.quaternion_wxyz[i], 1e-15);
}

TEST(Conversions, MatrixAndVectorLayoutIsRowMajor) {
  Eigen::Matrix3d m;
  m << 1, 2, 3, 4, 5, 6, 7, 8, 9;
  double out[3][3];
  FromMatrix3(m, out);
  EXPECT_EQ(out[0][2], 3.0);
  EXPECT_EQ(out[2][0], 7.0);
  EXPECT_EQ(ToMatrix3(out), m);
  const std::vector<double> v{1, 2, 3, 4};
  EXPECT_EQ(FromVectorX(ToVectorX(v)), v);
}

TEST(Validation, RejectsNaNInfWrongSizeAndNonUnitQuaternions) {
  const double good[3] = {1, 2, 3};
  EXPECT_EQ(CheckFinite(good, 3, "p"), "");
  const double bad[3] = {1, kNaN, 3};
  EXPECT_NE(CheckFinite(bad, 3, "p").find("p[1]"), std::string::npos);
  const double inf[2] = {std::numeric_limits<double>::infinity(), 0};
  EXPECT_NE(CheckFinite(inf, 2, "v"), "");

  const double huge[2] = {1.0, 1e308};
  EXPECT_NE(CheckBounded(huge, 2, 1e4, "p").find("p[1]"), std::string::npos);
  EXPECT_EQ(CheckBounded(good, 3, 1e4, "p"), "");
  EXPECT_NE(CheckBounded(bad, 3, 1e4, "p"), "");
  EXPECT_EQ(CheckSize(7, 7, "num_joints"), "");
  EXPECT_EQ(CheckSize(6, 7, "num_joints"), "num_joints is 6, expected 7");
  EXPECT_NE(CheckLength(3, 2, 10, "num_x"), "");
  EXPECT_NE(CheckLength(-1, 0, 10, "num_x"), "");
  EXPECT_NE(CheckLength(11, 11, 10, "num_x"), "");
  EXPECT_EQ(CheckLength(2, 2, 10, "num_x"), "");

  const double unit[4] = {0.5, 0.5, 0.5, 0.5};
  EXPECT_EQ(CheckUnitQuaternion(unit, "q"), "");
  const double nearly[4] = {1.0 + 5e-7, 0, 0, 0};
  EXPECT_EQ(CheckUnitQuaternion(nearly, "q"), "");
  const double half[4] = {0.5, 0, 0, 0};
  EXPECT_NE(CheckUnitQuaternion(half, "q").find("norm 0.5"), std::string::npos);
  const double zero[4] = {0, 0, 0, 0};
  EXPECT_NE(CheckUnitQuaternion(zero, "q"), "");
  const double nan_q[4] = {kNaN, 0, 0, 0};
  EXPECT_NE(CheckUnitQuaternion(nan_q, "q"), "");

  pose_t pose{};
  pose.quaternion_wxyz[0] = 1;
  EXPECT_EQ(CheckPose(pose, "X_WV"), "");
  pose.position_m[2] = kNaN;
  EXPECT_NE(CheckPose(pose, "X_WV").find("X_WV.position_m[2]"), std::string::npos);

  EXPECT_EQ(CheckEnum(2, 0, 3, "mode"), "");
  EXPECT_EQ(CheckEnum(4, 0, 3, "mode"), "mode is 4, expected 0..3");
  EXPECT_NE(CheckWithinLimits({0.0, 2.0}, {-1, -1}, {1, 1}, "q"), "");
  EXPECT_EQ(CheckWithinLimits({0.0, 1.0}, {-1, -1}, {1, 1}, "q"), "");
  EXPECT_EQ(FirstError({"", "b", "c"}), "b");
}

TEST(Validation, RejectionCounterCountsPerKey) {
  RejectionCounter counter;
  counter.Reject("A/size", "too big");
  counter.Reject("A/size", "too big again");
  counter.Reject("B/nan", "nan");
  EXPECT_EQ(counter.total(), 3);
  EXPECT_EQ(counter.counts().at("A/size"), 2);
  EXPECT_EQ(counter.counts().at("B/nan"), 1);
  EXPECT_EQ(counter.last_reason(), "B/nan: nan");
}

TEST(Validation, RejectionClassesAreBoundedAgainstMadeUpChannels) {
  RejectionCounter counter;
  for (int i = 0; i < 1000; ++i) counter.Reject("CHANNEL_" + std::to_string(i) + "/handler", "x");
  counter.Reject("CHANNEL_0/handler", "x");  // a known class keeps counting on its own
  const auto counts = counter.counts();
  EXPECT_EQ(counts.size(), kMaxRejectionClasses);
  EXPECT_EQ(counts.at("CHANNEL_0/handler"), 2);
  EXPECT_EQ(counts.at(kOtherRejectionClass), 1000 - static_cast<int64_t>(kMaxRejectionClasses - 1));
  EXPECT_EQ(counter.total(), 1001);
  counter.Reject("late", std::string(10000, 'r'));
  EXPECT_EQ(counter.last_reason(), "late: " + std::string(kMaxReasonLength, 'r'));
}

}  // namespace
}  // namespace orbed
