#pragma once
/// @file
/// orbed-hmd's core, without a bus or a clock: the headset and the person wearing it. The shell
/// (hmd_process.h) checks what arrives with the contract's checks, hands it here with the time as
/// numbers (HeadsetClock), and carries out what comes back (HeadsetActions): publish, reject, save
/// the state file, re-capture a display, stop. The core owns the robot model, the walk + SLAM pose
/// stream (pose_stream.h), the session machine (hmd_session.h) and what its state file holds
/// (session_file.h), the person at the window (interactive.h) and the latest valid inputs.
///
/// Options (HmdOptions, ResolveHmdOptions): the shipped model and scene by default, the instance
/// names checked, every channel of the headset's own and of its session suffixed with --headset
/// (channels::ForHeadset), the arm's with --arm (channels::ForArm), the rates and flags checked.
/// Construction loads the shipped configs, then --config over them (hmd_config.h), --user-seed,
/// the scene standing at --arm's place (config moved with it), the robot with the scene's tool,
/// and restores the session from the state file when there is one.
///
/// The hologram's pose X_WV (map coordinates, CurrentX_WV): in interactive mode the person's;
/// otherwise the latest valid REGISTRATION.X_WV_mean (of the active session while one is active),
/// else the emulated user's last X_WV, else the configured start offset X_WR_nominal · X_RV_start
/// (user.yaml start_offset, X_WR_nominal from the scene file). A new session forgets the first two.
/// What the hologram shows (Hologram): a person planning a target (interactive, t): that target in
/// AR_VIEW and the displays. Else during a set-up (a GUIDANCE fresher than kGuidanceFreshS on the
/// process clock, no alignment session): ar: AR_VIEW at the target, the displays without a
/// hologram; ar_reflective: both at the target; fixed: neither (the guidance is on the monitor).
/// Otherwise the real arm's joints everywhere (empty q: the joints of the frame drawn on).
/// A client's holograms (HOLOGRAMS from orbed-hl2ss, holograms.h) are drawn with it in AR_VIEW and
/// the displays, whatever it shows, while the latest came within kHologramsFreshS.
///
/// Sessions (OnSessionControl): the decision of HmdSession, and then: a START saves the START and
/// forgets the registered and the user's X_WV; a RESET saves without the last trial; a STOP saves no
/// session; a repeated request id answers with its first trial again (no save); an accepted
/// REQUEST_TRIAL asks the person (interactive) or runs RunHeadsetTrial() (headset_trial.h) at once,
/// in emulated time, at the latest q against the latest X_WR from the start offset, seeded from
/// (process seed, session, index); a trial that fails is refused "trial_failed". A trial without
/// tracking faults is then ready (trial_ready()): the shell has PublishReadyTrial() stamp it with
/// the process clock after the run (on the wall clock the run takes time). The trial (index
/// taken from the session, stamped clock_utime, request id the REQUEST_TRIAL's, user_id
/// "emulated-seed-<user seed>", the tracking faults met, the annotation rays) is saved before it
/// goes out. A trial that met tracking faults is pending: its faults are scheduled on the pose
/// stream from the walk's time of the request, and StepPose returns the trial with the first poses
/// after the last fault has played; meanwhile a repeat of its request is not acted on and another
/// REQUEST_TRIAL is refused "busy"; START, RESET and STOP drop it. The walk's time at clock_s is
/// clock_s − (clock_s of the first StepPose) + walk_offset_s(), where each published emulated trial
/// adds its alignment time not already played live (the person walked on while aligning).
///
/// The person (HandleKey, interactive.h's keys): re-capture and quit are asked of the shell; Enter
/// submits the alignment (with no session active first a local START "interactive-<wall s>", mode
/// ar_reflective with displays else ar, Karcher, published before the trial), its duration the
/// interactive timer's; , and . turn the selected joint of the measured q within the model's
/// limits as an IIWA_COMMAND (stamped wall_utime); t plans a target (from the fresh GUIDANCE's
/// target, else the measured q), , and . turn the target's joint, Enter sends it as SETUP_TASK
/// "interactive-<n>" (the fresh guidance's mode, else ar; request_id = the stamp). Each sets the
/// event line shown in the window; what cannot be done yet says why there.
///
/// Times: clock_s / clock_utime the process clock (wall or sim, --sim-time), monotonic_s the
/// steady wall clock (the person's trial timer), wall_utime the wall clock (a person's commands).
/// Frames: W world (= the SLAM map for estimates), R real robot base, V virtual robot base, C a
/// camera. Units: m, rad, s; utime µs.
/// Threading: not synchronised; one thread (the Process::Run() thread). Logs with base/log.h.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/guidance_t.hpp>
#include <orbed/hologram_scene_t.hpp>
#include <orbed/iiwa_command_t.hpp>
#include <orbed/registration_t.hpp>
#include <orbed/session_control_t.hpp>
#include <orbed/setup_task_t.hpp>

#include "hmd_emulator/headset_trial.h"
#include "hmd_emulator/hmd_config.h"
#include "hmd_emulator/hmd_session.h"
#include "hmd_emulator/image_pipeline.h"
#include "hmd_emulator/interactive.h"
#include "hmd_emulator/pose_stream.h"
#include "hmd_emulator/robot_state.h"
#include "hmd_emulator/session_file.h"
#include "lcmtypes/contract/channels.h"
#include "sim/robot_model.h"

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
  bool threaded{true};  ///< images on a worker thread (hmd_process.h)
  /// The session's state file (session_file.h): restored at start, saved on every change; "" = none.
  std::string state_file;
  /// One of several headsets (channels::IsInstanceName): every channel of the headset's
  /// own (HMD_POSE, HMD_POSE_TRUTH, HMD_CAMERA, GAZE_RAY, REFLECTIVE_VIEW, AR_VIEW,
  /// ALIGNMENT_TRIAL) and of its session (SESSION_CONTROL, REGISTRATION) gets the suffix _NAME
  /// (channels::ForHeadset); "" = the single headset, plain names.
  std::string headset;
  /// The arm it looks at, one of the scene's `arms:` (sim::Scene::StandAt): the walk and the start
  /// offset around that arm's base, the arm's channels (IIWA_STATUS, ROBOT_STATE, IIWA_COMMAND,
  /// GUIDANCE, SETUP_TASK) with its suffix (channels::ForArm); "" = the single arm.
  std::string arm;
  /// Another headset (its --headset NAME) whose camera is this one's first reflective display
  /// (viraal_trial.h's CollaboratorDisplay, the anchor's error from hmd.collaborator): where it
  /// truly is comes from its HMD_POSE_TRUTH_<NAME>; the live display 0 shows what its camera sees,
  /// and the emulated trials align with it. "" = none.
  std::string collaborator;
  std::string iiwa_status_channel{channels::kIiwaStatus};
  std::string robot_state_channel{channels::kRobotState};
  std::string session_control_channel{channels::kSessionControl};
  std::string registration_channel{channels::kRegistration};
  /// The set-up guidance (orbed-guidance): while a GUIDANCE is fresh, the hologram shows its target
  /// configuration (modes ar, ar_reflective), or nothing (fixed: the guidance is on a monitor).
  std::string guidance_channel{channels::kGuidance};
  std::string hmd_pose_channel{channels::kHmdPose};
  std::string hmd_pose_truth_channel{channels::kHmdPoseTruth};
  std::string camera_channel{channels::kHmdCamera};
  std::string gaze_channel{channels::kGazeRay};
  std::string reflective_channel{channels::kReflectiveView};
  std::string ar_view_channel{channels::kArView};
  std::string trial_channel{channels::kAlignmentTrial};
  /// Interactive: the person turns a joint of the real arm (keys 1-7 and , .) through the sim.
  std::string iiwa_command_channel{channels::kIiwaCommand};
  std::string setup_task_channel{channels::kSetupTask};  ///< interactive: the planned target
  /// The holograms an hl2ss client placed (orbed-hl2ss), drawn in AR_VIEW and the displays.
  std::string holograms_channel{channels::kHolograms};
};

/// Fills the default model and scene, checks the instance names, suffixes the channels and checks
/// the rates and flags (std::invalid_argument naming the flag). See the file comment.
HmdOptions ResolveHmdOptions(HmdOptions options);

/// The times an entry point may need (see the file comment).
struct HeadsetClock {
  double clock_s{0};            ///< the process clock [s]
  std::int64_t clock_utime{0};  ///< the process clock as a stamp [µs]
  double monotonic_s{0};        ///< the steady wall clock [s, any origin]
  std::int64_t wall_utime{0};   ///< the wall clock [µs since the epoch]
};

/// What the hologram shows (Hologram(); empty q: the real arm's joints, or the frame's).
struct HologramShown {
  bool hidden{false};
  Eigen::VectorXd q_rad;
  bool reflective_hidden{false};
  Eigen::VectorXd reflective_q_rad;
};
/// A GUIDANCE this young [s, process clock] is fresh.
inline constexpr double kGuidanceFreshS = 1.0;
/// A HOLOGRAMS this young [s, process clock] is drawn (its publisher re-sends it every second).
inline constexpr double kHologramsFreshS = 3.0;

/// What the shell does after an entry point, in this order.
struct HeadsetActions {
  std::optional<Refusal> refusal;                 ///< reject "<the input's channel>/<key>"
  std::optional<orbed::session_control_t> start;  ///< publish on SESSION_CONTROL (a local START)
  bool save{false};                               ///< write saved() to the state file
  std::optional<orbed::alignment_trial_t> trial;  ///< publish on ALIGNMENT_TRIAL
  std::optional<orbed::iiwa_command_t> command;   ///< publish on IIWA_COMMAND
  std::optional<orbed::setup_task_t> task;        ///< publish on SETUP_TASK
  std::optional<int> recapture;                   ///< re-capture this reflective display
  bool stop{false};                               ///< the person quit
};

class Headset {
 public:
  /// `options` resolved (ResolveHmdOptions). Loads the configs, scene and robot (std::runtime_error
  /// naming the file and key), checks --displays (std::invalid_argument), restores the state file.
  /// `process_seed`: --seed (the trials' and the live anchor error's); `monotonic_s` starts the
  /// person's trial timer.
  Headset(const HmdOptions& options, std::uint64_t process_seed, double monotonic_s);
  Headset(const Headset&) = delete;
  Headset& operator=(const Headset&) = delete;

  // Inputs the shell has checked (sim::CheckIiwaStatus, CheckPose, CheckWorldPose, CheckGuidance).
  void OnJoints(const Eigen::VectorXd& q_rad);
  void OnRobotBase(const Eigen::Isometry3d& X_WR);
  void OnCollaboratorCamera(const Eigen::Isometry3d& X_WC_true, std::int64_t utime);
  void OnGuidance(const orbed::guidance_t& msg, double clock_s);
  /// A HOLOGRAMS checked by CheckHologramScene, at clock_s: tessellated when it holds another scene
  /// than the last (utime aside).
  void OnHolograms(const orbed::hologram_scene_t& msg, double clock_s);
  /// The client's holograms to draw at clock_s: the latest HOLOGRAMS's if it came within
  /// kHologramsFreshS, else null.
  std::shared_ptr<const render::Mesh> Holograms(double clock_s) const;
  /// A REGISTRATION worth checking: valid, and of the active session while one is active.
  bool WantsRegistration(const orbed::registration_t& msg) const;
  void OnRegistration(const Eigen::Isometry3d& X_WV_mean) { X_WV_registration_ = X_WV_mean; }
  /// An ALIGNMENT_TRIAL worth checking: of the active session.
  bool WantsTrial(const orbed::alignment_trial_t& msg) const;
  /// A checked trial of the active session from elsewhere (HmdSession::ObserveTrial): save.
  HeadsetActions OnTrial(const orbed::alignment_trial_t& msg);
  /// SESSION_CONTROL, unchecked (HmdSession checks it). See the file comment.
  HeadsetActions OnSessionControl(const orbed::session_control_t& msg, const HeadsetClock& now);
  /// The emulated trial an accepted REQUEST_TRIAL just ran (trial_ready()), stamped clock_utime
  /// when done: saved, then published.
  bool trial_ready() const { return ready_trial_.has_value(); }
  HeadsetActions PublishReadyTrial(std::int64_t clock_utime);
  /// One key of the person (interactive.h), as if typed.
  HeadsetActions HandleKey(int key, const HeadsetClock& now);

  /// The pose timer: steps the walk to now.clock_s; the poses to publish, then a pending trial.
  struct PoseStep {
    PoseStream::Poses poses;
    HeadsetActions actions;
  };
  PoseStep StepPose(const HeadsetClock& now);
  /// The gaze ray of the latest sample, if any.
  std::optional<orbed::gaze_ray_t> Gaze() { return stream_->Gaze(robot_); }

  /// The image pipeline's inputs now: the latest sample, robot, X_WV, hologram and collaborator.
  FrameInputs Inputs(double clock_s) const;
  HologramShown Hologram(double clock_s) const;
  Eigen::Isometry3d CurrentX_WV() const;
  /// The image pipeline's options from the config and the options (threaded as options.threaded).
  ImagePipelineOptions PipelineOptions() const;
  /// The interactive window around the latest `ar_view` and the shown display's `reflective`.
  cv::Mat Window(const cv::Mat& ar_view, const cv::Mat& reflective, double clock_s) const;

  /// One line for the log: model, scene, walk, person, displays, rates.
  std::string Summary() const;
  const HmdOptions& options() const { return options_; }
  const HmdConfigSet& config() const { return config_; }
  const sim::RobotModel& robot_model() const { return *robot_model_; }
  const PoseStream& stream() const { return *stream_; }
  const HmdSession& session() const { return session_; }
  /// What the state file is to hold.
  const SavedSession& saved() const { return saved_; }
  InteractiveSession& interactive() { return *interactive_; }
  const RobotState& robot() const { return robot_; }
  /// The live walk's time at the last StepPose [s], and how far the emulated trials moved it on [s].
  double walk_t_s() const { return stream_->t_s(); }
  double walk_offset_s() const { return walk_offset_s_; }

 private:
  void LoadConfigs();
  sim::Scene LoadSceneAndRobot();
  void RestoreSession();
  void EmulateTrial(HeadsetActions* out);
  // `played_s`: walk time the trial already spent live (its tracking faults played on HMD_POSE).
  void PublishEmulatedTrial(const TrialOutcome& outcome, std::int64_t clock_utime, double played_s,
                            HeadsetActions* out);
  void PublishTrial(const Eigen::Isometry3d& X_WV, double duration_s, const std::string& user_id,
                    std::int64_t clock_utime, const TrackingFaultRecord& faults,
                    const std::vector<AnnotationRay>& annotation, HeadsetActions* out);
  void SubmitInteractiveTrial(const HeadsetClock& now, HeadsetActions* out);
  void TurnArmJoint(int joint, double delta_rad, std::int64_t wall_utime, HeadsetActions* out);
  void EditTarget(std::optional<std::pair<int, double>> turn, double clock_s);
  void SendPlannedTarget(const HeadsetClock& now, HeadsetActions* out);
  /// The latest valid GUIDANCE if it came within kGuidanceFreshS, else null.
  const orbed::guidance_t* FreshGuidance(double clock_s) const;

  HmdOptions options_;
  std::uint64_t process_seed_;
  HmdConfigSet config_;
  std::unique_ptr<sim::RobotModel> robot_model_;
  std::unique_ptr<PoseStream> stream_;
  HmdSession session_;
  SavedSession saved_;
  SessionMapCache session_map_;                    // the session's map after its last trial
  std::optional<InteractiveSession> interactive_;  // always set; the person only with --interactive
  std::optional<orbed::guidance_t> guidance_;      // the latest valid GUIDANCE
  double guidance_received_s_{0};                  // when it came [process clock s]
  std::vector<std::uint8_t> holograms_bytes_;      // the latest HOLOGRAMS encoded with utime 0
  std::shared_ptr<const render::Mesh> holograms_;  // and tessellated
  double holograms_received_s_{0};                 // when it came [process clock s]
  bool started_{false};
  double t0_s_{0};           // the walk's t = 0: the first StepPose [process clock s]
  double walk_offset_s_{0};  // emulated seconds of the trials published [s]
  RobotState robot_;
  // The collaborator's camera, truly, and the shared anchor's error of the live display (AnchorError).
  std::optional<Eigen::Isometry3d> collaborator_X_WC_true_;
  std::int64_t collaborator_utime_{0};
  Eigen::Isometry3d live_anchor_error_{Eigen::Isometry3d::Identity()};
  std::optional<Eigen::Isometry3d> X_WV_registration_, X_WV_user_;
  Eigen::Isometry3d X_WV_start_{Eigen::Isometry3d::Identity()};
  std::string user_id_;
  std::optional<TrialOutcome> ready_trial_;    // run, without tracking faults: to publish now
  std::optional<TrialOutcome> pending_trial_;  // waiting for its tracking faults to play
  double pending_trial_walk_t_s_{0};           // the live walk's time when it was requested
  Eigen::VectorXd planned_target_q_;           // the person's planned target (t)
  int planned_targets_sent_{0};
};

}  // namespace orbed::hmd
