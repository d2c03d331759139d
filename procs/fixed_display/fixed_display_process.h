#pragma once
/// @file
/// orbed-fixed-display: the fixed external monitor of the set-up study's `fixed` mode, as its own
/// image channel (fixed_display.h says what it shows and how the view moves).
///
///   Subscribes (sim/testbed_poses.h): ROBOT_STATE (X_WR: where the robot stands), GUIDANCE (the
///               target configuration and the mode; checked, refusals counted "GUIDANCE/field").
///   Publishes:  FIXED_VIEW, image_t JPEG, every 1/rate_hz while a GUIDANCE came within
///               stale_after_s and its mode is MODE_FIXED_DISPLAY (any mode with all_modes); X_WC is
///               the monitor camera's pose X_WD (truth: it is a rendering camera), utime = pose_utime
///               = the publishing time. A picture is rendered only when the target, the base or the
///               view changed; otherwise the last one is sent again with the new time.
///   Window:     with `window`, the picture in an OpenCV window whose keys turn and zoom the view
///               (kKeyHelp); the emulated assistant reads the camera's position from FIXED_VIEW.
///   PNG:        with `png_path`, every new picture is also written there (replaced atomically).
///
/// Threading: everything on the Process::Run thread.

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <orbed/image_t.hpp>

#include "lcmtypes/contract/channels.h"
#include "procs/fixed_display/fixed_display.h"
#include "runtime/process.h"
#include "sim/robot_model.h"
#include "sim/scene.h"
#include "sim/testbed_poses.h"

namespace orbed::fixed_display {

struct FixedDisplayOptions {
  std::string urdf_path;   ///< "" = the shipped model
  std::string scene_path;  ///< "" = the shipped scene; "none" = the robot alone
  double rate_hz{5.0};
  double stale_after_s{1.0};  ///< a GUIDANCE older than this shows nothing
  Eigen::Vector3d camera_m{kDefaultCamera_m};
  PictureOptions picture;
  bool all_modes{false};
  bool window{false};
  std::string png_path;
  std::string robot_state_channel{channels::kRobotState};
  std::string guidance_channel{channels::kGuidance};
  std::string fixed_view_channel{channels::kFixedView};
};

class FixedDisplay {
 public:
  /// Throws std::runtime_error for an unreadable model or scene, std::invalid_argument for a camera
  /// the orbit cannot hold (OrbitView::Through) at the scene's base.
  FixedDisplay(const CommonFlags& flags, const FixedDisplayOptions& options);
  int Run() { return process_.Run(); }
  Process& process() { return process_; }

  /// What the timer publishes at `utime` [us, the process clock: wall, or the sim's with --sim-time]: none
  /// without a fresh target and a base.
  std::optional<orbed::image_t> PictureNow(int64_t utime);
  /// The current view and the home view (the configured camera); a key applied as in the window.
  const OrbitView& view() const { return view_; }
  void PressKey(int key);
  /// Pictures rendered so far (a picture sent again does not count).
  int renders() const { return renders_; }

 private:
  void Tick();

  Process process_;
  FixedDisplayOptions options_;
  sim::RobotModel model_;
  std::optional<sim::Scene> scene_;
  sim::TestbedPoses poses_;
  FixedViewRenderer renderer_;
  OrbitView home_, view_;
  int8_t mode_{-1};  // of the latest valid GUIDANCE (its target: poses_.q_virtual())
  int64_t guidance_received_utime_{0};
  // The last picture and what it showed.
  std::optional<orbed::image_t> last_;
  Eigen::VectorXd last_q_;
  Eigen::Isometry3d last_X_WR_{Eigen::Isometry3d::Identity()};
  OrbitView last_view_;
  int renders_{0};
  bool window_open_{false};
};

/// orbed-fixed-display's command line (flags: --help). Exit 0; 2 or CLI11's usage code (106-109) on
/// bad arguments; 1 when it cannot start.
int RunFixedDisplay(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::fixed_display
