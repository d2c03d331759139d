#include "lcmtypes/contract/conversions.h"

#include <chrono>

namespace orbed {

Eigen::Quaterniond QuaternionFromWxyz(const double q_wxyz[4]) {
  return Eigen::Quaterniond(q_wxyz[0], q_wxyz[1], q_wxyz[2], q_wxyz[3]);
}

void QuaternionToWxyz(const Eigen::Quaterniond& q, double q_wxyz[4]) {
  q_wxyz[0] = q.w();
  q_wxyz[1] = q.x();
  q_wxyz[2] = q.y();
  q_wxyz[3] = q.z();
}

orbed::pose_t ToPose(const Eigen::Isometry3d& X_AB) {
  orbed::pose_t pose{};
  FromVector3(X_AB.translation(), pose.position_m);
  Eigen::Quaterniond q(X_AB.rotation());
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  QuaternionToWxyz(q, pose.quaternion_wxyz);
  return pose;
}

Eigen::Isometry3d FromPose(const orbed::pose_t& pose) {
  Eigen::Isometry3d X_AB = Eigen::Isometry3d::Identity();
  X_AB.linear() = QuaternionFromWxyz(pose.quaternion_wxyz).normalized().toRotationMatrix();
  X_AB.translation() = ToVector3(pose.position_m);
  return X_AB;
}

Eigen::Vector3d ToVector3(const double v[3]) { return Eigen::Vector3d(v[0], v[1], v[2]); }

void FromVector3(const Eigen::Vector3d& v, double out[3]) {
  for (int i = 0; i < 3; ++i) out[i] = v[i];
}

Eigen::Matrix3d ToMatrix3(const double m[3][3]) {
  Eigen::Matrix3d out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out(r, c) = m[r][c];
  return out;
}

void FromMatrix3(const Eigen::Matrix3d& m, double out[3][3]) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[r][c] = m(r, c);
}

Eigen::VectorXd ToVectorX(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

std::vector<double> FromVectorX(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

int64_t NowMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

orbed::image_t JpegImageMessage(const std::vector<std::uint8_t>& jpeg, const geometry::Intrinsics& K,
                                int64_t utime, const Eigen::Isometry3d& X_WC, int64_t pose_utime) {
  orbed::image_t img{};
  img.utime = utime;
  img.width = K.width_px;
  img.height = K.height_px;
  img.row_stride = 0;
  img.pixel_format = orbed::image_t::FORMAT_JPEG;
  img.fx_px = K.fx_px;
  img.fy_px = K.fy_px;
  img.cx_px = K.cx_px;
  img.cy_px = K.cy_px;
  img.X_WC = ToPose(X_WC);
  img.pose_utime = pose_utime;
  img.num_bytes = static_cast<int32_t>(jpeg.size());
  img.data = jpeg;
  return img;
}

}  // namespace orbed
