#include "hmd_emulator/reflective.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace orbed::hmd {
namespace {

bool SameIntrinsics(const geometry::Intrinsics& a, const geometry::Intrinsics& b) {
  return a.width_px == b.width_px && a.height_px == b.height_px && a.fx_px == b.fx_px && a.fy_px == b.fy_px &&
         a.cx_px == b.cx_px && a.cy_px == b.cy_px;
}

}  // namespace

ReflectiveGeometry MakeReflectiveGeometry(const geometry::Intrinsics& intrinsics,
                                          const Eigen::Isometry3d& X_WC, double D_m) {
  if (!std::isfinite(D_m) || !(D_m > 0))
    throw std::invalid_argument("reflective display: D must be finite and > 0, got " + std::to_string(D_m));
  ReflectiveGeometry g;
  g.K_o = intrinsics.K();
  g.K_m = geometry::MirrorIntrinsics(g.K_o);
  g.X_WC = X_WC;
  g.X_WM = X_WC * geometry::MirrorPoseInCamera(D_m);
  g.distance_m = D_m;
  g.P_o = geometry::MakeCameraMatrix(g.K_o, X_WC);
  g.P_m = geometry::MakeMirrorCameraMatrix(g.K_o, X_WC, D_m);
  return g;
}

Eigen::Vector3d DisplayPanelPoint(const ReflectiveGeometry& g, double u_px, double v_px,
                                  double depth_in_M_m) {
  const double s = depth_in_M_m > 0 ? depth_in_M_m : 0.5 * g.distance_m;
  const double fx = g.K_o(0, 0), fy = g.K_o(1, 1), cx = g.K_o(0, 2), cy = g.K_o(1, 2);
  const Eigen::Vector3d p_MQ = s * Eigen::Vector3d((u_px - cx) / fx, -(v_px - cy) / fy, 1.0);
  return g.X_WM * p_MQ;
}

Compositor::Compositor(const sim::RobotModel& robot, const render::OverlayStyle& style,
                       const render::TessellationOptions& tessellation)
    : robot_(robot), style_(style), tessellation_(tessellation) {
  handle_ = virtual_robot_.AddRobot(robot, render::BodyKind::kVirtualRobot);
}

void Compositor::Overlay(const geometry::Intrinsics& intrinsics, const Eigen::Isometry3d& X_WC,
                         const Eigen::VectorXd* q_rad, const Eigen::Isometry3d& X_WV,
                         const render::Mesh* holograms, cv::Mat* image, cv::Mat* body_id) {
  if (q_rad && q_rad->size() != robot_.num_joints())
    throw std::invalid_argument("compositor: q has " + std::to_string(q_rad->size()) +
                                " entries, the robot " + std::to_string(robot_.num_joints()));
  if (!renderer_ || !SameIntrinsics(renderer_->intrinsics(), intrinsics))
    renderer_ = std::make_unique<render::Renderer>(intrinsics);
  mesh_.Clear();
  if (q_rad) {
    virtual_robot_.PoseRobot(handle_, *q_rad, X_WV);
    render::Tessellate(virtual_robot_, render::kVirtualOnly, tessellation_, &mesh_);
  }
  if (holograms) {
    const int offset = static_cast<int>(mesh_.p_W.size());
    mesh_.p_W.insert(mesh_.p_W.end(), holograms->p_W.begin(), holograms->p_W.end());
    for (render::Mesh::Triangle t : holograms->triangles) {
      for (int& v : t.v) v += offset;
      mesh_.triangles.push_back(t);
    }
  }
  renderer_->RenderOverlay(mesh_, X_WC, style_, image, body_id);
}

void Compositor::ComposeReflective(const CapturedFrame& frame, double D_m, const Eigen::Isometry3d& X_WV,
                                   ReflectiveView* view, cv::Mat* body_id, const render::Mesh* holograms) {
  const geometry::Intrinsics& K = frame.intrinsics;
  if (frame.bgr.empty() || frame.bgr.type() != CV_8UC3 || frame.bgr.cols != K.width_px ||
      frame.bgr.rows != K.height_px)
    throw std::invalid_argument("reflective display: the frame must be CV_8UC3 of its intrinsics' size");
  view->geometry = MakeReflectiveGeometry(K, frame.X_WC_est, D_m);
  view->X_WV = X_WV;
  view->source_utime = frame.utime;
  frame.bgr.copyTo(view->bgr);
  Overlay(K, frame.X_WC_est, &frame.q_rad, X_WV, holograms, &view->bgr, body_id);
}

void Compositor::ComposeArView(const cv::Mat& live_bgr, const geometry::Intrinsics& intrinsics,
                               const Eigen::Isometry3d& X_WC_est, const Eigen::VectorXd& q_rad,
                               const Eigen::Isometry3d& X_WV, cv::Mat* out, cv::Mat* body_id,
                               const render::Mesh* holograms) {
  if (live_bgr.empty() || live_bgr.type() != CV_8UC3 || live_bgr.cols != intrinsics.width_px ||
      live_bgr.rows != intrinsics.height_px)
    throw std::invalid_argument("AR view: the frame must be CV_8UC3 of its intrinsics' size");
  if (out != &live_bgr) live_bgr.copyTo(*out);
  Overlay(intrinsics, X_WC_est, &q_rad, X_WV, holograms, out, body_id);
}

void Compositor::ComposeHolograms(const cv::Mat& bgr, const geometry::Intrinsics& intrinsics,
                                  const Eigen::Isometry3d& X_WC_est, const render::Mesh& holograms,
                                  cv::Mat* out) {
  if (bgr.empty() || bgr.type() != CV_8UC3 || bgr.cols != intrinsics.width_px ||
      bgr.rows != intrinsics.height_px)
    throw std::invalid_argument("holograms: the frame must be CV_8UC3 of its intrinsics' size");
  if (out != &bgr) bgr.copyTo(*out);
  Overlay(intrinsics, X_WC_est, nullptr, Eigen::Isometry3d::Identity(), &holograms, out, nullptr);
}

}  // namespace orbed::hmd
