#pragma once
/// @file
/// SO(3) primitives for the registration server: the exponential and logarithm maps, rotation
/// distances, and validation of rotations that arrive from outside (files, messages).
///
/// Conventions (docs/design.md, "Frames"): a rotation R_AB maps vectors expressed in B to A. Quaternions are
/// Eigen::Quaterniond, stored (x, y, z, w) internally but always read/written as (w, x, y, z) at the
/// boundary. q and -q are the same rotation; every function here accepts either sign.
/// A rotation vector w = θ·a (unit axis a, angle θ [rad]) is the Lie-algebra coordinate:
/// R = exp(ŵ), ŵ = Hat(w). Log returns θ ∈ [0, π].
///
/// Accuracy: Log and Exp are accurate to a few ulp of θ over the whole range θ ∈ [1e-10, π]; they
/// never take acos of the trace (which loses half the digits near 0 and near π). The angle comes
/// from atan2(|v|, |w|) of the quaternion, and the quaternion of a matrix from Eigen's
/// largest-pivot (Shepperd-style) conversion.
///
/// Threading: every function is pure and reentrant.

#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace orbed::geometry {

/// The skew-symmetric matrix ŵ with ŵ·v = w × v.
Eigen::Matrix3d Hat(const Eigen::Vector3d& w);

/// exp: rotation vector w [rad] → unit quaternion (w ≥ 0 for |w| ≤ π).
Eigen::Quaterniond ExpQuaternion(const Eigen::Vector3d& w);

/// exp: rotation vector w [rad] → rotation matrix.
Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& w);

/// log: unit quaternion (either sign) → rotation vector θ·a [rad], θ ∈ [0, π]. At exactly θ = π
/// the axis sign is the one carried by the quaternion's vector part (both are valid logs).
/// The quaternion need not be exactly unit: only its direction matters.
Eigen::Vector3d LogQuaternion(const Eigen::Quaterniond& quat);

/// log: rotation matrix (must already be in SO(3); see ValidateRotationMatrix) → θ·a [rad].
Eigen::Vector3d LogSO3(const Eigen::Matrix3d& R);

/// Rotation angle of q [rad], in [0, π].
double RotationAngle(const Eigen::Quaterniond& quat);

/// Geodesic distance between two rotations, the angle of quat_a⁻¹·quat_b [rad], in [0, π].
double GeodesicDistance(const Eigen::Quaterniond& quat_a, const Eigen::Quaterniond& quat_b);

/// The representative of ±q with w > 0; when w == 0 the first non-zero of (x, y, z) is made
/// positive. Gives every rotation a single printed form.
Eigen::Quaterniond CanonicalQuaternion(const Eigen::Quaterniond& quat);

/// Tolerances for accepting rotations from outside.
struct RotationTolerance {
  /// Accepted as is: ‖RᵀR − I‖_F (or |‖q‖ − 1|) at most this.
  double exact = 1e-9;
  /// Projected to SO(3) (and reported) up to this; beyond, rejected.
  double projectable = 1e-3;
};

/// The outcome of validating a rotation given by a matrix or a quaternion.
struct RotationCheck {
  /// True when the rotation is usable (as given or after projection).
  bool valid = false;
  /// True when the input was slightly off SO(3) and was projected onto it.
  bool projected = false;
  /// ‖RᵀR − I‖_F for matrices, |‖q‖ − 1| for quaternions.
  double error = 0.0;
  /// The usable rotation (identity when !valid).
  Eigen::Quaterniond quat = Eigen::Quaterniond::Identity();
  /// Why it was rejected, or what projection did ("" when valid and untouched).
  std::string message;
};

/// Validates R: all entries finite, det(R) > 0, ‖RᵀR − I‖_F ≤ tolerance.projectable; between
/// exact and projectable it is projected to the nearest rotation (SVD, Frobenius sense).
RotationCheck ValidateRotationMatrix(const Eigen::Matrix3d& R, const RotationTolerance& tolerance = {});

/// Validates a quaternion given as (w, x, y, z): finite, |‖q‖ − 1| ≤ tolerance.projectable;
/// between exact and projectable it is normalized.
RotationCheck ValidateQuaternionWxyz(const Eigen::Vector4d& wxyz, const RotationTolerance& tolerance = {});

}  // namespace orbed::geometry
