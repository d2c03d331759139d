// Oracles: closed forms (geodesic midpoints via Eigen's slerp, angles on a common axis,
// symmetric configurations whose mean is known by symmetry) and Eigen's AngleAxis for logs.
#include "geometry/rotation_mean.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "base/units.h"
#include "geometry/test_rotations.h"

namespace orbed::geometry {
namespace {

using testing::AngleBetween;
using testing::Rot;

// Signed angle of a rotation about +z (assumes the rotation is about z).
double AngleAboutZ(const Eigen::Quaterniond& q) { return 2.0 * std::atan2(q.z(), q.w()); }

std::vector<Eigen::Quaterniond> RandomCluster(int n, double spread_rad, unsigned seed,
                                              const Eigen::Quaterniond& center) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Eigen::Quaterniond> q;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d v(normal(rng), normal(rng), normal(rng));
    q.push_back(center * Rot(spread_rad * v.norm(), v));
  }
  return q;
}

TEST(RotationMeanTest, TwoRotationsMeanIsTheGeodesicMidpoint) {
  // Closed form on one axis: the mean of 10° and 70° about z is 40°.
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  KarcherMeanResult r = ComputeKarcherMean({Rot(10 * kDegToRad, z), Rot(70 * kDegToRad, z)});
  ASSERT_TRUE(r.valid) << r.reason;
  EXPECT_TRUE(r.converged);
  EXPECT_NEAR(AngleBetween(r.q_WV_mean, Rot(40 * kDegToRad, z)), 0.0, 1e-12);

  // General pair: slerp(0.5).
  const Eigen::Quaterniond a = Rot(0.9, Eigen::Vector3d(1, 2, -1));
  const Eigen::Quaterniond b = Rot(-1.7, Eigen::Vector3d(0.3, -1, 2));
  r = ComputeKarcherMean({a, b});
  ASSERT_TRUE(r.valid) << r.reason;
  EXPECT_TRUE(r.converged);
  EXPECT_TRUE(r.unique);
  EXPECT_NEAR(AngleBetween(r.q_WV_mean, a.slerp(0.5, b)), 0.0, 1e-12);
}

TEST(RotationMeanTest, WeightedTwoRotationsMeanDividesTheGeodesicByTheWeights) {
  const Eigen::Quaterniond a = Rot(0.4, Eigen::Vector3d(1, 0, 1));
  const Eigen::Quaterniond b = Rot(1.3, Eigen::Vector3d(-1, 2, 0.5));
  // Weights 1 and 3: the minimizer of d(a,R)² + 3 d(b,R)² sits 3/4 of the way from a to b.
  const KarcherMeanResult r = ComputeKarcherMean({a, b}, {1.0, 3.0});
  ASSERT_TRUE(r.valid) << r.reason;
  EXPECT_TRUE(r.converged);
  EXPECT_NEAR(AngleBetween(r.q_WV_mean, a.slerp(0.75, b)), 0.0, 1e-12);
  // On one axis: weights 2, 1 of 0° and 90° give 30°.
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  const KarcherMeanResult on_axis = ComputeKarcherMean({Rot(0, z), Rot(90 * kDegToRad, z)}, {2.0, 1.0});
  EXPECT_NEAR(AngleAboutZ(on_axis.q_WV_mean), 30 * kDegToRad, 1e-12);
}

TEST(RotationMeanTest, CommonAxisKarcherIsTheAngleMeanAndChordalIsAtanHalf) {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  const std::vector<Eigen::Quaterniond> q = {Rot(0, z), Rot(0, z), Rot(90 * kDegToRad, z)};
  const KarcherMeanResult karcher = ComputeKarcherMean(q);
  ASSERT_TRUE(karcher.valid) << karcher.reason;
  EXPECT_TRUE(karcher.converged);
  EXPECT_TRUE(karcher.unique);
  EXPECT_NEAR(AngleAboutZ(karcher.q_WV_mean) / kDegToRad, 30.0, 1e-10);
  EXPECT_NEAR(karcher.max_residual_rad, 60 * kDegToRad, 1e-12);

  // M restricted to the (w, z) plane is [[2.5, 0.5], [0.5, 0.5]] / 3: the top eigenvector is at
  // φ = atan(0.5)/2, the rotation angle 2φ = atan(0.5) = 26.565°.
  const ChordalMeanResult chordal = ComputeChordalMean(q);
  ASSERT_TRUE(chordal.valid) << chordal.reason;
  EXPECT_NEAR(AngleAboutZ(chordal.q_WV_mean), std::atan(0.5), 1e-13);
  EXPECT_NEAR(AngleAboutZ(chordal.q_WV_mean) / kDegToRad, 26.565, 1e-3);
  // Eigenvalues of that block: (3 ± √5)/2 / 3; the other two are 0.
  EXPECT_NEAR(chordal.eigen_gap, (3.0 + std::sqrt(5.0)) / 6.0 - (3.0 - std::sqrt(5.0)) / 6.0, 1e-13);
  EXPECT_NEAR(karcher.chordal_eigen_gap, chordal.eigen_gap, 1e-15);
}

TEST(RotationMeanTest, RotationAndItsInverseAverageToIdentity) {
  const Eigen::Quaterniond R = Rot(1.2, Eigen::Vector3d(2, -1, 0.3));
  const KarcherMeanResult r = ComputeKarcherMean({R, R.conjugate()});
  ASSERT_TRUE(r.valid) << r.reason;
  EXPECT_NEAR(AngleBetween(r.q_WV_mean, Eigen::Quaterniond::Identity()), 0.0, 1e-13);
}

TEST(RotationMeanTest, MeanIsBiInvariant) {
  const std::vector<Eigen::Quaterniond> q =
      RandomCluster(9, 25 * kDegToRad, 11, Rot(0.8, Eigen::Vector3d(1, 1, 1)));
  const Eigen::Quaterniond L = Rot(2.1, Eigen::Vector3d(-1, 0.5, 2));
  const Eigen::Quaterniond S = Rot(-0.6, Eigen::Vector3d(0, 1, 3));
  std::vector<Eigen::Quaterniond> moved;
  for (const auto& qi : q) moved.push_back(L * qi * S);
  const KarcherMeanResult base = ComputeKarcherMean(q);
  const KarcherMeanResult transformed = ComputeKarcherMean(moved);
  ASSERT_TRUE(base.valid && transformed.valid);
  EXPECT_TRUE(base.converged && transformed.converged);
  EXPECT_NEAR(AngleBetween(transformed.q_WV_mean, L * base.q_WV_mean * S), 0.0, 1e-12);
}

TEST(RotationMeanTest, ResidualsSumToZeroAtTheOptimum) {
  const std::vector<Eigen::Quaterniond> q =
      RandomCluster(15, 40 * kDegToRad, 5, Rot(-2.5, Eigen::Vector3d(0, 1, 0)));
  const KarcherMeanResult r = ComputeKarcherMean(q);
  ASSERT_TRUE(r.valid);
  EXPECT_TRUE(r.converged);
  EXPECT_LT(r.last_step_rad, 1e-12);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& qi : q) {
    const Eigen::AngleAxisd aa(r.q_WV_mean.conjugate() * qi);  // Eigen's log, not ours
    sum += aa.angle() * aa.axis();
  }
  EXPECT_LT(sum.norm(), 1e-11);
}

TEST(RotationMeanTest, AntipodalPairIsFlaggedNonUniqueWithoutCrashing) {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  const KarcherMeanResult r = ComputeKarcherMean({Eigen::Quaterniond::Identity(), Rot(kPi, z)});
  ASSERT_TRUE(r.valid) << r.reason;
  EXPECT_FALSE(r.unique);
  EXPECT_TRUE(r.q_WV_mean.coeffs().allFinite());
  EXPECT_NEAR(r.chordal_eigen_gap, 0.0, 1e-15);
  // Both minimizers are a quarter turn about z; any of them is a correct answer.
  EXPECT_NEAR(std::abs(AngleAboutZ(r.q_WV_mean)), kPi / 2, 1e-9);
  EXPECT_NEAR(r.max_residual_rad, kPi / 2, 1e-9);
}

TEST(RotationMeanTest, ResidualAtPiIsFlaggedAmbiguous) {
  // A single iteration from a start at I (the chordal mean of these weights) sees a residual at π.
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  KarcherOptions options;
  options.max_iterations = 1;
  const KarcherMeanResult r =
      ComputeKarcherMean({Eigen::Quaterniond::Identity(), Rot(kPi, z)}, {2.0, 1.0}, options);
  ASSERT_TRUE(r.valid) << r.reason;
  EXPECT_TRUE(r.ambiguous);
  EXPECT_FALSE(r.unique);
}

TEST(RotationMeanTest, ClusterAroundAHalfTurnConverges) {
  // Symmetric pairs C·exp(±δ_k): the mean is C by symmetry. C is a half turn, 180° from identity.
  const Eigen::Quaterniond C = Rot(kPi, Eigen::Vector3d(1, 2, 3));
  std::vector<Eigen::Quaterniond> q;
  const std::vector<Eigen::Vector3d> deltas = {Eigen::Vector3d(0.1, 0.02, -0.05),
                                               Eigen::Vector3d(-0.03, 0.2, 0.01),
                                               Eigen::Vector3d(0.05, -0.04, 0.15)};
  for (const auto& d : deltas) {
    q.push_back(C * Rot(d.norm(), d));
    q.push_back(C * Rot(-d.norm(), d));
  }
  const KarcherMeanResult r = ComputeKarcherMean(q);
  ASSERT_TRUE(r.valid) << r.reason;
  EXPECT_TRUE(r.converged);
  EXPECT_TRUE(r.unique);
  EXPECT_FALSE(r.ambiguous);
  EXPECT_NEAR(AngleBetween(r.q_WV_mean, C), 0.0, 1e-12);
}

TEST(RotationMeanTest, SignFlippedQuaternionsGiveTheSameMean) {
  const std::vector<Eigen::Quaterniond> q =
      RandomCluster(8, 30 * kDegToRad, 3, Rot(1.0, Eigen::Vector3d(0, 0, 1)));
  std::vector<Eigen::Quaterniond> flipped = q;
  for (size_t i = 0; i < flipped.size(); i += 2) flipped[i].coeffs() *= -1.0;
  const KarcherMeanResult a = ComputeKarcherMean(q);
  const KarcherMeanResult b = ComputeKarcherMean(flipped);
  ASSERT_TRUE(a.valid && b.valid);
  EXPECT_LT(AngleBetween(a.q_WV_mean, b.q_WV_mean), 1e-13);
  EXPECT_LT(
      (ComputeChordalMean(q).q_WV_mean.coeffs() - ComputeChordalMean(flipped).q_WV_mean.coeffs()).norm(),
      1e-13);
  EXPECT_GE(b.q_WV_mean.w(), 0.0);  // canonical sign
}

TEST(RotationMeanTest, IterationCapLeavesConvergedFalse) {
  const std::vector<Eigen::Quaterniond> q =
      RandomCluster(20, 50 * kDegToRad, 9, Eigen::Quaterniond::Identity());
  KarcherOptions options;
  options.max_iterations = 1;
  const KarcherMeanResult r = ComputeKarcherMean(q, {}, options);
  ASSERT_TRUE(r.valid);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_FALSE(r.converged);
  EXPECT_GT(r.last_step_rad, 1e-12);
}

TEST(RotationMeanTest, SingleRotationIsItsOwnMean) {
  const Eigen::Quaterniond a = Rot(2.0, Eigen::Vector3d(1, -1, 0));
  const KarcherMeanResult r = ComputeKarcherMean({a});
  ASSERT_TRUE(r.valid);
  EXPECT_TRUE(r.converged);
  EXPECT_LT(AngleBetween(r.q_WV_mean, a), 1e-15);
}

TEST(RotationMeanTest, BadInputIsRejectedWithAReason) {
  EXPECT_NE(ComputeKarcherMean({}).reason.find("no rotations"), std::string::npos);
  const Eigen::Quaterniond bad(2, 0, 0, 0);
  EXPECT_NE(ComputeKarcherMean({Eigen::Quaterniond::Identity(), bad}).reason.find("rotation 1"),
            std::string::npos);
  EXPECT_NE(ComputeKarcherMean({Eigen::Quaterniond::Identity()}, {1.0, 2.0}).reason.find("weights"),
            std::string::npos);
  EXPECT_NE(ComputeKarcherMean({Eigen::Quaterniond::Identity()}, {-1.0}).reason.find("weight 0"),
            std::string::npos);
  EXPECT_NE(ComputeKarcherMean({Eigen::Quaterniond::Identity()}, {0.0}).reason.find("zero"),
            std::string::npos);
  const Eigen::Quaterniond nan(std::nan(""), 0, 0, 0);
  EXPECT_FALSE(ComputeChordalMean({nan}).valid);
  KarcherOptions options;
  options.max_iterations = 0;
  EXPECT_FALSE(ComputeKarcherMean({Eigen::Quaterniond::Identity()}, {}, options).valid);
}

}  // namespace
}  // namespace orbed::geometry
