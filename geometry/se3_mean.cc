#include "geometry/se3_mean.h"

#include <algorithm>
#include <cmath>

#include "base/stats.h"
#include "base/units.h"
#include "geometry/so3.h"

namespace orbed::geometry {
namespace {

constexpr double kHalfPi = 1.5707963267948966;

}  // namespace

const char* AveragingMethodName(AveragingMethod method) {
  switch (method) {
    case AveragingMethod::kChordal:
      return "chordal";
    case AveragingMethod::kKarcher:
      return "karcher";
    case AveragingMethod::kRobust:
      return "robust";
  }
  return "unknown";
}

Se3MeanResult ComputeSe3Mean(const std::vector<Eigen::Quaterniond>& quat_WV,
                             const std::vector<Eigen::Vector3d>& p_WV, const Se3MeanOptions& options) {
  Se3MeanResult result;
  result.method = options.method;
  result.num_trials = static_cast<int>(quat_WV.size());
  if (options.method != AveragingMethod::kChordal && options.method != AveragingMethod::kKarcher &&
      options.method != AveragingMethod::kRobust) {
    result.reason = "unknown averaging method " + std::to_string(static_cast<int>(options.method));
    return result;
  }
  if (quat_WV.size() != p_WV.size()) {
    result.reason = "got " + std::to_string(quat_WV.size()) + " rotations but " +
                    std::to_string(p_WV.size()) + " translations";
    return result;
  }
  if (quat_WV.empty()) {
    result.reason = "no trials to average";
    return result;
  }
  for (size_t i = 0; i < p_WV.size(); ++i) {
    if (!p_WV[i].allFinite()) {
      result.reason = "translation of trial " + std::to_string(i) + " has a non-finite coordinate";
      return result;
    }
  }
  if (options.p_VC && !options.p_VC->allFinite()) {
    result.reason = "model centroid p_VC has a non-finite coordinate";
    return result;
  }
  const std::string rotation_problem = ValidateRotationSamples(quat_WV, {});
  if (!rotation_problem.empty()) {
    result.reason = rotation_problem;
    return result;
  }

  // 1. Which trials to use.
  if (options.method == AveragingMethod::kRobust) {
    const OutlierResult outliers = RejectOutliers(quat_WV, p_WV, options.outlier);
    if (!outliers.valid) {
      result.reason = outliers.reason;
      return result;
    }
    result.used = outliers.inliers;
    result.rejected = outliers.rejected;
  } else {
    result.used.resize(quat_WV.size());
    for (size_t i = 0; i < quat_WV.size(); ++i) result.used[i] = static_cast<int>(i);
  }
  std::vector<Eigen::Quaterniond> q_used;
  std::vector<Eigen::Vector3d> p_used;
  q_used.reserve(result.used.size());
  p_used.reserve(result.used.size());
  for (int i : result.used) {
    q_used.push_back(quat_WV[i]);
    p_used.push_back(p_WV[i]);
  }

  // 2. Rotation.
  if (options.method == AveragingMethod::kChordal) {
    const ChordalMeanResult chordal = ComputeChordalMean(q_used);
    if (!chordal.valid) {
      result.reason = chordal.reason;
      return result;
    }
    result.q_WV_mean = chordal.q_WV_mean;
    result.chordal_eigen_gap = chordal.eigen_gap;
    result.iterations = 0;
    result.converged = true;
  } else {
    const KarcherMeanResult karcher = ComputeKarcherMean(q_used, {}, options.karcher);
    if (!karcher.valid) {
      result.reason = karcher.reason;
      return result;
    }
    result.q_WV_mean = karcher.q_WV_mean;
    result.chordal_eigen_gap = karcher.chordal_eigen_gap;
    result.iterations = karcher.iterations;
    result.converged = karcher.converged;
    result.ambiguous = karcher.ambiguous;
  }
  const Eigen::Matrix3d R_WV_mean = result.q_WV_mean.toRotationMatrix();

  // 3. Translation (eq. 3, optionally about the centroid).
  const size_t n = q_used.size();
  const double inv_n = 1.0 / static_cast<double>(n);
  const Eigen::Vector3d p_VC = options.p_VC.value_or(Eigen::Vector3d::Zero());
  std::vector<Eigen::Vector3d> p_WC(n);
  Eigen::Vector3d p_WC_mean = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < n; ++k) {
    p_WC[k] = options.p_VC ? Eigen::Vector3d(p_used[k] + q_used[k] * p_VC) : p_used[k];
    p_WC_mean += p_WC[k];
  }
  p_WC_mean *= inv_n;
  result.p_WV_mean = options.p_VC ? Eigen::Vector3d(p_WC_mean - R_WV_mean * p_VC) : p_WC_mean;

  // 4. Dispersion.
  Se3Dispersion& d = result.dispersion;
  d.num_used = static_cast<int>(n);
  const Eigen::Quaterniond q_mean_conj = result.q_WV_mean.conjugate();
  std::vector<double> angles_deg(n);
  double sum_sq_angle = 0.0, sum_sq_translation = 0.0, max_angle = 0.0;
  for (size_t k = 0; k < n; ++k) {
    const Eigen::Vector3d r = LogQuaternion(q_mean_conj * q_used[k]);
    const double angle = r.norm();
    angles_deg[k] = kRadToDeg * angle;
    sum_sq_angle += angle * angle;
    max_angle = std::max(max_angle, angle);
    d.rotation_covariance_rad2 += r * r.transpose();
    const Eigen::Vector3d e = p_WC[k] - p_WC_mean;
    sum_sq_translation += e.squaredNorm();
    d.translation_covariance_m2 += e * e.transpose();
  }
  d.rotation_rms_deg = kRadToDeg * std::sqrt(sum_sq_angle * inv_n);
  d.rotation_median_deg = stats::Median(angles_deg);
  d.rotation_max_deg = kRadToDeg * max_angle;
  d.rotation_covariance_rad2 *= inv_n;
  d.translation_rms_m = std::sqrt(sum_sq_translation * inv_n);
  d.translation_covariance_m2 *= inv_n;
  if (options.method == AveragingMethod::kChordal) {
    // The chordal mean is the top eigenvector of M: unique exactly when that eigenvalue is simple.
    result.unique = result.chordal_eigen_gap > kChordalGapMargin;
  } else {
    result.unique = max_angle < kHalfPi - options.karcher.certificate_margin_rad;
  }
  result.valid = true;
  return result;
}

}  // namespace orbed::geometry
