#pragma once
/// @file
/// The frames an hl2ss client sees, and how they map to orbed's. One definition for every hl2ss
/// stream (poses, calibration) and for the holograms a client places (the Unity scene).
///
/// Frames:
///   W   orbed's world: z up, floor at z = 0 (docs/design.md §2).
///   D   the device's spatial coordinate system that hl2ss poses are expressed in: right-handed,
///       y up (as Windows Perception's). Same origin as W; x_D = x_W, y_D = z_W, z_D = −y_W.
///   C   orbed's camera frame: x right, y down, z forward along the principal ray.
///   Ĉ   ("Ch" in code) the camera frame the device reports for its cameras: x right, y up, z backward
///       (the camera looks along −z); X_CĈ = diag(1, −1, −1).
///   U   the Unity scene a hl2ss Unity plugin places holograms in: left-handed, y up, same origin;
///       p_U = (x, y, −z) of p_D.
/// hl2ss sends a pose as 16 float32 in row-major order of the matrix M = X_DĈᵀ (row-vector
/// convention: [p_D 1] = [p_Ĉ 1] · M), so the translation is in the last row.
///
/// Threading: pure functions.

#include <array>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace orbed::hl2ss {

/// R_WD: D's axes expressed in W (columns x_D = x_W, y_D = z_W, z_D = −y_W).
inline Eigen::Matrix3d R_WD() {
  Eigen::Matrix3d R;
  R << 1, 0, 0,  //
      0, 0, -1,  //
      0, 1, 0;
  return R;
}

/// X_WD: D has W's origin.
inline Eigen::Isometry3d X_WD() {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = R_WD();
  return X;
}

/// X_CĈ: the device's camera convention (y up, z backward) in orbed's (y down, z forward).
inline Eigen::Isometry3d X_CCh() {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::Vector3d(1, -1, -1).asDiagonal();
  return X;
}

/// The 16 float32 hl2ss sends for a pose X_DF of a frame F (row-major of X_DFᵀ).
inline std::array<float, 16> PoseMatrixRowMajor(const Eigen::Isometry3d& X_DF) {
  const Eigen::Matrix4d M = X_DF.matrix().transpose();
  std::array<float, 16> out{};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out[4 * r + c] = static_cast<float>(M(r, c));
  return out;
}

/// The pose hl2ss reports for an orbed camera at X_WC: X_DĈ = X_WD⁻¹ · X_WC · X_CĈ.
inline Eigen::Isometry3d CameraPoseForClient(const Eigen::Isometry3d& X_WC) {
  return X_WD().inverse() * X_WC * X_CCh();
}

/// Unity (U, left-handed) position to D: negate z.
inline Eigen::Vector3d p_D_FromUnity(const Eigen::Vector3d& p_U) { return {p_U.x(), p_U.y(), -p_U.z()}; }

/// Unity rotation (quaternion x, y, z, w as Unity stores it) to R_DF: with S = diag(1, 1, −1),
/// R_D = S R_U S, which for a quaternion negates its x and y parts.
inline Eigen::Quaterniond q_D_FromUnity(double x, double y, double z, double w) {
  return Eigen::Quaterniond(w, -x, -y, z).normalized();
}

}  // namespace orbed::hl2ss
