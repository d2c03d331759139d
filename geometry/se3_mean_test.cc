// Oracles: hand-computed means and dispersions (angles on one axis, symmetric translations), and a
// configuration whose centroid-based mean is known by construction.
#include "geometry/se3_mean.h"

#include <cmath>

#include <gtest/gtest.h>

#include "base/units.h"
#include "geometry/test_rotations.h"

namespace orbed::geometry {
namespace {

using testing::AngleBetween;
using testing::Rot;

TEST(Se3MeanTest, TranslationIsTheArithmeticMeanAndDispersionMatchesHandValues) {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  const std::vector<Eigen::Quaterniond> q = {Rot(0, z), Rot(0, z), Rot(90 * kDegToRad, z)};
  const std::vector<Eigen::Vector3d> p = {{1, 0, 0}, {-1, 0, 0}, {0, 0, 3}};
  const Se3MeanResult r = ComputeSe3Mean(q, p);
  ASSERT_TRUE(r.valid) << r.reason;
  EXPECT_EQ(r.method, AveragingMethod::kKarcher);
  EXPECT_TRUE(r.converged);
  EXPECT_TRUE(r.unique);
  EXPECT_EQ(r.num_trials, 3);
  EXPECT_EQ(r.dispersion.num_used, 3);
  EXPECT_TRUE(r.rejected.empty());
  EXPECT_NEAR(AngleBetween(r.q_WV_mean, Rot(30 * kDegToRad, z)), 0.0, 1e-12);
  EXPECT_TRUE(r.p_WV_mean.isApprox(Eigen::Vector3d(0, 0, 1), 1e-15));
  // Residual angles 30°, 30°, 60°.
  EXPECT_NEAR(r.dispersion.rotation_rms_deg, std::sqrt((900.0 + 900.0 + 3600.0) / 3.0), 1e-9);
  EXPECT_NEAR(r.dispersion.rotation_median_deg, 30.0, 1e-9);
  EXPECT_NEAR(r.dispersion.rotation_max_deg, 60.0, 1e-9);
  Eigen::Matrix3d expected_rotation_cov = Eigen::Matrix3d::Zero();
  expected_rotation_cov(2, 2) = (2.0 * std::pow(kPi / 6, 2) + std::pow(kPi / 3, 2)) / 3.0;
  EXPECT_TRUE(r.dispersion.rotation_covariance_rad2.isApprox(expected_rotation_cov, 1e-10));
  // Translation residuals (1,0,-1), (-1,0,-1), (0,0,2).
  EXPECT_NEAR(r.dispersion.translation_rms_m, std::sqrt((2.0 + 2.0 + 4.0) / 3.0), 1e-15);
  Eigen::Matrix3d expected_translation_cov = Eigen::Matrix3d::Zero();
  expected_translation_cov(0, 0) = 2.0 / 3.0;
  expected_translation_cov(2, 2) = 6.0 / 3.0;
  EXPECT_TRUE(r.dispersion.translation_covariance_m2.isApprox(expected_translation_cov, 1e-15));
}

TEST(Se3MeanTest, ChordalMethodReportsNoIterations) {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  Se3MeanOptions options;
  options.method = AveragingMethod::kChordal;
  const Se3MeanResult r = ComputeSe3Mean({Rot(0, z), Rot(0, z), Rot(90 * kDegToRad, z)},
                                         {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}, options);
  ASSERT_TRUE(r.valid);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_TRUE(r.converged);
  EXPECT_NEAR(AngleBetween(r.q_WV_mean, Rot(std::atan(0.5), z)), 0.0, 1e-13);
}

// Rotations θ_i about one axis: M's two non-zero eigenvalues are (1 ± R)/2 with R = |mean e^{iθ_i}|,
// so the eigen-gap is R; the chordal mean is unique exactly when R > 0, whatever the residuals.
TEST(Se3MeanTest, ChordalUniquenessIsTheEigenGapNotAResidualTest) {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  Se3MeanOptions options;
  options.method = AveragingMethod::kChordal;
  const std::vector<Eigen::Vector3d> origins(3, Eigen::Vector3d::Zero());
  // 0, 0, 170 deg: a residual of about 160 deg, yet one chordal mean.
  const double far = 170 * kDegToRad;
  Se3MeanResult r = ComputeSe3Mean({Rot(0, z), Rot(0, z), Rot(far, z)}, origins, options);
  ASSERT_TRUE(r.valid);
  const double R = std::hypot(2 + std::cos(far), std::sin(far)) / 3;
  EXPECT_NEAR(r.chordal_eigen_gap, R, 1e-12);
  EXPECT_GT(r.dispersion.rotation_max_deg, 150.0);
  EXPECT_TRUE(r.unique);
  // 0, 120, 240 deg: R = 0, every rotation about z is as close; no unique chordal mean.
  r = ComputeSe3Mean({Rot(0, z), Rot(120 * kDegToRad, z), Rot(240 * kDegToRad, z)}, origins, options);
  ASSERT_TRUE(r.valid);
  EXPECT_NEAR(r.chordal_eigen_gap, 0.0, 1e-12);
  EXPECT_FALSE(r.unique);
}

TEST(Se3MeanTest, AveragingAboutTheModelCentroidRemovesTheLeverArm) {
  // Every trial places the model centroid C at the same world point c, with rotations ±20° about
  // z: the mean rotation is I, and about C the mean base is c − p_VC with zero translation spread.
  const Eigen::Vector3d p_VC(0.0, 0.0, 0.5);
  const Eigen::Vector3d c(1.0, 2.0, 0.7);
  const Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
  std::vector<Eigen::Quaterniond> q = {Rot(20 * kDegToRad, axis), Rot(-20 * kDegToRad, axis)};
  std::vector<Eigen::Vector3d> p;
  for (const auto& qi : q) p.push_back(c - qi * p_VC);
  Se3MeanOptions options;
  options.p_VC = p_VC;
  const Se3MeanResult about_centroid = ComputeSe3Mean(q, p, options);
  ASSERT_TRUE(about_centroid.valid) << about_centroid.reason;
  EXPECT_NEAR(AngleBetween(about_centroid.q_WV_mean, Eigen::Quaterniond::Identity()), 0.0, 1e-13);
  EXPECT_LT((about_centroid.p_WV_mean - (c - p_VC)).norm(), 1e-14);
  EXPECT_LT(about_centroid.dispersion.translation_rms_m, 1e-14);
  // Eq. 3 about V's origin: the origins differ by ±0.5·sin 20° in y and agree in z at c − 0.5·cos 20°.
  const Se3MeanResult about_origin = ComputeSe3Mean(q, p);
  EXPECT_NEAR(about_origin.p_WV_mean.z(), c.z() - 0.5 * std::cos(20 * kDegToRad), 1e-14);
  EXPECT_NEAR(about_origin.dispersion.translation_rms_m, 0.5 * std::sin(20 * kDegToRad), 1e-14);
}

TEST(Se3MeanTest, RobustMethodReportsTheRejectedTrial) {
  const Eigen::Quaterniond truth = Rot(0.5, Eigen::Vector3d(1, 0, 1));
  std::vector<Eigen::Quaterniond> q;
  std::vector<Eigen::Vector3d> p;
  const std::vector<Eigen::Vector3d> deltas = {
      {0.01, 0, 0}, {-0.01, 0, 0}, {0, 0.01, 0}, {0, -0.01, 0}, {0, 0, 0.01}};
  for (const auto& d : deltas) {
    q.push_back(truth * Rot(d.norm(), d));
    p.push_back(Eigen::Vector3d(0.5, 0.5, 0.5) + 0.1 * d);
  }
  q.push_back(truth * Rot(kPi / 2, Eigen::Vector3d(0, 0, 1)));
  p.push_back(Eigen::Vector3d(0.5, 0.5, 0.5));
  Se3MeanOptions options;
  options.method = AveragingMethod::kRobust;
  const Se3MeanResult r = ComputeSe3Mean(q, p, options);
  ASSERT_TRUE(r.valid) << r.reason;
  ASSERT_EQ(r.rejected.size(), 1u);
  EXPECT_EQ(r.rejected[0].index, 5);
  EXPECT_EQ(r.used, (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(r.dispersion.num_used, 5);
  EXPECT_LT(AngleBetween(r.q_WV_mean, truth), 0.01);
}

TEST(Se3MeanTest, BadInputIsRejectedWithAReason) {
  EXPECT_NE(ComputeSe3Mean({}, {}).reason.find("no trials"), std::string::npos);
  EXPECT_NE(ComputeSe3Mean({Eigen::Quaterniond::Identity()}, {}).reason.find("translations"),
            std::string::npos);
  EXPECT_NE(
      ComputeSe3Mean({Eigen::Quaterniond::Identity()}, {{0, std::nan(""), 0}}).reason.find("non-finite"),
      std::string::npos);
  EXPECT_NE(ComputeSe3Mean({Eigen::Quaterniond(0.5, 0, 0, 0)}, {{0, 0, 0}}).reason.find("unit"),
            std::string::npos);
  Se3MeanOptions options;
  options.method = static_cast<AveragingMethod>(7);
  EXPECT_NE(ComputeSe3Mean({Eigen::Quaterniond::Identity()}, {{0, 0, 0}}, options).reason.find("method"),
            std::string::npos);
}

}  // namespace
}  // namespace orbed::geometry
