#include "geometry/rotation_mean.h"

#include <cmath>
#include <string>

#include <Eigen/Eigenvalues>

#include "base/units.h"
#include "geometry/so3.h"

namespace orbed::geometry {
namespace {

constexpr double kUnitTolerance = 1e-6;
constexpr double kHalfPi = 1.5707963267948966;

// Rotation vector of the residual conj(q_bar)·q_i, hemisphere-fixed (θ ∈ [0, π]).
inline Eigen::Vector3d Residual(const Eigen::Quaterniond& q_bar_conj, const Eigen::Quaterniond& q_i) {
  return LogQuaternion(q_bar_conj * q_i);
}

}  // namespace

std::string ValidateRotationSamples(const std::vector<Eigen::Quaterniond>& quat_WV,
                                    const std::vector<double>& weights) {
  if (quat_WV.empty()) return "no rotations to average";
  if (!weights.empty() && weights.size() != quat_WV.size()) {
    return "got " + std::to_string(weights.size()) + " weights for " + std::to_string(quat_WV.size()) +
           " rotations";
  }
  for (size_t i = 0; i < quat_WV.size(); ++i) {
    const Eigen::Quaterniond& q = quat_WV[i];
    if (!q.coeffs().allFinite()) return "rotation " + std::to_string(i) + " has a non-finite component";
    if (std::abs(q.norm() - 1.0) > kUnitTolerance) {
      return "rotation " + std::to_string(i) + " is not a unit quaternion (norm " + std::to_string(q.norm()) +
             ")";
    }
  }
  if (!weights.empty()) {
    double sum = 0.0;
    for (size_t i = 0; i < weights.size(); ++i) {
      if (!std::isfinite(weights[i]) || weights[i] < 0.0) {
        return "weight " + std::to_string(i) + " is not a finite non-negative number";
      }
      sum += weights[i];
    }
    if (!(sum > 0.0)) return "weights sum to zero";
  }
  return "";
}

ChordalMeanResult ComputeChordalMean(const std::vector<Eigen::Quaterniond>& quat_WV,
                                     const std::vector<double>& weights) {
  ChordalMeanResult result;
  result.reason = ValidateRotationSamples(quat_WV, weights);
  if (!result.reason.empty()) return result;

  // M = Σ w_i q_i q_iᵀ / Σ w_i, with q as the 4-vector (x, y, z, w); the sign of q cancels.
  Eigen::Matrix4d M = Eigen::Matrix4d::Zero();
  double weight_sum = 0.0;
  for (size_t i = 0; i < quat_WV.size(); ++i) {
    const double w = weights.empty() ? 1.0 : weights[i];
    const Eigen::Vector4d c = quat_WV[i].coeffs();
    M.selfadjointView<Eigen::Lower>().rankUpdate(c, w);
    weight_sum += w;
  }
  M /= weight_sum;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> solver(M.selfadjointView<Eigen::Lower>());
  if (solver.info() != Eigen::Success) {
    result.reason = "eigen-decomposition of the quaternion scatter matrix failed";
    return result;
  }
  // Eigenvalues ascend.
  const Eigen::Vector4d v = solver.eigenvectors().col(3);
  result.q_WV_mean = CanonicalQuaternion(Eigen::Quaterniond(v[3], v[0], v[1], v[2]).normalized());
  result.eigen_gap = solver.eigenvalues()[3] - solver.eigenvalues()[2];
  result.valid = true;
  return result;
}

KarcherMeanResult ComputeKarcherMean(const std::vector<Eigen::Quaterniond>& quat_WV,
                                     const std::vector<double>& weights, const KarcherOptions& options) {
  KarcherMeanResult result;
  if (!(options.step_tolerance_rad > 0.0) || options.max_iterations < 1) {
    result.reason = "Karcher options need step_tolerance_rad > 0 and max_iterations >= 1";
    return result;
  }
  const ChordalMeanResult start = ComputeChordalMean(quat_WV, weights);
  if (!start.valid) {
    result.reason = start.reason;
    return result;
  }
  result.q_WV_start = start.q_WV_mean;
  result.chordal_eigen_gap = start.eigen_gap;

  double weight_sum = 0.0;
  if (weights.empty()) {
    weight_sum = static_cast<double>(quat_WV.size());
  } else {
    for (double w : weights) weight_sum += w;
  }
  const double inv_weight_sum = 1.0 / weight_sum;

  Eigen::Quaterniond q_bar = start.q_WV_mean;
  double max_residual = 0.0;
  double max_residual_seen = 0.0;  // over every evaluation, for the ambiguity flag
  bool residuals_current = false;  // max_residual evaluated at q_bar (not one step behind)
  for (int k = 0; k < options.max_iterations; ++k) {
    const Eigen::Quaterniond q_bar_conj = q_bar.conjugate();
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    double max_sq = 0.0;
    for (size_t i = 0; i < quat_WV.size(); ++i) {
      const Eigen::Vector3d r = Residual(q_bar_conj, quat_WV[i]);
      const double w = weights.empty() ? 1.0 : weights[i];
      step += w * r;
      // Only samples with weight contribute to the certificate (zero weight = not in the set).
      if (w > 0.0) max_sq = std::max(max_sq, r.squaredNorm());
    }
    step *= inv_weight_sum;
    max_residual = std::sqrt(max_sq);
    max_residual_seen = std::max(max_residual_seen, max_residual);
    result.last_step_rad = step.norm();
    q_bar = (q_bar * ExpQuaternion(step)).normalized();
    result.iterations = k + 1;
    if (result.last_step_rad < options.step_tolerance_rad) {
      // The residuals above were taken < tolerance away from the returned mean.
      result.converged = true;
      residuals_current = true;
      break;
    }
  }
  if (!residuals_current) {
    const Eigen::Quaterniond q_bar_conj = q_bar.conjugate();
    double max_sq = 0.0;
    for (size_t i = 0; i < quat_WV.size(); ++i) {
      if (!weights.empty() && weights[i] <= 0.0) continue;
      max_sq = std::max(max_sq, Residual(q_bar_conj, quat_WV[i]).squaredNorm());
    }
    max_residual = std::sqrt(max_sq);
    max_residual_seen = std::max(max_residual_seen, max_residual);
  }
  result.q_WV_mean = CanonicalQuaternion(q_bar);
  result.max_residual_rad = max_residual;
  result.unique = max_residual < kHalfPi - options.certificate_margin_rad;
  result.ambiguous = max_residual_seen > kPi - options.ambiguity_tolerance_rad;
  result.valid = true;
  return result;
}

}  // namespace orbed::geometry
