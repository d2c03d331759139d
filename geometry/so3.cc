#include "geometry/so3.h"

#include <cmath>
#include <cstdio>

#include <Eigen/SVD>

namespace orbed::geometry {
namespace {

// Below this |v| (half-angle sine) the series forms are exact to double precision: the first
// neglected term is O(n⁴) relative, < 1e-24.
constexpr double kSmallHalfSine = 1e-6;
// Below this θ the Exp series are exact to double precision (first neglected term O(θ⁴)).
constexpr double kSmallAngle = 1e-6;

std::string Format(const char* fmt, double a, double b = 0.0) {
  char buf[160];
  std::snprintf(buf, sizeof(buf), fmt, a, b);
  return buf;
}

}  // namespace

Eigen::Matrix3d Hat(const Eigen::Vector3d& w) {
  Eigen::Matrix3d m;
  m << 0.0, -w.z(), w.y(),  //
      w.z(), 0.0, -w.x(),   //
      -w.y(), w.x(), 0.0;
  return m;
}

Eigen::Quaterniond ExpQuaternion(const Eigen::Vector3d& w) {
  const double theta2 = w.squaredNorm();
  const double theta = std::sqrt(theta2);
  double c;            // cos(θ/2)
  double sin_over_th;  // sin(θ/2)/θ
  if (theta < kSmallAngle) {
    c = 1.0 - theta2 / 8.0;
    sin_over_th = 0.5 - theta2 / 48.0;
  } else {
    c = std::cos(0.5 * theta);
    sin_over_th = std::sin(0.5 * theta) / theta;
  }
  return Eigen::Quaterniond(c, sin_over_th * w.x(), sin_over_th * w.y(), sin_over_th * w.z());
}

Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& w) { return ExpQuaternion(w).toRotationMatrix(); }

Eigen::Vector3d LogQuaternion(const Eigen::Quaterniond& quat) {
  // quat = (cos(θ/2), sin(θ/2)·a) up to sign and scale; pick the w ≥ 0 hemisphere so θ ∈ [0, π].
  double w = quat.w();
  Eigen::Vector3d v = quat.vec();
  if (w < 0.0) {
    w = -w;
    v = -v;
  }
  const double n = v.norm();
  if (n < kSmallHalfSine * w) {
    // θ/n = 2·atan(n/w)/n = (2/w)·(1 − (n/w)²/3 + O((n/w)⁴)).
    const double r2 = (n * n) / (w * w);
    return (2.0 / w) * (1.0 - r2 / 3.0) * v;
  }
  const double theta = 2.0 * std::atan2(n, w);
  return (theta / n) * v;
}

Eigen::Vector3d LogSO3(const Eigen::Matrix3d& R) { return LogQuaternion(Eigen::Quaterniond(R)); }

double RotationAngle(const Eigen::Quaterniond& quat) {
  return 2.0 * std::atan2(quat.vec().norm(), std::abs(quat.w()));
}

double GeodesicDistance(const Eigen::Quaterniond& quat_a, const Eigen::Quaterniond& quat_b) {
  return RotationAngle(quat_a.conjugate() * quat_b);
}

Eigen::Quaterniond CanonicalQuaternion(const Eigen::Quaterniond& quat) {
  double sign = 1.0;
  if (quat.w() < 0.0) {
    sign = -1.0;
  } else if (quat.w() == 0.0) {
    const double first = quat.x() != 0.0 ? quat.x() : (quat.y() != 0.0 ? quat.y() : quat.z());
    if (first < 0.0) sign = -1.0;
  }
  return Eigen::Quaterniond(sign * quat.w(), sign * quat.x(), sign * quat.y(), sign * quat.z());
}

RotationCheck ValidateRotationMatrix(const Eigen::Matrix3d& R, const RotationTolerance& tolerance) {
  RotationCheck check;
  if (!R.allFinite()) {
    check.message = "rotation matrix has a non-finite entry";
    return check;
  }
  const double det = R.determinant();
  check.error = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
  if (!(det > 0.0)) {
    check.message =
        Format("rotation matrix has det = %.6g <= 0 (a reflection or singular), not a rotation", det);
    return check;
  }
  if (check.error > tolerance.projectable) {
    check.message =
        Format("not a rotation: |R^T R - I|_F = %.3g exceeds %.3g", check.error, tolerance.projectable);
    return check;
  }
  Eigen::Matrix3d R_use = R;
  if (check.error > tolerance.exact) {
    // Nearest rotation in the Frobenius norm: U·diag(1, 1, det(U Vᵀ))·Vᵀ.
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
    D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
    R_use = svd.matrixU() * D * svd.matrixV().transpose();
    check.projected = true;
    check.message = Format("rotation matrix projected to SO(3): |R^T R - I|_F was %.3g", check.error);
  }
  check.quat = Eigen::Quaterniond(R_use).normalized();
  check.valid = true;
  return check;
}

RotationCheck ValidateQuaternionWxyz(const Eigen::Vector4d& wxyz, const RotationTolerance& tolerance) {
  RotationCheck check;
  if (!wxyz.allFinite()) {
    check.message = "quaternion has a non-finite component";
    return check;
  }
  const double norm = wxyz.norm();
  check.error = std::abs(norm - 1.0);
  if (check.error > tolerance.projectable) {
    check.message =
        Format("quaternion norm %.9g is not 1 (off by more than %.3g)", norm, tolerance.projectable);
    return check;
  }
  check.quat = Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
  if (check.error > tolerance.exact) {
    check.projected = true;
    check.message = Format("quaternion normalized: its norm was %.9g", norm);
  }
  check.quat.normalize();
  check.valid = true;
  return check;
}

}  // namespace orbed::geometry
