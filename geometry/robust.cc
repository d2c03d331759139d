#include "geometry/robust.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "base/stats.h"
#include "base/units.h"
#include "geometry/rotation_mean.h"
#include "geometry/so3.h"

namespace orbed::geometry {
namespace {

constexpr double kMadToSigma = 1.4826;

std::string ValidateWeights(const std::vector<double>& weights, size_t n) {
  if (weights.empty()) return "";
  if (weights.size() != n) {
    return "got " + std::to_string(weights.size()) + " weights for " + std::to_string(n) + " samples";
  }
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(weights[i]) || weights[i] < 0.0) {
      return "weight " + std::to_string(i) + " is not a finite non-negative number";
    }
    sum += weights[i];
  }
  return sum > 0.0 ? "" : "weights sum to zero";
}

// One Weiszfeld / Vardi–Zhang step in a tangent space at y. `residual(i)` gives x_i − y in that
// tangent space. Returns the step; sets `at_median` when y itself is the median.
template <typename ResidualFn>
Eigen::Vector3d WeiszfeldStep(size_t n, const std::vector<double>& weights, double coincidence,
                              ResidualFn residual, bool* at_median) {
  Eigen::Vector3d pull = Eigen::Vector3d::Zero();  // Σ_{i∉C} w_i r_i / d_i
  double inverse_distance_sum = 0.0;               // Σ_{i∉C} w_i / d_i
  double eta = 0.0;                                // weight of samples at y
  for (size_t i = 0; i < n; ++i) {
    const double w = weights.empty() ? 1.0 : weights[i];
    if (w <= 0.0) continue;
    const Eigen::Vector3d r = residual(i);
    const double d = r.norm();
    if (d < coincidence) {
      eta += w;
      continue;
    }
    pull += (w / d) * r;
    inverse_distance_sum += w / d;
  }
  *at_median = false;
  if (inverse_distance_sum == 0.0) {  // every weighted sample is at y
    *at_median = true;
    return Eigen::Vector3d::Zero();
  }
  const Eigen::Vector3d step = pull / inverse_distance_sum;
  if (eta > 0.0) {
    const double pull_norm = pull.norm();
    if (pull_norm <= eta) {  // subgradient optimality at a sample
      *at_median = true;
      return Eigen::Vector3d::Zero();
    }
    return (1.0 - eta / pull_norm) * step;
  }
  return step;
}

}  // namespace

RotationL1MedianResult ComputeRotationL1Median(const std::vector<Eigen::Quaterniond>& quat_WV,
                                               const std::vector<double>& weights,
                                               const L1MedianOptions& options) {
  RotationL1MedianResult result;
  const ChordalMeanResult start = ComputeChordalMean(quat_WV, weights);
  if (!start.valid) {
    result.reason = start.reason;
    return result;
  }
  Eigen::Quaterniond y = start.q_WV_mean;
  for (int k = 0; k < options.max_iterations; ++k) {
    const Eigen::Quaterniond y_conj = y.conjugate();
    bool at_median = false;
    const Eigen::Vector3d step = WeiszfeldStep(
        quat_WV.size(), weights, options.coincidence_tolerance,
        [&](size_t i) { return LogQuaternion(y_conj * quat_WV[i]); }, &at_median);
    result.iterations = k + 1;
    if (at_median) {
      result.converged = true;
      break;
    }
    y = (y * ExpQuaternion(step)).normalized();
    if (step.norm() < options.step_tolerance) {
      result.converged = true;
      break;
    }
  }
  result.q_WV_median = CanonicalQuaternion(y);
  result.valid = true;
  return result;
}

PointL1MedianResult ComputePointL1Median(const std::vector<Eigen::Vector3d>& p_W,
                                         const std::vector<double>& weights, const L1MedianOptions& options) {
  PointL1MedianResult result;
  if (p_W.empty()) {
    result.reason = "no points";
    return result;
  }
  result.reason = ValidateWeights(weights, p_W.size());
  if (!result.reason.empty()) return result;
  Eigen::Vector3d y = Eigen::Vector3d::Zero();
  double weight_sum = 0.0;
  for (size_t i = 0; i < p_W.size(); ++i) {
    if (!p_W[i].allFinite()) {
      result.reason = "point " + std::to_string(i) + " has a non-finite coordinate";
      return result;
    }
    const double w = weights.empty() ? 1.0 : weights[i];
    y += w * p_W[i];
    weight_sum += w;
  }
  y /= weight_sum;
  for (int k = 0; k < options.max_iterations; ++k) {
    bool at_median = false;
    const Eigen::Vector3d step = WeiszfeldStep(
        p_W.size(), weights, options.coincidence_tolerance,
        [&](size_t i) -> Eigen::Vector3d { return p_W[i] - y; }, &at_median);
    result.iterations = k + 1;
    if (at_median) {
      result.converged = true;
      break;
    }
    y += step;
    if (step.norm() < options.step_tolerance) {
      result.converged = true;
      break;
    }
  }
  result.p_W_median = y;
  result.valid = true;
  return result;
}

OutlierResult RejectOutliers(const std::vector<Eigen::Quaterniond>& quat_WV,
                             const std::vector<Eigen::Vector3d>& p_WV, const OutlierOptions& options) {
  OutlierResult result;
  if (quat_WV.size() != p_WV.size()) {
    result.reason = "got " + std::to_string(quat_WV.size()) + " rotations but " +
                    std::to_string(p_WV.size()) + " translations";
    return result;
  }
  if (!(options.k_mad > 0.0) || !(options.min_rotation_threshold_deg >= 0.0) ||
      !(options.min_translation_threshold_m >= 0.0)) {
    result.reason = "outlier options need k_mad > 0 and non-negative threshold floors";
    return result;
  }
  const RotationL1MedianResult rotation_median = ComputeRotationL1Median(quat_WV, {}, options.median);
  if (!rotation_median.valid) {
    result.reason = rotation_median.reason;
    return result;
  }
  const PointL1MedianResult point_median = ComputePointL1Median(p_WV, {}, options.median);
  if (!point_median.valid) {
    result.reason = point_median.reason;
    return result;
  }
  result.q_WV_median = rotation_median.q_WV_median;
  result.p_WV_median = point_median.p_W_median;

  const size_t n = quat_WV.size();
  std::vector<double> rotation_deg(n), translation_m(n);
  for (size_t i = 0; i < n; ++i) {
    rotation_deg[i] = kRadToDeg * GeodesicDistance(result.q_WV_median, quat_WV[i]);
    translation_m[i] = (p_WV[i] - result.p_WV_median).norm();
  }
  auto threshold = [&](const std::vector<double>& d, double floor) {
    const double med = stats::Median(d);
    std::vector<double> deviation(d.size());
    for (size_t i = 0; i < d.size(); ++i) deviation[i] = std::abs(d[i] - med);
    return std::max(floor, med + options.k_mad * kMadToSigma * stats::Median(deviation));
  };
  result.rotation_threshold_deg = threshold(rotation_deg, options.min_rotation_threshold_deg);
  result.translation_threshold_m = threshold(translation_m, options.min_translation_threshold_m);

  const bool may_reject = static_cast<int>(n) >= options.min_trials;
  for (size_t i = 0; i < n; ++i) {
    const bool rotation_out = may_reject && rotation_deg[i] > result.rotation_threshold_deg;
    const bool translation_out = may_reject && translation_m[i] > result.translation_threshold_m;
    if (!rotation_out && !translation_out) {
      result.inliers.push_back(static_cast<int>(i));
      continue;
    }
    RejectedTrial rejected;
    rejected.index = static_cast<int>(i);
    rejected.rotation_deg = rotation_deg[i];
    rejected.translation_m = translation_m[i];
    char buf[256];
    if (rotation_out && translation_out) {
      std::snprintf(buf, sizeof(buf),
                    "rotation %.3f deg > threshold %.3f deg and translation %.4f m > threshold %.4f m "
                    "from the L1 medians",
                    rotation_deg[i], result.rotation_threshold_deg, translation_m[i],
                    result.translation_threshold_m);
    } else if (rotation_out) {
      std::snprintf(buf, sizeof(buf), "rotation %.3f deg from the L1 median > threshold %.3f deg",
                    rotation_deg[i], result.rotation_threshold_deg);
    } else {
      std::snprintf(buf, sizeof(buf), "translation %.4f m from the L1 median > threshold %.4f m",
                    translation_m[i], result.translation_threshold_m);
    }
    rejected.reason = buf;
    result.rejected.push_back(rejected);
  }
  result.valid = true;
  return result;
}

}  // namespace orbed::geometry
