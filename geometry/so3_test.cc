// Oracles: closed-form rotations and quaternions built with std::cos/std::sin and Eigen's own
// AngleAxis / toRotationMatrix, never with the functions under test.
#include "geometry/so3.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "base/units.h"

namespace orbed::geometry {
namespace {

// Exact quaternion for angle θ about unit axis a.
Eigen::Quaterniond AxisAngleQuaternion(double theta, const Eigen::Vector3d& a) {
  const Eigen::Vector3d u = a.normalized();
  return Eigen::Quaterniond(std::cos(0.5 * theta), std::sin(0.5 * theta) * u.x(),
                            std::sin(0.5 * theta) * u.y(), std::sin(0.5 * theta) * u.z());
}

TEST(So3Test, ExpOfQuarterTurnAboutZIsTheClosedForm) {
  Eigen::Matrix3d expected;
  expected << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  EXPECT_TRUE(ExpSO3(Eigen::Vector3d(0, 0, kPi / 2)).isApprox(expected, 1e-15));
  EXPECT_TRUE(
      Hat(Eigen::Vector3d(1, 2, 3)).isApprox((Eigen::Matrix3d() << 0, -3, 2, 3, 0, -1, -2, 1, 0).finished()));
}

TEST(So3Test, LogIsAccurateAtTinyAngle) {
  const double theta = 1e-10;
  const Eigen::Vector3d a = Eigen::Vector3d(1, -2, 0.5).normalized();
  const Eigen::Quaterniond q = AxisAngleQuaternion(theta, a);
  const Eigen::Vector3d from_quaternion = LogQuaternion(q);
  const Eigen::Vector3d from_matrix = LogSO3(q.toRotationMatrix());
  // Relative accuracy; an acos(trace) log returns 0 here (1 − θ²/2 rounds to 1).
  EXPECT_LT((from_quaternion - theta * a).norm(), 1e-15 * theta);
  EXPECT_LT((from_matrix - theta * a).norm(), 1e-12 * theta);
  // Exp at the same scale: the off-diagonal entries carry θ to full relative precision.
  const Eigen::Matrix3d R = ExpSO3(theta * Eigen::Vector3d::UnitZ());
  EXPECT_NEAR(R(1, 0), theta, 1e-15 * theta);
  EXPECT_NEAR(R(0, 1), -theta, 1e-15 * theta);
}

TEST(So3Test, LogIsAccurateNearPi) {
  const double theta = kPi - 1e-9;
  const Eigen::Vector3d a = Eigen::Vector3d(0.3, 0.4, -0.5).normalized();
  // w = cos(θ/2) = sin(0.5e-9), exactly representable to full relative precision.
  const Eigen::Quaterniond q(std::sin(0.5e-9), std::cos(0.5e-9) * a.x(), std::cos(0.5e-9) * a.y(),
                             std::cos(0.5e-9) * a.z());
  const Eigen::Vector3d from_quaternion = LogQuaternion(q);
  const Eigen::Vector3d from_matrix = LogSO3(q.toRotationMatrix());
  EXPECT_NEAR(from_quaternion.norm(), theta, 1e-14);
  EXPECT_NEAR(from_matrix.norm(), theta, 1e-12);  // acos(trace) is off by ~1e-8 here
  EXPECT_LT((from_quaternion.normalized() - a).norm(), 1e-14);
  EXPECT_LT((from_matrix.normalized() - a).norm(), 1e-12);
  // Sign-flipped input, same log.
  EXPECT_LT((LogQuaternion(Eigen::Quaterniond(-q.coeffs())) - from_quaternion).norm(), 1e-15);
}

TEST(So3Test, LogAtExactlyPiHasNormPi) {
  const Eigen::Matrix3d R_z_pi = Eigen::Vector3d(-1, -1, 1).asDiagonal();
  const Eigen::Vector3d w = LogSO3(R_z_pi);
  EXPECT_NEAR(w.norm(), kPi, 1e-15);
  EXPECT_NEAR(std::abs(w.z()), kPi, 1e-15);
}

TEST(So3Test, ExpAndLogRoundTripAcrossTheRange) {
  const Eigen::Vector3d a = Eigen::Vector3d(-0.2, 0.9, 0.4).normalized();
  for (double theta : {0.0, 1e-12, 1e-8, 1e-6, 1e-3, 0.5, 1.0, 2.0, 3.0, 3.14159, kPi - 1e-6}) {
    const Eigen::Quaterniond expected = AxisAngleQuaternion(theta, a);
    const Eigen::Quaterniond q = ExpQuaternion(theta * a);
    EXPECT_LT((q.coeffs() - expected.coeffs()).norm(), 1e-15) << theta;
    EXPECT_LT((LogQuaternion(expected) - theta * a).norm(), 4e-15 * std::max(theta, 1e-300) + 1e-300)
        << theta;
    EXPECT_NEAR(RotationAngle(expected), theta, 4e-16 * std::max(1.0, theta)) << theta;
  }
}

TEST(So3Test, GeodesicDistanceIsTheRelativeAngle) {
  const Eigen::Quaterniond a(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()));
  const Eigen::Quaterniond b =
      a * Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 1, 0).normalized()));
  EXPECT_NEAR(GeodesicDistance(a, b), 0.7, 1e-15);
  EXPECT_NEAR(GeodesicDistance(a, Eigen::Quaterniond(-b.coeffs())), 0.7, 1e-15);
}

TEST(So3Test, CanonicalQuaternionPicksPositiveW) {
  const Eigen::Quaterniond c = CanonicalQuaternion(Eigen::Quaterniond(-0.5, 0.5, -0.5, 0.5));
  EXPECT_EQ(c.w(), 0.5);
  EXPECT_EQ(c.x(), -0.5);
  const Eigen::Quaterniond tie = CanonicalQuaternion(Eigen::Quaterniond(0.0, 0.0, -1.0, 0.0));
  EXPECT_EQ(tie.y(), 1.0);
}

TEST(So3Test, ValidRotationMatrixIsAcceptedUntouched) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(1.0, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const RotationCheck check = ValidateRotationMatrix(R);
  ASSERT_TRUE(check.valid) << check.message;
  EXPECT_FALSE(check.projected);
  EXPECT_TRUE(check.quat.toRotationMatrix().isApprox(R, 1e-14));
}

TEST(So3Test, SlightlyOffRotationIsProjectedAndSaysSo) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(1.0, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Eigen::Matrix3d noisy = R;
  noisy(0, 1) += 1e-5;
  noisy(2, 2) *= 1.0 + 1e-5;
  const RotationCheck check = ValidateRotationMatrix(noisy);
  ASSERT_TRUE(check.valid) << check.message;
  EXPECT_TRUE(check.projected);
  EXPECT_NE(check.message.find("projected"), std::string::npos);
  EXPECT_LT(GeodesicDistance(check.quat, Eigen::Quaterniond(R)), 2e-5);
}

TEST(So3Test, GarbageRotationsAreRejectedWithAReason) {
  const Eigen::Matrix3d reflection = Eigen::Vector3d(1, 1, -1).asDiagonal();
  RotationCheck check = ValidateRotationMatrix(reflection);
  EXPECT_FALSE(check.valid);
  EXPECT_NE(check.message.find("det"), std::string::npos);

  check = ValidateRotationMatrix(2.0 * Eigen::Matrix3d::Identity());
  EXPECT_FALSE(check.valid);
  EXPECT_NE(check.message.find("not a rotation"), std::string::npos);

  Eigen::Matrix3d with_nan = Eigen::Matrix3d::Identity();
  with_nan(1, 2) = std::numeric_limits<double>::quiet_NaN();
  check = ValidateRotationMatrix(with_nan);
  EXPECT_FALSE(check.valid);
  EXPECT_NE(check.message.find("non-finite"), std::string::npos);

  check = ValidateRotationMatrix(Eigen::Matrix3d::Zero());
  EXPECT_FALSE(check.valid);
}

TEST(So3Test, QuaternionValidation) {
  RotationCheck check = ValidateQuaternionWxyz(Eigen::Vector4d(1, 0, 0, 0));
  EXPECT_TRUE(check.valid);
  EXPECT_FALSE(check.projected);
  check = ValidateQuaternionWxyz(Eigen::Vector4d(1.0001, 0, 0, 0));
  EXPECT_TRUE(check.valid);
  EXPECT_TRUE(check.projected);
  EXPECT_DOUBLE_EQ(check.quat.w(), 1.0);
  check = ValidateQuaternionWxyz(Eigen::Vector4d(2, 0, 0, 0));
  EXPECT_FALSE(check.valid);
  EXPECT_NE(check.message.find("norm"), std::string::npos);
  check = ValidateQuaternionWxyz(Eigen::Vector4d(std::numeric_limits<double>::infinity(), 0, 0, 0));
  EXPECT_FALSE(check.valid);
}

}  // namespace
}  // namespace orbed::geometry
