#include "geometry/triangulation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "base/units.h"

namespace orbed::geometry {
namespace {

// Angle between unit vectors [rad] in [0, π], from atan2 (accurate at 0 and π).
double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

}  // namespace

TriangulationResult TriangulateRays(const std::vector<Eigen::Vector3d>& origin_W_m,
                                    const std::vector<Eigen::Vector3d>& direction_W,
                                    const TriangulationOptions& options) {
  TriangulationResult result;
  const size_t n = origin_W_m.size();
  if (n != direction_W.size()) {
    result.reason =
        "got " + std::to_string(n) + " ray origins but " + std::to_string(direction_W.size()) + " directions";
    return result;
  }
  if (n < 2) {
    result.reason = "need at least 2 rays, got " + std::to_string(n);
    return result;
  }
  if (!std::isfinite(options.min_ray_angle_deg) || options.min_ray_angle_deg < 0.0 ||
      options.min_ray_angle_deg >= 90.0) {
    result.reason = "min_ray_angle_deg must be in [0, 90)";
    return result;
  }
  for (size_t i = 0; i < n; ++i) {
    if (!origin_W_m[i].allFinite() || !direction_W[i].allFinite()) {
      result.reason = "ray " + std::to_string(i) + " has a non-finite origin or direction";
      return result;
    }
    const double norm = direction_W[i].norm();
    if (std::abs(norm - 1.0) > options.unit_tolerance) {
      char buf[128];
      std::snprintf(buf, sizeof(buf), "direction of ray %zu has norm %.9g, expected a unit vector", i, norm);
      result.reason = buf;
      return result;
    }
  }

  // Ray geometry: largest direction angle (reported) and largest acute line angle (the test).
  double max_direction_angle = 0.0, max_line_angle = 0.0;
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      const double angle = AngleBetween(direction_W[i], direction_W[j]);
      max_direction_angle = std::max(max_direction_angle, angle);
      max_line_angle = std::max(max_line_angle, std::min(angle, kPi - angle));
    }
  }
  result.ray_angle_deg = kRadToDeg * max_direction_angle;
  if (kRadToDeg * max_line_angle < options.min_ray_angle_deg) {
    char buf[160];
    std::snprintf(buf, sizeof(buf), "rays are near-parallel: largest angle between lines %.4g deg < %.4g deg",
                  kRadToDeg * max_line_angle, options.min_ray_angle_deg);
    result.reason = buf;
    return result;
  }

  // Normal equations (Σ P_i) x = Σ P_i h_i; Σ P_i is symmetric positive definite once two lines
  // are non-parallel. Origins are taken relative to the first one to keep the numbers small.
  const Eigen::Vector3d h0 = origin_W_m[0];
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d u = direction_W[i].normalized();
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - u * u.transpose();
    A += P;
    b += P * (origin_W_m[i] - h0);
  }
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(A);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) {
    result.reason = "the ray normal matrix is singular";
    return result;
  }
  result.p_W = h0 + ldlt.solve(b);

  double sum_sq_gap = 0.0;
  result.depth_m.resize(n);
  int behind = -1;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d u = direction_W[i].normalized();
    const Eigen::Vector3d d = result.p_W - origin_W_m[i];
    result.depth_m[i] = d.dot(u);
    sum_sq_gap += (d - result.depth_m[i] * u).squaredNorm();
    if (result.depth_m[i] < 0.0 && behind < 0) behind = static_cast<int>(i);
  }
  result.gap_m = std::sqrt(sum_sq_gap / static_cast<double>(n));
  if (behind >= 0) {
    char buf[160];
    std::snprintf(buf, sizeof(buf), "the point is behind the origin of ray %d (depth %.4g m)", behind,
                  result.depth_m[behind]);
    result.reason = buf;
    return result;
  }
  result.valid = true;
  return result;
}

}  // namespace orbed::geometry
