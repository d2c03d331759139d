#pragma once
/// @file
/// The reflective-AR display (paper Sec. II-B) and the AR view: the virtual robot at X_WV drawn as
/// a hologram over a camera frame, with a client's holograms (holograms.h) in the same overlay.
///
/// What is in the picture (the physical mechanism the alignment study relies on):
///   * The captured frame shows the REAL robot (at X_WR) as the camera truly saw it, from X_WC_true.
///   * The device only knows its SLAM estimate X_WC_est of that capture pose (image_t carries it).
///     The hologram is drawn with what the device knows: the virtual robot at X_WV, joint vector q of
///     capture time, projected with the observer geometry P_o = K_o [R_CW | p_CW] of X_WC_est.
///   * So with X_WV = X_WR the overlay still misses the real robot by the SLAM error at capture
///     time (X_WC_true vs X_WC_est); an emulated user aligning in this image inherits that error.
///   The content is drawn with P_o, never with P_m, and is independent of D, as the paper states
///   (D "does not affect the rendering content in the reflective-AR display"): no pixel changes
///   with D.
///
/// The reversed frustum (where and how the image is shown in the AR scene):
///   X_CM = [R_x(π) | (0, 0, D)]   (M: C turned π about x, moved D along the principal ray, so M
///                                   sits at the gaze hit on the robot and looks back toward C)
///   X_WM = X_WC · X_CM = X_WC · [R_x(π) | (0, 0, D)],  K_m = diag(1, −1, 1) · K_o,
///   P_m = K_m [R_MW | p_MW] = K_m · P · X_MW,  X_MW = X_CM⁻¹ · X_CW = X_CM · X_CW
/// (X_CM is its own inverse: R_x(π)² = I and R_x(π)·(0, 0, D) = (0, 0, −D)). This is the
/// geometrically meaningful order: the turn and the shift act in the camera frame C, after the
/// world-to-camera transform. The paper's equation for P_m writes the product in the other order,
/// K_m · P · [R | p] · [R_x(π) | (0, 0, D)], which read literally would turn about the world's x axis
/// and shift along the world's z before the extrinsics; its text ("the optical center of the
/// observer frustum is rotated by π around the x axis, and translated by D along the principal ray")
/// describes the order used here. P_m places the display (X_WM, the panel below); it is not what
/// draws the content: the virtual robot is projected with P_o (the overlay must register with the
/// captured image, which P_o formed), and the composed image is the same for every D.
/// An eye at M looking into a planar mirror at z_C = D/2 (facing M) sees exactly the rays the camera
/// captured: the mirror reflects M onto C. The display is that mirror: pixel (u, v) is shown at
///   p_M = s · ((u − cx)/fx, −(v − cy)/fy, 1),   s = D/2 by default (DisplayPanelPoint),
/// which lies on the capture ray of (u, v) seen from C, and which P_m maps to (u, v − 2 cy): K_m's
/// y-flip only negates the row axis (the y-up convention of graphics engines), so the composed image
/// is stored un-flipped, row 0 at the top, like the captured frame. D and s place and scale the
/// panel; they never change its pixels.
///
/// Frames: W world, C camera (z forward, x right, y down), M reversed frustum, V virtual robot base.
/// Units: m, rad, px; utime in µs.
/// Threading: a Compositor owns a Renderer and scratch geometry; use one per thread.

#include <cstdint>
#include <memory>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "geometry/camera_model.h"
#include "render/renderer.h"
#include "render/scene_geometry.h"
#include "sim/robot_model.h"

namespace orbed::hmd {

/// A camera frame as the device holds it.
struct CapturedFrame {
  cv::Mat bgr;                      ///< CV_8UC3, rendered from the TRUE capture pose
  geometry::Intrinsics intrinsics;  ///< K_o of the frame
  Eigen::Isometry3d X_WC_est{Eigen::Isometry3d::Identity()};  ///< SLAM estimate at capture
  Eigen::VectorXd q_rad;  ///< robot joint vector at capture (IIWA_STATUS) [rad]
  std::int64_t utime{0};  ///< capture time [µs]
};

/// Imaging geometry of one reflective display (what reflective_view_t carries).
struct ReflectiveGeometry {
  Eigen::Matrix3d K_o{Eigen::Matrix3d::Identity()};            ///< observer (capture) intrinsics [px]
  Eigen::Matrix3d K_m{Eigen::Matrix3d::Identity()};            ///< diag(1, −1, 1) · K_o [px]
  Eigen::Isometry3d X_WC{Eigen::Isometry3d::Identity()};       ///< capture pose used (the estimate)
  Eigen::Isometry3d X_WM{Eigen::Isometry3d::Identity()};       ///< reversed frustum, X_WC · X_CM(D)
  double distance_m{0};                                        ///< D [m]
  geometry::CameraMatrix P_o{geometry::CameraMatrix::Zero()};  ///< K_o [R_CW | p_CW]: draws the content
  /// K_m [R_MW | p_MW] = K_m · P · X_CM · X_CW: the reversed frustum of the paper's Sec. II-B, in
  /// the geometric order (the file comment; the paper's printed product order differs). Places the
  /// display; the content is drawn with P_o.
  geometry::CameraMatrix P_m{geometry::CameraMatrix::Zero()};
};

/// The geometry for a frame captured at X_WC with gaze distance D. Throws std::invalid_argument
/// unless D is finite and > 0.
ReflectiveGeometry MakeReflectiveGeometry(const geometry::Intrinsics& intrinsics,
                                          const Eigen::Isometry3d& X_WC, double D_m);

/// Where the display shows pixel (u, v), in W: p_M = s ((u − cx)/fx, −(v − cy)/fy, 1) with
/// s = `depth_in_M_m` (default, when <= 0: D/2, the mirror plane).
Eigen::Vector3d DisplayPanelPoint(const ReflectiveGeometry& geometry, double u_px, double v_px,
                                  double depth_in_M_m = 0);

struct ReflectiveView {
  cv::Mat bgr;  ///< the composed image, CV_8UC3, the frame's size, row 0 at the top
  ReflectiveGeometry geometry;
  Eigen::Isometry3d X_WV{Eigen::Isometry3d::Identity()};  ///< virtual robot base used
  std::int64_t source_utime{0};                           ///< the frame's capture time [µs]
};

/// Draws the virtual robot over camera frames. Holds a reference to `robot` (must outlive it).
class Compositor {
 public:
  explicit Compositor(const sim::RobotModel& robot, const render::OverlayStyle& style = {},
                      const render::TessellationOptions& tessellation = {});

  /// Reflective display: `frame` + the virtual robot at (frame.q_rad, X_WV) drawn with P_o of
  /// frame.X_WC_est, and the geometry for D. `body_id` (optional, CV_32S) receives the overlay's
  /// body indices into virtual_geometry().bodies(), -1 elsewhere. `holograms` (optional): a client's
  /// holograms (holograms.h, triangles in W) drawn in the same overlay, z-buffered with the robot.
  /// Throws std::invalid_argument on an empty or mis-sized frame, a wrong q size or a bad D.
  void ComposeReflective(const CapturedFrame& frame, double D_m, const Eigen::Isometry3d& X_WV,
                         ReflectiveView* view, cv::Mat* body_id = nullptr,
                         const render::Mesh* holograms = nullptr);

  /// AR view: the virtual robot at (q, X_WV) over a live frame, drawn from the current estimate
  /// X_WC_est, with `holograms` as above. `out` may alias `live_bgr`'s buffer only if it is the
  /// same Mat object.
  void ComposeArView(const cv::Mat& live_bgr, const geometry::Intrinsics& intrinsics,
                     const Eigen::Isometry3d& X_WC_est, const Eigen::VectorXd& q_rad,
                     const Eigen::Isometry3d& X_WV, cv::Mat* out, cv::Mat* body_id = nullptr,
                     const render::Mesh* holograms = nullptr);

  /// A client's holograms alone (no virtual robot) over a frame taken at X_WC_est, in the hologram
  /// style; `out` as for ComposeArView. Throws std::invalid_argument on a mis-sized frame.
  void ComposeHolograms(const cv::Mat& bgr, const geometry::Intrinsics& intrinsics,
                        const Eigen::Isometry3d& X_WC_est, const render::Mesh& holograms, cv::Mat* out);

  /// The virtual robot's bodies (names "virtual/<link>"), posed at the last call.
  const render::SceneGeometry& virtual_geometry() const { return virtual_robot_; }

 private:
  // The virtual robot at (*q_rad, X_WV) when q_rad is given, and the holograms when given, in one
  // overlay.
  void Overlay(const geometry::Intrinsics& intrinsics, const Eigen::Isometry3d& X_WC,
               const Eigen::VectorXd* q_rad, const Eigen::Isometry3d& X_WV, const render::Mesh* holograms,
               cv::Mat* image, cv::Mat* body_id);

  const sim::RobotModel& robot_;
  render::OverlayStyle style_;
  render::TessellationOptions tessellation_;
  render::SceneGeometry virtual_robot_;
  int handle_{0};
  render::Mesh mesh_;
  std::unique_ptr<render::Renderer> renderer_;  // rebuilt when the intrinsics change
};

}  // namespace orbed::hmd
