#include "hmd_emulator/annotation.h"

#include <algorithm>
#include <cmath>

#include "base/units.h"

namespace orbed::hmd {

Eigen::Isometry3d HeadLookingAt(const Eigen::Vector3d& p_WH, const Eigen::Vector3d& p_WQ) {
  const Eigen::Vector3d z = (p_WQ - p_WH).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d X_WH = Eigen::Isometry3d::Identity();
  X_WH.linear().col(0) = x;
  X_WH.linear().col(1) = y;
  X_WH.linear().col(2) = z;
  X_WH.translation() = p_WH;
  return X_WH;
}

AnnotatingPerson::AnnotatingPerson(SlamModel* slam, double t_s, const AnnotationStyle& style,
                                   std::uint64_t pointing_seed)
    : slam_(slam), style_(style), rng_(pointing_seed), t_s_(t_s) {
  slam_->set_random_losses(false);
}

GazeRayRecord AnnotatingPerson::Annotate(const Eigen::Vector3d& p_WH, const Eigen::Vector3d& p_WQ) {
  const double sigma_rad = style_.pointing_std_deg * kDegToRad;
  const double about_x = rng_.Normal(0.0, sigma_rad);
  const double about_y = rng_.Normal(0.0, sigma_rad);
  Eigen::Isometry3d X_WH_true = HeadLookingAt(p_WH, p_WQ);
  X_WH_true.linear() = X_WH_true.linear() *
                       Eigen::AngleAxisd(about_x, Eigen::Vector3d::UnitX()).toRotationMatrix() *
                       Eigen::AngleAxisd(about_y, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const int samples = std::max(1, static_cast<int>(std::lround(style_.dwell_s * slam_->config().rate_hz)));
  for (int k = 0; k < samples; ++k) Step(X_WH_true);
  return {last_.X_WH_est.translation(), last_.X_WH_est.linear().col(2)};
}

GazeRayRecord AnnotatingPerson::AnnotateHologram(const Eigen::Vector3d& p_WH, const Eigen::Isometry3d& X_WV,
                                                 const Eigen::Vector3d& p_VQ) {
  return Annotate(p_WH, ApparentPose(last_.X_WH_true, last_.X_WH_est, X_WV) * p_VQ);
}

void AnnotatingPerson::Walk(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                            const Eigen::Vector3d& look_at) {
  const double distance = (to - from).norm();
  const int samples = std::max(
      1, static_cast<int>(std::ceil(distance / style_.walk_speed_m_per_s * slam_->config().rate_hz)));
  for (int k = 1; k <= samples; ++k) {
    const Eigen::Vector3d p = from + (to - from) * (static_cast<double>(k) / samples);
    Step(HeadLookingAt(p, look_at));
  }
}

SlamSample AnnotatingPerson::Step(const Eigen::Isometry3d& X_WH_true) {
  last_ = slam_->Step(X_WH_true, t_s_);
  t_s_ += 1.0 / slam_->config().rate_hz;
  return last_;
}

}  // namespace orbed::hmd
