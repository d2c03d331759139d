#pragma once
/// @file
/// The orbed-hmd process (DESIGN.md §4 "orbed-hmd"): the headset and the person wearing it, wired to
/// the bus. The engines (hmd_render_lib, hmd_user_lib) know nothing of LCM; this class feeds them
/// what arrives and publishes what they produce.
///
///   Subscribes: IIWA_STATUS (iiwa_status_t): q of the real robot [rad] (drawn, and the trial's q);
///               ROBOT_STATE (robot_state_t): X_WR, the true robot base (drawn, and the trial's truth);
///               SESSION_CONTROL (session_control_t): START / RESET / STOP / REQUEST_TRIAL;
///               REGISTRATION (registration_t): X_WV_mean, where the hologram is drawn when valid.
///   Publishes:  HMD_POSE and HMD_POSE_TRUTH (hmd_pose_t) at pose_hz: one SLAM sample as the device
///               estimates it (X_WH_est, X_WC_est, tracking state) and the truth, same seq and utime;
///               HMD_CAMERA (image_t, JPEG) at camera_hz: the scene and the real robot (latest q,
///               X_WR) rendered from the TRUE camera pose of the latest sample, stamped with the
///               ESTIMATED pose and that sample's utime (capture time = sample time), K_o;
///               GAZE_RAY (gaze_ray_t) at hmd.gaze_hz: from the estimated head along its line of
///               sight (toward the walk's look-at target), the hit found by ray casting the true
///               ray against the scene and the real robot (distance and body), reported in map
///               coordinates (origin_est + t · direction_est);
///               REFLECTIVE_VIEW (reflective_view_t) at hmd.reflective_hz per display (--displays):
///               the display's captured frame composited with the virtual robot at the current X_WV,
///               K_m = diag(1, −1, 1) · K_o, X_WM = X_WC_est · [R_x(π) | (0, 0, D)], D = distance from
///               the capture camera centre to the gaze hit on the robot (the real robot's surface
///               along the capture-time line of sight; hmd.gaze_fallback_distance_m when the gaze
///               misses the robot or no robot pose is known);
///               AR_VIEW (image_t, JPEG) at hmd.ar_view_hz: the hologram at X_WV over the latest
///               camera frame, drawn with that frame's estimated pose;
///               ALIGNMENT_TRIAL (alignment_trial_t): one per accepted REQUEST_TRIAL (emulated user)
///               or Enter (interactive); SESSION_CONTROL START once, for a local session, when a
///               person submits in interactive mode with no session active; PROCESS_STATUS at 1 Hz.
///
/// The current X_WV (map coordinates): in interactive mode the person's; otherwise the latest valid
/// REGISTRATION.X_WV_mean (of the active session while one is active), else the emulated user's
/// last X_WV, else the configured start offset X_WR_nominal · X_RV_start (user.yaml start_offset,
/// X_WR_nominal from the scene file).
///
/// Sessions (the contract with orbed-scenario): START opens session s with display_mode MODE_AR
/// (num_mirrors must be 0) or MODE_AR_REFLECTIVE (1 <= num_mirrors <= the displays placed in
/// hmd.yaml), trial index 0; a repeated START of the active session is a no-op; RESET sets the
/// index to 0; STOP closes it. REQUEST_TRIAL for the active session: the emulated user performs one
/// ViRAAl alignment at once, in emulated time (viraal_trial.h: its own walk along the configured
/// path with its own SLAM model seeded from (--seed, session, index), displays capturing at their
/// waypoints, alignment at hmd.align_waypoint) at the latest IIWA_STATUS q against the latest
/// ROBOT_STATE X_WR, starting from the start offset; then ALIGNMENT_TRIAL {session, index (per
/// session from 0), mode, num_mirrors, q, X_WV, duration_s = the emulated alignment time,
/// user_id "emulated-seed-<user seed>"}. In interactive mode REQUEST_TRIAL only tells the person.
///
/// Rejections (Process::Reject, key "<channel>/<class>"; the process keeps running):
///   IIWA_STATUS/num_joints, /non_finite, /limits (beyond a joint limit by > 0.01 rad);
///   ROBOT_STATE/pose (X_WR not finite or not a unit quaternion);
///   REGISTRATION/pose (a valid mean with a bad X_WV_mean);
///   SESSION_CONTROL/command, /session_id (empty), /display_mode, /num_mirrors, /unknown_session
///   (RESET/REQUEST_TRIAL for a session that is not the active one), /no_robot_state (REQUEST_TRIAL
///   before any valid IIWA_STATUS and ROBOT_STATE: the trial needs q and X_WR), /trial_failed;
///   and <channel>/decode for undecodable bytes (Process).
///
/// Threading: handlers and timers run on the Process::Run() thread. With options.threaded (the
/// default) the images (render, composite, JPEG) are made on one worker thread that the timers hand
/// the latest state to (latest wins: a request that finds the previous one still pending replaces
/// it and counts as a skipped frame), so that a frame never delays a 60 Hz pose; the worker
/// publishes HMD_CAMERA, REFLECTIVE_VIEW and AR_VIEW itself (LCM's publish is thread-safe). Without
/// it everything runs inline on the Run() thread (deterministic, for tests). A frame whose inputs
/// (true camera pose, q, X_WR) equal the previous frame's reuses its JPEG bytes (a standing wearer
/// and a resting arm give the same picture), restamped; REFLECTIVE_VIEW re-composites only when its
/// frame or X_WV changed.
///
/// Clocks: message utimes are the wall clock (NowMicros) at sampling; the walk's time t [s] runs on
/// the monotonic clock from the first pose tick.
/// Frames: W world (= the SLAM map for estimates), H head, C camera, M reversed frustum, R real
/// robot base, V virtual robot base. Units: m, rad, px, Hz; utime µs.

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/iiwa_status_t.hpp>
#include <orbed/registration_t.hpp>
#include <orbed/robot_state_t.hpp>
#include <orbed/session_control_t.hpp>

#include "hmd_emulator/hmd_config.h"
#include "hmd_emulator/interactive.h"
#include "procs/common/channels.h"
#include "procs/common/process.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::hmd {

struct HmdOptions {
  /// URDF and scene; "" = the files shipped in the source tree (HmdSourcePath()).
  std::string urdf_path;
  std::string scene_path;
  /// YAML files applied after the shipped config/{slam,user,viraal_walk,hmd}.yaml (hmd_config.h).
  std::vector<std::string> config_paths;
  /// A different person: overrides user.seed when set.
  std::optional<std::uint64_t> user_seed;
  double camera_hz{30.0};
  double pose_hz{60.0};
  int jpeg_quality{85};         ///< 1..100
  int displays{1};              ///< live reflective displays, 0..hmd.displays.size()
  bool interactive{false};      ///< a person in an OpenCV window instead of the emulated user
  std::string screenshot_path;  ///< interactive: the window's last image is written here at exit
  /// Interactive: key codes fed as if typed, one per window refresh, before real keys (tests, demos).
  std::string scripted_keys;
  bool threaded{true};  ///< images on a worker thread (see the file comment)
  std::string iiwa_status_channel{channels::kIiwaStatus};
  std::string robot_state_channel{channels::kRobotState};
  std::string session_control_channel{channels::kSessionControl};
  std::string registration_channel{channels::kRegistration};
  std::string hmd_pose_channel{channels::kHmdPose};
  std::string hmd_pose_truth_channel{channels::kHmdPoseTruth};
  std::string camera_channel{channels::kHmdCamera};
  std::string gaze_channel{channels::kGazeRay};
  std::string reflective_channel{channels::kReflectiveView};
  std::string ar_view_channel{channels::kArView};
  std::string trial_channel{channels::kAlignmentTrial};
};

class HmdProcess {
 public:
  /// Loads the URDF, scene and configs (std::runtime_error naming the file and key), validates the
  /// options (std::invalid_argument naming the flag), opens LCM (std::runtime_error naming the URL),
  /// starts the worker thread (threaded) and, when interactive, the window (std::runtime_error
  /// without a display).
  HmdProcess(const orbed::CommonFlags& flags, const HmdOptions& options);
  ~HmdProcess();
  HmdProcess(const HmdProcess&) = delete;
  HmdProcess& operator=(const HmdProcess&) = delete;

  /// Runs until stopped; in interactive mode also until q/Esc. Writes the screenshot at the end.
  int Run();
  orbed::Process& process() { return *process_; }
  const HmdOptions& options() const { return options_; }
  const HmdConfigSet& config() const { return config_; }

  // The timers' callbacks, public so tests can drive them without waiting (Run() thread only).
  /// Steps the head and SLAM model to t and publishes HMD_POSE + HMD_POSE_TRUTH.
  void PublishPose();
  void PublishGaze();
  /// Requests (threaded) or makes and publishes (inline) a camera frame / the reflective views /
  /// the AR view from the latest state.
  void RequestCamera();
  void RequestReflective();
  void RequestArView();
  /// Interactive mode: handles one key as if typed (ApplyKey plus submit, reset, recapture, quit).
  void HandleKey(int key);
  /// The window's current picture (interactive mode's content; works without a window).
  cv::Mat CurrentWindowImage();
  /// Waits until the worker has finished every pending request (no-op inline).
  void Flush();

  /// The current X_WV (see the file comment) and the active session ("" when none).
  Eigen::Isometry3d CurrentX_WV() const;
  const std::string& active_session() const { return session_.id; }
  int64_t skipped_frames() const;

 private:
  class ImagePipeline;
  struct Session {
    std::string id;
    int8_t display_mode{0};
    int32_t num_mirrors{0};
    int8_t method{0};
    int32_t next_index{0};
  };
  struct FrameInputs;

  void OnIiwaStatus(const orbed::iiwa_status_t& msg, const std::string& channel);
  void OnRobotState(const orbed::robot_state_t& msg, const std::string& channel);
  void OnSessionControl(const orbed::session_control_t& msg, const std::string& channel);
  void OnRegistration(const orbed::registration_t& msg, const std::string& channel);
  void EmulateTrial(const std::string& channel);
  void PublishTrial(const Eigen::Isometry3d& X_WV, double duration_s, const std::string& user_id);
  void InteractiveTick();
  FrameInputs Inputs() const;

  HmdOptions options_;
  HmdConfigSet config_;
  sim::Scene scene_;
  std::unique_ptr<sim::RobotModel> robot_;
  std::unique_ptr<orbed::Process> process_;
  std::unique_ptr<ImagePipeline> pipeline_;
  struct Live;
  std::unique_ptr<Live> live_;  // head trajectory, SLAM model, latest sample, ray-cast geometry

  // Latest valid inputs (Run() thread).
  bool have_q_{false}, have_X_WR_{false};
  Eigen::VectorXd q_rad_;
  Eigen::Isometry3d X_WR_{Eigen::Isometry3d::Identity()};
  Session session_;
  std::optional<Eigen::Isometry3d> X_WV_registration_, X_WV_user_;
  Eigen::Isometry3d X_WV_start_{Eigen::Isometry3d::Identity()};
  Eigen::Isometry3d X_WV_manual_{Eigen::Isometry3d::Identity()};  // interactive
  std::unique_ptr<EmulatedUser> user_;
  std::string user_id_;

  // Interactive mode.
  InteractiveState ui_;
  bool trial_requested_{false};
  std::chrono::steady_clock::time_point trial_started_{std::chrono::steady_clock::now()};
  std::string last_event_;
  std::size_t scripted_next_{0};
  cv::Mat last_window_;
  bool window_open_{false};
};

}  // namespace orbed::hmd
