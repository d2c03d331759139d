#pragma once
/// @file
/// Small rotation helpers shared by the registration library's tests (not part of the library):
/// a rotation from angle-axis and the geodesic angle between two rotations, both via Eigen's
/// AngleAxis, which the tests use as the independent oracle.

#include <Eigen/Geometry>

namespace orbed::geometry::testing {

/// R = exp(angle · axis^), the axis normalised.
inline Eigen::Quaterniond Rot(double angle_rad, const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, axis.normalized()));
}

/// Geodesic angle of a^-1·b [rad], in [0, π].
inline double AngleBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return Eigen::AngleAxisd(a.conjugate() * b).angle();
}

}  // namespace orbed::geometry::testing
