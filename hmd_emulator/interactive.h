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
/// The person as the set-up assistant (paper Fig. 4 c-e), with the guidance in the status bar:
///   1 … 7   select a joint of the real arm   , / .   turn it −/+ by the rotation step (the shell
///           sends IIWA_COMMAND, so the sim's speeds, limits and collision stops hold)
///   t       plan the target instead (the paper's interactive planning): , and . turn the
///           selected joint of the hologram's target configuration, Enter sends it as a SETUP_TASK
///           (orbed-guidance shows it); t again: back to the arm
///
/// InteractiveSession holds the rest of the person's side without a window, a bus or a clock: the
/// hologram pose they set, the requested-trial flag and its timer (times come in as arguments),
/// the last event line, the scripted keys, and the window's status lines. orbed-hmd's shell acts on
/// what HandleKey() asks (re-capture, quit, submit) and shows Window().
///
/// Frames: W world (map), V virtual robot base. Units: m, deg where named, s.
/// Threading: pure functions of their arguments; an InteractiveSession is not synchronised (one
/// thread, the Process::Run() thread).

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "hmd_emulator/hmd_session.h"

namespace orbed::hmd {

struct InteractiveState {
  double step_m{0.005};  ///< translation per key press [m]
  double step_deg{0.5};  ///< rotation per key press [deg]
  bool show_help{false};
  int shown_display{0};     ///< index of the reflective display in the right panel
  int selected_joint{0};    ///< 0-based joint that , and . turn
  bool edit_target{false};  ///< , and . turn the target's joint (t), not the real arm's
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
  kSelectJoint,   ///< selected_joint changed
  kJointMinus,    ///< turn the selected joint by −step_deg
  kJointPlus,     ///< … by +step_deg
  kToggleTarget,  ///< edit_target toggled
};

/// Applies one key code (cv::waitKey's, low byte) to the state and to X_WV (in place).
/// `num_displays` bounds shown_display, `num_joints` the joint keys (a digit beyond it: kNone).
KeyAction ApplyKey(int key, int num_displays, InteractiveState* state, Eigen::Isometry3d* X_WV,
                   int num_joints = 7);

/// The help overlay's lines (also printed by --help).
std::vector<std::string> InteractiveHelpLines();

/// The window: `ar_view` (left) and `reflective` (right; an empty Mat shows "no reflective display")
/// each scaled to panel_width_px, a status bar with `status_lines` (and the step sizes), and the help
/// overlay when state.show_help. Returns CV_8UC3.
cv::Mat WindowImage(const cv::Mat& ar_view, const cv::Mat& reflective, const InteractiveState& state,
                    const std::vector<std::string>& status_lines, int panel_width_px = 800);

/// The guidance as one status line: "guidance (ar): next joint 3 | error [deg] +0.0 -12.5 … | done"
/// (joints 1-based; `next_joint` 0-based, −1 when done).
std::string GuidanceLine(const std::string& mode, const std::vector<double>& error_deg, int next_joint,
                         bool done);

/// Decodes the two-character escapes "\n" (Enter, 13) and "\e" (Esc, 27) of --scripted-keys; every
/// other byte is its own key code.
std::vector<int> ScriptedKeys(const std::string& text);

class InteractiveSession {
 public:
  /// What a key asks of the shell beyond this object.
  enum class Request {
    kNone,
    kRecapture,  ///< re-capture shown_display() from the current view
    kQuit,
    kSubmit,      ///< submit an ALIGNMENT_TRIAL at X_WV() (then Submitted() or CannotSubmit())
    kMoveJoint,   ///< turn joint selected_joint() of the real arm by joint_step_rad()
    kEditTarget,  ///< planning began (editing_target()) or ended
    kMoveTarget,  ///< turn joint selected_joint() of the planned target by joint_step_rad()
    kSendTarget,  ///< Enter while planning: send the planned target
  };

  /// The hologram starts at X_WV_start; `scripted_keys` as --scripted-keys; the trial timer starts
  /// at now_s [s, any monotonic origin].
  InteractiveSession(int num_displays, const Eigen::Isometry3d& X_WV_start, const std::string& scripted_keys,
                     double now_s, int num_joints = 7);

  /// Applies one key (ApplyKey(); 0 puts the hologram back at the start pose).
  Request HandleKey(int key);
  /// The next scripted key, one per call, or -1 once all were typed.
  int NextScriptedKey();

  /// Restarts the trial timer (e.g. when the window opens).
  void RestartTimer(double now_s) { trial_started_s_ = now_s; }
  /// A REQUEST_TRIAL for trial `index` of `session_id` arrived: asks the person, restarts the
  /// timer. Returns the event line.
  const std::string& TrialRequested(const std::string& session_id, int32_t index, double now_s);
  /// The trial was submitted now: returns its duration since the request, the previous submission
  /// or the timer's start [s]; clears the request and restarts the timer.
  double Submitted(const std::string& session_id, int32_t index, double now_s);
  /// Sets the event line (shown in the window).
  void SetEvent(std::string event) { last_event_ = std::move(event); }

  const Eigen::Isometry3d& X_WV() const { return X_WV_; }
  const Eigen::Isometry3d& X_WV_start() const { return X_WV_start_; }
  int shown_display() const { return ui_.shown_display; }
  int selected_joint() const { return ui_.selected_joint; }
  bool editing_target() const { return ui_.edit_target; }
  /// The turn kMoveJoint asks for [rad]: ±step_deg.
  double joint_step_rad() const { return joint_step_rad_; }
  bool trial_requested() const { return trial_requested_; }
  const std::string& last_event() const { return last_event_; }

  /// The window (WindowImage()) with the status lines: the session, the offset of the hologram
  /// drawn (X_WV_shown) from the start pose, whether the robot is live, the tracking state
  /// (`tracking`, "-" when none), the guidance (`guidance`: one line, GuidanceLine()) with the
  /// selected joint, and the last event.
  cv::Mat Window(const cv::Mat& ar_view, const cv::Mat& reflective, const HmdSessionState& session,
                 const Eigen::Isometry3d& X_WV_shown, bool robot_known, const std::string& tracking,
                 const std::string& guidance = "") const;

 private:
  int num_displays_;
  Eigen::Isometry3d X_WV_start_;
  Eigen::Isometry3d X_WV_;
  InteractiveState ui_;
  std::vector<int> scripted_;
  std::size_t scripted_next_{0};
  bool trial_requested_{false};
  double trial_started_s_{0};
  std::string last_event_;
  int num_joints_{7};
  double joint_step_rad_{0};
};

}  // namespace orbed::hmd
