#pragma once
/// @file
/// The interactive mode's logic without a window: what each key does to the virtual robot's pose
/// X_WV and to the step sizes, and the window's picture (the AR view and a reflective display side
/// by side, a status bar, an optional help overlay). orbed-hmd --interactive shows WindowImage() with
/// cv::imshow and feeds cv::waitKey's codes to ApplyKey(); tests call both directly.
///
/// Keys (lower case; arrow keys are not portable across OpenCV backends):
///   a / d   move V along −x / +x of W        w / s   along +y / −y        r / f   along +z / −z
///   j / l   yaw −/+ about z_W               i / k   pitch +/− about y_W   u / o   roll −/+ about x_W
///           (rotations about W's axes through V's origin)
///   [ / ]   translation step ÷2 / ×2 (0.5–100 mm)     - / =   rotation step ÷2 / ×2 (0.05–10 deg)
///   0       back to the start pose       n   show the next reflective display
///   c       re-capture the shown display from the current view
///   Enter   submit the alignment trial   h   help overlay on/off      q / Esc   quit
///
/// Frames: W world (map), V virtual robot base. Units: m, deg where named.
/// Threading: pure functions of their arguments.

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

namespace orbed::hmd {

struct InteractiveState {
  double step_m{0.005};  ///< translation per key press [m]
  double step_deg{0.5};  ///< rotation per key press [deg]
  bool show_help{false};
  int shown_display{0};  ///< index of the reflective display in the right panel
};

enum class KeyAction {
  kNone,   ///< not a key of the interactive mode
  kMoved,  ///< X_WV changed
  kStep,   ///< a step size changed
  kHelp,   ///< help overlay toggled
  kReset,  ///< back to the start pose (the caller sets X_WV)
  kNextDisplay,
  kRecapture,
  kSubmit,
  kQuit,
};

/// Applies one key code (cv::waitKey's, low byte) to the state and to X_WV (in place).
/// `num_displays` bounds shown_display.
KeyAction ApplyKey(int key, int num_displays, InteractiveState* state, Eigen::Isometry3d* X_WV);

/// The help overlay's lines (also printed by --help).
std::vector<std::string> InteractiveHelpLines();

/// The window: `ar_view` (left) and `reflective` (right; an empty Mat shows "no reflective display")
/// each scaled to panel_width_px, a status bar with `status_lines` (and the step sizes), and the help
/// overlay when state.show_help. Returns CV_8UC3.
cv::Mat WindowImage(const cv::Mat& ar_view, const cv::Mat& reflective, const InteractiveState& state,
                    const std::vector<std::string>& status_lines, int panel_width_px = 800);

}  // namespace orbed::hmd
