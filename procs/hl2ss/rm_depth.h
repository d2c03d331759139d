#pragma once
/// @file
/// The research-mode depth camera of an emulated HoloLens 2 in its long-throw mode, as an hl2ss
/// client receives it: 320×288 depth [mm] and active brightness (AB) at 5 Hz, rendered from the
/// room's z-buffer; the PNG payload; the mode-1 pose; the mode-2 calibration. Pure library: the
/// server (another file) frames packets and owns sockets and clocks.
///
/// Protocol facts (hl2ss's Python client viewer/hl2ss.py and hl2ss_3dcv.py, 2025 form; its
/// server's long-throw encoder and research-mode calibration code):
///   payload  = PNG | sensor ticks (u64). The PNG is a 320×288 8-bit BGRA picture whose bytes, as
///              OpenCV decodes them (IMREAD_UNCHANGED), are the 288×320 depth u16 followed by the
///              288×320 AB u16 (the client views the picture as u16 rows, 2·288 of them, and
///              splits them in half). The device zeroes the depth of every pixel its sigma buffer
///              marks invalid: 0 is the invalid value, and so it is here.
///   depth    the distance along the pixel's ray [mm] (radial, not z): the client divides it by
///              ‖(x, y, 1)‖·scale to get z [m] and multiplies (x, y, 1) by z (hl2ss_3dcv's
///              rm_depth_compute_rays / rm_depth_normalize / rm_depth_to_points; Microsoft's
///              research-mode samples likewise scale the unit ray by depth/1000).
///   mode 2   float32: uv2x (P), uv2y (P), extrinsics (16), scale (1: 1000), mapx (P), mapy (P),
///            K (4), P = 320·288. uv2xy[v][u] is the unit-plane (x, y) of the pixel's centre; the
///            extrinsics map the rig node N to the camera in the row-vector convention
///            ([p_Z 1] = [p_N 1]·E); the undistort map and K are built as the server builds them
///            from the sensor's own mapping functions, whose image points have integer
///            coordinates at pixel corners (so a pinhole's map is u + ½, v + ½).
///   mode 1   the pose after each payload is the rig node's in the device frame D (frames.h),
///            the client's `reference_to_world`: world = [p_Z 1]·E⁻¹·pose.
///
/// The emulated sensor (documented choices, stated as such):
///   - a pinhole without distortion, square pixels, horizontal field of view 75° (the Azure Kinect
///     depth camera's narrow mode, whose 2×2-binned form is also 320×288: the same time-of-flight
///     family as the HoloLens 2's), principal point at the image centre;
///   - range: radial distance in [0.5, 5.8] m, the Azure Kinect SDK's operating range of that
///     mode (Microsoft publishes none for the long throw); outside it, and where nothing is hit,
///     the depth and AB are 0;
///   - the rig node N is the head frame H with the device's axes (x right, y up, z backward:
///     X_HN = diag(1, −1, −1)); the depth camera Z (computer-vision axes) sits 3 cm above and
///     1 cm ahead of the eyes, pitched 10° down (X_HZ below);
///   - AB = min(65535, 10 000 / r²) with r the radial distance [m]: the illumination's fall-off
///     only (no albedo, no incidence angle), 0 where the depth is invalid.
/// Depth is rendered from the TRUE head pose; the mode-1 pose is the headset's estimate.
///
/// Frames: W world, D device (frames.h), H head (x right, y down, z forward), N rig node, Z the
/// depth camera (x right, y down, z forward). Units: m, except depth [mm] and the ray table.
/// Threading: a LongThrowCamera owns a renderer: one thread at a time. Free functions are pure.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "geometry/camera_model.h"
#include "render/renderer.h"

namespace orbed::hl2ss {

inline constexpr int kLongThrowWidth = 320;
inline constexpr int kLongThrowHeight = 288;
inline constexpr int kLongThrowHz = 5;
inline constexpr float kLongThrowScale = 1000.0f;  ///< depth units per metre (mode 2's scale)

/// The emulated sensor's pinhole (see the file comment).
geometry::Intrinsics LongThrowIntrinsics();

/// The sensor's own mapping functions, in its API's pixel convention (integer image coordinates at
/// pixel corners, so pixel (u, v)'s centre is (u + ½, v + ½)), for a camera with intrinsics K
/// (pixel centres at integers): an image point to the unit plane z = 1 of Z, and back. The mode-2
/// uv2xy table and undistort map, and RC's map-camera-points answers, all come from these two.
Eigen::Vector2d LongThrowImagePointToUnitPlane(const geometry::Intrinsics& K,
                                               const Eigen::Vector2d& uv_corner);
Eigen::Vector2d LongThrowUnitPlaneToImagePoint(const geometry::Intrinsics& K, const Eigen::Vector2d& xy);

struct LongThrowOptions {
  geometry::Intrinsics intrinsics{LongThrowIntrinsics()};
  Eigen::Isometry3d X_HZ{DefaultX_HZ()};  ///< the depth camera on the head
  Eigen::Isometry3d X_HN{DefaultX_HN()};  ///< the rig node on the head
  double min_range_m{0.5};                ///< radial [m]
  double max_range_m{5.8};                ///< radial [m]
  double ab_at_1m{10000.0};               ///< AB of a surface 1 m away

  static Eigen::Isometry3d DefaultX_HZ();
  static Eigen::Isometry3d DefaultX_HN();
};

/// One long-throw frame: depth [mm] (CV_16UC1, 0 = invalid) and AB (CV_16UC1), 288 rows × 320.
struct LongThrowFrame {
  cv::Mat depth_mm;
  cv::Mat ab;
};

class LongThrowCamera {
 public:
  /// Throws std::invalid_argument when the intrinsics are not 320×288 or the range is empty.
  explicit LongThrowCamera(const LongThrowOptions& options = {});

  /// Renders `mesh` (render::RoomMesh's: the room as the headset's camera sees it) from the
  /// depth camera of a head truly at X_WH.
  void Render(const render::Mesh& mesh, const Eigen::Isometry3d& X_WH, LongThrowFrame* frame);

  /// The depth camera of a head at X_WH: X_WZ = X_WH · X_HZ.
  Eigen::Isometry3d X_WZ(const Eigen::Isometry3d& X_WH) const { return X_WH * options_.X_HZ; }
  const LongThrowOptions& options() const { return options_; }

 private:
  LongThrowOptions options_;
  render::Renderer renderer_;
  cv::Mat ray_norm_;  // ‖(x, y, 1)‖ per pixel, CV_64F
  cv::Mat bgr_, z_m_;
};

/// The mode-0/1 payload: the PNG of the frame, then `sensor_ticks` (u64). Replaces *payload.
/// False and *error when the frame is not two 288×320 u16 pictures or PNG coding fails.
bool EncodeLongThrowPayload(const LongThrowFrame& frame, std::uint64_t sensor_ticks,
                            std::vector<std::uint8_t>* payload, std::string* error);

/// The mode-2 calibration bytes (float32, the layout above).
std::vector<std::uint8_t> PackLongThrowCalibration(const LongThrowOptions& options);

/// The rig node's pose the device reports for a head at X_WH (the estimate): X_DN.
Eigen::Isometry3d RigNodePoseForClient(const Eigen::Isometry3d& X_WH, const LongThrowOptions& options);

}  // namespace orbed::hl2ss
