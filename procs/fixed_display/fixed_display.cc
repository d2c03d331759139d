#include "procs/fixed_display/fixed_display.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "base/units.h"

namespace orbed::fixed_display {

OrbitView OrbitView::Through(const Eigen::Vector3d& p_WD, const Eigen::Vector3d& p_Wc) {
  const Eigen::Vector3d d = p_WD - p_Wc;
  OrbitView view;
  view.distance_m = d.norm();
  if (!(view.distance_m >= kMinDistance_m && view.distance_m <= kMaxDistance_m)) {
    throw std::invalid_argument("the monitor's camera must be " + std::to_string(kMinDistance_m) + " to " +
                                std::to_string(kMaxDistance_m) + " m from the robot's middle");
  }
  view.elevation_rad = std::asin(d.z() / view.distance_m);
  if (std::abs(view.elevation_rad) > kMaxElevation_rad) {
    throw std::invalid_argument("the monitor's camera is too steeply above or below the robot");
  }
  view.azimuth_rad = std::atan2(d.y(), d.x());
  return view;
}

Eigen::Isometry3d OrbitView::X_WD(const Eigen::Vector3d& p_Wc) const {
  const double ce = std::cos(elevation_rad);
  const Eigen::Vector3d p_WD =
      p_Wc + distance_m * Eigen::Vector3d(ce * std::cos(azimuth_rad), ce * std::sin(azimuth_rad),
                                          std::sin(elevation_rad));
  return geometry::LookAt(p_WD, p_Wc);
}

Eigen::Vector3d OrbitCentre(const Eigen::Isometry3d& X_WR) {
  return X_WR.translation() + Eigen::Vector3d(0, 0, kOrbitCentreHeight_m);
}

std::optional<OrbitView> ApplyKey(int key, const OrbitView& view, const OrbitView& home) {
  OrbitView v = view;
  switch (key) {
    case 'a':
      v.azimuth_rad -= 15 * kDegToRad;
      break;
    case 'd':
      v.azimuth_rad += 15 * kDegToRad;
      break;
    case 'w':
      v.elevation_rad += 10 * kDegToRad;
      break;
    case 's':
      v.elevation_rad -= 10 * kDegToRad;
      break;
    case '+':
    case '=':
      v.distance_m *= 0.85;
      break;
    case '-':
    case '_':
      v.distance_m /= 0.85;
      break;
    case 'r':
      v = home;
      break;
    default:
      return std::nullopt;
  }
  v.azimuth_rad = std::remainder(v.azimuth_rad, 2 * M_PI);
  v.elevation_rad = std::clamp(v.elevation_rad, -OrbitView::kMaxElevation_rad, OrbitView::kMaxElevation_rad);
  v.distance_m = std::clamp(v.distance_m, OrbitView::kMinDistance_m, OrbitView::kMaxDistance_m);
  return v;
}

geometry::Intrinsics MonitorIntrinsics(const PictureOptions& options) {
  geometry::Intrinsics K;
  K.width_px = options.width_px;
  K.height_px = options.height_px;
  K.fx_px = 0.5 * options.width_px / std::tan(0.5 * options.horizontal_fov_deg * kDegToRad);
  K.fy_px = K.fx_px;
  K.cx_px = 0.5 * (options.width_px - 1);
  K.cy_px = 0.5 * (options.height_px - 1);
  return K;
}

FixedViewRenderer::FixedViewRenderer(const sim::RobotModel& model, const sim::Scene* scene,
                                     const PictureOptions& options)
    : renderer_(MonitorIntrinsics(options)) {
  if (scene) geometry_.AddSceneObjects(*scene);
  robot_ = geometry_.AddRobot(model, render::BodyKind::kRealRobot);
}

cv::Mat FixedViewRenderer::Render(const Eigen::VectorXd& q_target_rad, const Eigen::Isometry3d& X_WR,
                                  const Eigen::Isometry3d& X_WD, const std::string& caption,
                                  cv::Mat* body_id) {
  geometry_.PoseRobot(robot_, q_target_rad, X_WR);
  mesh_.Clear();
  render::Tessellate(geometry_, render::kAllKinds, render::TessellationOptions{}, &mesh_);
  cv::Mat bgr;
  renderer_.Render(mesh_, X_WD, &bgr, nullptr, body_id);
  if (!caption.empty()) {
    cv::rectangle(bgr, cv::Point(0, 0), cv::Point(bgr.cols, 22), cv::Scalar(30, 30, 30), cv::FILLED);
    cv::putText(bgr, caption, cv::Point(6, 16), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(235, 235, 235), 1,
                cv::LINE_AA);
  }
  return bgr;
}

}  // namespace orbed::fixed_display
