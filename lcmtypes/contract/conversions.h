#pragma once
/// @file
/// Eigen <-> message conversions. pose_t holds X_AB as (p_AB [m], q_AB (w, x, y, z)); the frames
/// are named by the field that holds it. ToPose normalises the quaternion and picks w >= 0 so that
/// equal rotations encode to equal bytes. FromPose does not validate: run CheckPose first on
/// anything that came off the bus.

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>
#include <orbed/image_t.hpp>
#include <orbed/pose_t.hpp>

#include "geometry/camera_model.h"

namespace orbed {

orbed::pose_t ToPose(const Eigen::Isometry3d& X_AB);
Eigen::Isometry3d FromPose(const orbed::pose_t& pose);

/// (w, x, y, z) array <-> Eigen quaternion (Eigen stores x, y, z, w internally: never memcpy).
Eigen::Quaterniond QuaternionFromWxyz(const double q_wxyz[4]);
void QuaternionToWxyz(const Eigen::Quaterniond& q, double q_wxyz[4]);

/// Fixed-size message arrays <-> Eigen.
Eigen::Vector3d ToVector3(const double v[3]);
void FromVector3(const Eigen::Vector3d& v, double out[3]);
Eigen::Matrix3d ToMatrix3(const double m[3][3]);
void FromMatrix3(const Eigen::Matrix3d& m, double out[3][3]);

Eigen::VectorXd ToVectorX(const std::vector<double>& v);
std::vector<double> FromVectorX(const Eigen::VectorXd& v);

/// An image_t of JPEG bytes with the camera's intrinsics K, its pose X_WC (what the publisher knows:
/// the headset's SLAM estimate, a rendering camera's truth) and the times of capture and of the pose.
orbed::image_t JpegImageMessage(const std::vector<std::uint8_t>& jpeg, const geometry::Intrinsics& K,
                                int64_t utime, const Eigen::Isometry3d& X_WC, int64_t pose_utime);

/// Wall clock in microseconds since the Unix epoch (the utime of most messages).
int64_t NowMicros();

}  // namespace orbed
