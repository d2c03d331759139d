#pragma once
/// @file
/// The fixed external monitor of the set-up study's `fixed` mode (paper Sec. IV-B): a picture of the
/// target configuration, the robot drawn at its real base in the operating room, from a camera the
/// user can turn about the robot and move nearer or farther. No hologram, no overlay: a monitor.
/// The core, without a bus or a clock.
///
/// The camera D orbits a centre c = p_WR + (0, 0, kOrbitCentreHeight_m) above the real base (about
/// the middle of an upright iiwa): p_WD = c + d (cos el cos az, cos el sin az, sin el), looking at c
/// (geometry::LookAt: z toward c, x horizontal to the right, y down). The default view is where the
/// emulated assistant's model puts the monitor's camera (procs/assistant/assistant.yaml,
/// monitor.camera_m; a test checks the two agree): the view starts there and the keys move it.
///
/// Frames: W world, R real base, D the monitor's camera. Units: m, rad; deg where the name says so.
/// Threading: values; a FixedViewRenderer owns a renderer's scratch buffers: one thread.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "geometry/camera_model.h"
#include "render/renderer.h"
#include "render/scene_geometry.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::fixed_display {

/// Height of the orbit's centre above the robot's base [m]: about half an upright iiwa 7 (1.27 m
/// to the flange, KUKA data sheet), so the arm fills the picture in any configuration.
inline constexpr double kOrbitCentreHeight_m = 0.5;
/// The default camera [m, W]: the assistant's monitor.camera_m (from the foot end, above the table).
inline const Eigen::Vector3d kDefaultCamera_m{1.5, 0.3, 1.8};

/// Where the monitor's camera is, about the orbit's centre.
struct OrbitView {
  double azimuth_rad{0};    ///< about W's z, from W's x toward y
  double elevation_rad{0};  ///< above the horizontal, within ±kMaxElevation
  double distance_m{2};     ///< from the centre, within [kMinDistance_m, kMaxDistance_m]

  static constexpr double kMaxElevation_rad = 1.4;  ///< 80 deg: LookAt needs a defined roll
  static constexpr double kMinDistance_m = 0.8;
  static constexpr double kMaxDistance_m = 6.0;

  /// The view whose camera is at p_WD, looking at p_Wc. Throws std::invalid_argument when p_WD is
  /// within kMinDistance_m of the centre, beyond kMaxDistance_m, or steeper than kMaxElevation.
  static OrbitView Through(const Eigen::Vector3d& p_WD, const Eigen::Vector3d& p_Wc);
  /// The camera's pose for the orbit's centre p_Wc.
  Eigen::Isometry3d X_WD(const Eigen::Vector3d& p_Wc) const;
};

/// The orbit's centre for the real base X_WR.
Eigen::Vector3d OrbitCentre(const Eigen::Isometry3d& X_WR);

/// What a key does to the view (the window's keys, also in --help): a/d turn the camera 15 deg
/// about the robot (left/right), w/s raise/lower it 10 deg, +/- (or =/_) move it 15 % nearer/farther,
/// r back to `home`. Limits are clamped. Returns the new view, or none for a key that does nothing.
std::optional<OrbitView> ApplyKey(int key, const OrbitView& view, const OrbitView& home);
/// The keys, one line, for --help and the window's caption.
inline constexpr char kKeyHelp[] = "a/d turn, w/s up/down, +/- zoom, r reset";

struct PictureOptions {
  int width_px{640};
  int height_px{480};
  double horizontal_fov_deg{60.0};  ///< a monitor's rendering camera, not a person's eye
  int jpeg_quality{85};
};

/// The monitor's pinhole camera: square pixels, principal point at the centre.
geometry::Intrinsics MonitorIntrinsics(const PictureOptions& options);

/// Renders the target configuration q_target [rad] of the robot at its real base X_WR, in the
/// scene (when given), seen from X_WD; the picture is BGR (CV_8UC3), with a one-line caption.
/// `body_id` (CV_32S, render::Mesh body index of the robot's links and the scene's objects, -1
/// elsewhere) when not null.
class FixedViewRenderer {
 public:
  FixedViewRenderer(const sim::RobotModel& model, const sim::Scene* scene, const PictureOptions& options);
  cv::Mat Render(const Eigen::VectorXd& q_target_rad, const Eigen::Isometry3d& X_WR,
                 const Eigen::Isometry3d& X_WD, const std::string& caption, cv::Mat* body_id = nullptr);
  const geometry::Intrinsics& intrinsics() const { return renderer_.intrinsics(); }
  /// The robot's bodies (render::Body::robot == 0) in the geometry; for tests.
  const render::SceneGeometry& geometry() const { return geometry_; }

 private:
  render::SceneGeometry geometry_;
  int robot_{-1};
  render::Renderer renderer_;
  render::Mesh mesh_;
};

}  // namespace orbed::fixed_display
