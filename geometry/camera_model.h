#pragma once
/// @file
/// Pinhole camera geometry of the HMD's photo/video camera C and of the reflective-AR display's
/// reversed frustum M (paper Sec. II-B). Computer-vision convention: z forward along the principal
/// ray, x right, y down; pixel (u, v) with u right, v down, pixel centres at integers.
///
///   Observer:  P_o = K_o [R_CW | p_CW]            (X_CW = X_WC⁻¹)
///   Mirror:    X_CM = [R_x(π) | (0, 0, D)]         (M is C rotated π about x, moved D along z_C)
///              X_WM = X_WC · X_CM,  K_m = diag(1, −1, 1) · K_o,  P_m = K_m [R_MW | p_MW]
/// (the flip and the shift act in C, after the extrinsics; the paper's printed product order differs,
/// see reflective.h). D is the distance from the camera centre to the gaze hit on the robot [m].
///
/// Pure functions; thread-safe.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <stdexcept>

namespace orbed::geometry {

struct Intrinsics {
  int width_px = 1280;
  int height_px = 720;
  double fx_px = 1545.4;
  double fy_px = 1551.2;
  double cx_px = 597.2;
  double cy_px = 322.1;

  /// HoloLens 1 photo/video camera, 1280×720 mode (the principal point is off-centre).
  static Intrinsics HoloLensPv() { return Intrinsics{}; }
  Eigen::Matrix3d K() const {
    Eigen::Matrix3d k;
    k << fx_px, 0, cx_px, 0, fy_px, cy_px, 0, 0, 1;
    return k;
  }
};

/// The frame of a viewer (head or camera) at p_WE looking at p_WT, z up in W: z toward the target,
/// x horizontal to the right, y down (computer-vision axes). Throws std::invalid_argument when the
/// target is within 1 mm or straight above/below (roll undefined).
inline Eigen::Isometry3d LookAt(const Eigen::Vector3d& p_WE, const Eigen::Vector3d& p_WT) {
  const Eigen::Vector3d d = p_WT - p_WE;
  if (!(d.norm() > 1e-3)) throw std::invalid_argument("look-at target within 1 mm of the viewer");
  const Eigen::Vector3d z = d.normalized();
  const Eigen::Vector3d x_raw = z.cross(Eigen::Vector3d::UnitZ());
  if (!(x_raw.norm() > 1e-6)) {
    throw std::invalid_argument("look-at target straight above or below the viewer");
  }
  const Eigen::Vector3d x = x_raw.normalized();
  Eigen::Isometry3d X_WE = Eigen::Isometry3d::Identity();
  X_WE.linear().col(0) = x;
  X_WE.linear().col(1) = z.cross(x);
  X_WE.linear().col(2) = z;
  X_WE.translation() = p_WE;
  return X_WE;
}

using CameraMatrix = Eigen::Matrix<double, 3, 4>;

/// P = K [R_CW | p_CW] for a camera at X_WC.
inline CameraMatrix MakeCameraMatrix(const Eigen::Matrix3d& K, const Eigen::Isometry3d& X_WC) {
  const Eigen::Isometry3d X_CW = X_WC.inverse();
  CameraMatrix Rt;
  Rt.leftCols<3>() = X_CW.linear();
  Rt.col(3) = X_CW.translation();
  return K * Rt;
}

/// Projects p_W with P. Returns false (uv untouched) when the point is not in front of the camera
/// (homogeneous depth <= 1e-9).
inline bool Project(const CameraMatrix& P, const Eigen::Vector3d& p_W, Eigen::Vector2d* uv) {
  const Eigen::Vector3d h = P * p_W.homogeneous();
  if (!(h.z() > 1e-9)) return false;
  *uv = h.head<2>() / h.z();
  return true;
}

/// The reversed frustum's pose in C: rotated π about x, moved D along the principal ray.
inline Eigen::Isometry3d MirrorPoseInCamera(double D_m) {
  Eigen::Isometry3d X_CM = Eigen::Isometry3d::Identity();
  X_CM.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  X_CM.translation() = Eigen::Vector3d(0, 0, D_m);
  return X_CM;
}

/// K_m = diag(1, −1, 1) · K_o.
inline Eigen::Matrix3d MirrorIntrinsics(const Eigen::Matrix3d& K_o) {
  return Eigen::Vector3d(1, -1, 1).asDiagonal() * K_o;
}

/// P_m for a frame captured at X_WC with gaze distance D.
inline CameraMatrix MakeMirrorCameraMatrix(const Eigen::Matrix3d& K_o, const Eigen::Isometry3d& X_WC,
                                           double D_m) {
  return MakeCameraMatrix(MirrorIntrinsics(K_o), X_WC * MirrorPoseInCamera(D_m));
}

}  // namespace orbed::geometry
