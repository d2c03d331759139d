// Oracles: medians known in closed form (points on one geodesic / one line, a symmetric square, a
// dominant weight) and a planted outlier with known truth.
#include "geometry/robust.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "base/units.h"
#include "geometry/rotation_mean.h"
#include "geometry/test_rotations.h"

namespace orbed::geometry {
namespace {

using testing::AngleBetween;
using testing::Rot;

TEST(RobustTest, RotationL1MedianOnOneGeodesicIsTheMiddleSample) {
  // On one axis the geodesic L1 median is the ordinary median of the angles: exactly on a sample,
  // where the plain Weiszfeld step divides by zero.
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  const std::vector<Eigen::Quaterniond> q = {Rot(0, z), Rot(10 * kDegToRad, z), Rot(50 * kDegToRad, z)};
  const RotationL1MedianResult r = ComputeRotationL1Median(q);
  ASSERT_TRUE(r.valid) << r.reason;
  EXPECT_TRUE(r.converged);
  EXPECT_NEAR(AngleBetween(r.q_WV_median, q[1]), 0.0, 1e-9);
  EXPECT_TRUE(r.q_WV_median.coeffs().allFinite());
}

TEST(RobustTest, RotationL1MedianStartingExactlyOnTheMedianSampleStaysThere) {
  // Symmetric about the middle sample: the chordal start is exactly that sample.
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
  const Eigen::Quaterniond c = Rot(0.7, Eigen::Vector3d(1, 1, 0));
  const std::vector<Eigen::Quaterniond> q = {c * Rot(-0.3, x), c, c * Rot(0.3, x)};
  const RotationL1MedianResult r = ComputeRotationL1Median(q);
  ASSERT_TRUE(r.valid);
  EXPECT_TRUE(r.converged);
  EXPECT_NEAR(AngleBetween(r.q_WV_median, c), 0.0, 1e-12);
}

TEST(RobustTest, PointL1MedianClosedForms) {
  // On a line: the middle point.
  PointL1MedianResult r = ComputePointL1Median({{0, 0, 0}, {1, 0, 0}, {5, 0, 0}});
  ASSERT_TRUE(r.valid);
  EXPECT_TRUE(r.converged);
  EXPECT_NEAR((r.p_W_median - Eigen::Vector3d(1, 0, 0)).norm(), 0.0, 1e-9);
  // Square corners: the centre.
  r = ComputePointL1Median({{0, 0, 1}, {2, 0, 1}, {2, 2, 1}, {0, 2, 1}});
  EXPECT_NEAR((r.p_W_median - Eigen::Vector3d(1, 1, 1)).norm(), 0.0, 1e-9);
  // A weight larger than the others' total pull: the median is that point (Vardi–Zhang).
  r = ComputePointL1Median({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {10.0, 1.0, 1.0});
  EXPECT_TRUE(r.converged);
  EXPECT_NEAR(r.p_W_median.norm(), 0.0, 1e-9);
  // Bad input.
  EXPECT_FALSE(ComputePointL1Median({}).valid);
  EXPECT_FALSE(ComputePointL1Median({{0, 0, std::nan("")}}).valid);
  EXPECT_FALSE(ComputePointL1Median({{0, 0, 0}}, {1.0, 1.0}).valid);
}

TEST(RobustTest, OneBotchedTrialOfElevenIsRejectedAndTheMeanStaysWithinHalfADegree) {
  const Eigen::Quaterniond truth = Rot(40 * kDegToRad, Eigen::Vector3d(0.3, -0.5, 0.8));
  const Eigen::Vector3d p_truth(1.2, -0.4, 0.8);
  std::mt19937 rng(2024);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Eigen::Quaterniond> q;
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < 10; ++i) {
    // Rotation noise of 1° RMS angle (σ = 1/√3 ° per axis), 5 mm per axis.
    const Eigen::Vector3d w =
        (1.0 / std::sqrt(3.0)) * kDegToRad * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    q.push_back(truth * Rot(w.norm(), w));
    p.push_back(p_truth + 0.005 * Eigen::Vector3d(normal(rng), normal(rng), normal(rng)));
  }
  q.push_back(truth * Rot(120 * kDegToRad, Eigen::Vector3d(0, 1, 0)));
  p.push_back(p_truth);

  const OutlierResult outliers = RejectOutliers(q, p);
  ASSERT_TRUE(outliers.valid) << outliers.reason;
  ASSERT_EQ(outliers.rejected.size(), 1u);
  EXPECT_EQ(outliers.rejected[0].index, 10);
  EXPECT_NEAR(outliers.rejected[0].rotation_deg, 120.0, 3.0);
  EXPECT_NE(outliers.rejected[0].reason.find("rotation"), std::string::npos);
  EXPECT_EQ(outliers.inliers.size(), 10u);
  EXPECT_LT(AngleBetween(outliers.q_WV_median, truth), 1.0 * kDegToRad);

  std::vector<Eigen::Quaterniond> kept;
  for (int i : outliers.inliers) kept.push_back(q[i]);
  const KarcherMeanResult mean = ComputeKarcherMean(kept);
  ASSERT_TRUE(mean.valid);
  EXPECT_LT(AngleBetween(mean.q_WV_mean, truth), 0.5 * kDegToRad);
  // Without rejection the outlier drags the mean by ~120°/11 ≈ 11°.
  EXPECT_GT(AngleBetween(ComputeKarcherMean(q).q_WV_mean, truth), 5.0 * kDegToRad);
}

TEST(RobustTest, TranslationOutlierIsRejected) {
  std::vector<Eigen::Quaterniond> q(6, Eigen::Quaterniond::Identity());
  std::vector<Eigen::Vector3d> p = {{0, 0, 0},      {0.002, 0, 0},  {0, 0.003, 0},
                                    {0, 0, -0.002}, {-0.001, 0, 0}, {0.3, 0, 0}};
  const OutlierResult r = RejectOutliers(q, p);
  ASSERT_TRUE(r.valid);
  ASSERT_EQ(r.rejected.size(), 1u);
  EXPECT_EQ(r.rejected[0].index, 5);
  EXPECT_NE(r.rejected[0].reason.find("translation"), std::string::npos);
}

TEST(RobustTest, IdenticalTrialsAndTooFewTrialsRejectNothing) {
  std::vector<Eigen::Quaterniond> q(5, Rot(0.3, Eigen::Vector3d::UnitY()));
  std::vector<Eigen::Vector3d> p(5, Eigen::Vector3d(1, 2, 3));
  p[2].x() += 1e-4;  // MAD = 0; below the floor
  EXPECT_TRUE(RejectOutliers(q, p).rejected.empty());
  const OutlierResult two =
      RejectOutliers({Eigen::Quaterniond::Identity(), Rot(2.0, Eigen::Vector3d::UnitX())},
                     {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()});
  ASSERT_TRUE(two.valid);
  EXPECT_TRUE(two.rejected.empty());
  EXPECT_FALSE(RejectOutliers(q, {Eigen::Vector3d::Zero()}).valid);
}

}  // namespace
}  // namespace orbed::geometry
