#pragma once
/// @file
/// The set-up assistant's state machine (orbed-assistant, assistant_process.h), without a bus or a
/// clock: the shell hands it the checked messages and the time, it answers with what to publish.
/// It drives the person (Assistant, assistant.h) joint by joint, from joint 1 to the flange.
///
/// Phases: kIdle (no task) → kWait (a task, or --once) → kLook → kMove → (kLook → kMove)... → kDone.
///   kWait   until GUIDANCE shows the task's target and mode (any GUIDANCE with --once), a joint
///           vector and ROBOT_STATE are known, the arm is at rest (MOTION_IDLE) and, in the headset
///           modes, a REGISTRATION gave the hologram's pose; then the set-up starts (same step). On
///           the fixed monitor the person first turns and zooms its view (Assistant::PlanMonitorView):
///           that view replaces FIXED_VIEW's camera until the set-up ends, its time is added.
///   kLook   the person looks at joint j (the first look over the whole range, the next ones within
///           correction_window_deg) and decides where to put it; the move starts (same step).
///   kMove   IIWA_COMMAND (the measured q with joint j at the goal) every command_resend_s until the
///           joint is within arrived_deg of the goal with the arm at rest, or the sim stopped it
///           (motion state ≥ MOTION_STOPPED_AT_LIMIT, more than 2·command_resend_s into the move:
///           the joint stays where it is); then the next look (next step), or the next joint after
///           looks_per_joint looks, or kDone after the last joint. A move longer than
///           move_timeout_s fails the set-up (kDone, `failure` set).
///   kDone   the result is kept; a new task (new request id) starts over in kWait.
/// Execution time is the time model's (assistant.h), never the clock's.
///
/// Tasks (SETUP_TASK): a new request id starts a set-up; the current (or last finished) task's
/// id again changes nothing, and once finished its SETUP_RESULT is answered again, the same message.
/// With `once` tasks are ignored and the set-up starts from kWait at construction.
///
/// What the person sees (CurrentView): the eye and the SLAM error from the latest HMD_POSE pair
/// (else the config's eye, no error); the hologram at REGISTRATION's pose; in MODE_AR_REFLECTIVE the
/// reflective display captured at the config's `reflective.capture_m` (display 0 of hmd.yaml, at
/// its waypoint of viraal_walk.yaml: no message carries a display's capture pose but REFLECTIVE_VIEW,
/// an image stream this process does not read), its hologram at REGISTRATION's pose.
///
/// Time: `t_s` is any monotonic clock in seconds (the process clock: wall or sim); `utime` only
/// stamps what is published. Frames: W world, R real base, V virtual base, H head, E eye, D the
/// monitor's camera. Units: rad, m, s inside; deg where the name says so.
/// Threading: not synchronised; one thread.

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <orbed/guidance_t.hpp>
#include <orbed/iiwa_command_t.hpp>
#include <orbed/setup_result_t.hpp>
#include <orbed/setup_task_t.hpp>

#include "procs/assistant/assistant.h"
#include "sim/robot_model.h"

namespace orbed::assistant {

/// What a finished set-up reports (also the result file's content).
struct SetupResult {
  int8_t mode{0};
  uint64_t seed{0};
  double person_scale{1};
  Eigen::VectorXd q_start_rad, q_target_rad, q_reached_rad;
  std::vector<int> twisting;
  std::vector<int> ranges;
  double execution_s{0};
  bool headset_pose{false};
};
/// The result file (JSON): mode, seed, person_scale, q_start_deg, q_target_deg, q_reached_deg,
/// error_deg (|reached − target| per joint), twisting, ranges, execution_s, headset_pose.
std::string SetupResultJson(const SetupResult& result);

/// The machine's timing (the process's options of the same names).
struct MachineOptions {
  bool once{false};  ///< start at construction, ignore SETUP_TASK
  double command_resend_s{0.25};
  double move_timeout_s{30.0};
  double arrived_deg{0.05};  ///< a joint this near its goal, the arm at rest, has arrived
  double fixed_view_stale_s{2.0};
};

/// A line for the process's log.
struct MachineNote {
  bool warning{false};
  std::string text;
};

/// What one Step asks the shell to do.
struct StepOutput {
  std::optional<orbed::iiwa_command_t> command;     ///< publish on IIWA_COMMAND
  std::optional<orbed::setup_result_t> task_reply;  ///< publish on SETUP_RESULT
  bool finished{false};  ///< the set-up finished in this step (result() is set): write the file
  std::string failure;   ///< non-empty: the set-up failed (a move timed out): fail and stop
  bool stop{false};      ///< finished with `once`: stop the process
  std::vector<MachineNote> notes;
};

/// What became of a SETUP_TASK.
struct TaskAnswer {
  enum Kind { kIgnored, kRepeat, kRefused, kStarted } kind{kIgnored};
  std::optional<orbed::setup_result_t> reply;  ///< kRepeat of a finished task: publish it again
  std::string problem;                         ///< kRefused: guidance::CheckSetupTask's reason
};

class AssistantMachine {
 public:
  enum class Phase { kIdle, kWait, kLook, kMove, kDone };

  /// `model` must outlive the machine. Throws std::invalid_argument for a config out of range.
  AssistantMachine(const sim::RobotModel& model, const AssistantConfig& config,
                   const MachineOptions& options);

  // Inputs, already checked by the shell (guidance::CheckGuidance, sim::CheckIiwaStatus, ...).
  void OnGuidance(const orbed::guidance_t& msg) { guidance_ = msg; }
  void OnJoints(const Eigen::VectorXd& q_rad) { q_rad_ = q_rad; }
  void OnRobotState(const Eigen::Isometry3d& X_WR, int8_t motion_state);
  /// A valid REGISTRATION's mean: where the hologram is drawn.
  void OnRegistration(const Eigen::Isometry3d& X_WV) { X_WV_ = X_WV; }
  /// HMD_POSE (truth false) or HMD_POSE_TRUTH (true): the pair of one seq gives the eye and A.
  void OnHeadPose(bool truth, int64_t seq, const Eigen::Isometry3d& X_WH);
  /// FIXED_VIEW's camera position at t_s; true when it moved (more than 1 µm) or is the first.
  bool OnMonitorCamera(const Eigen::Vector3d& p_WD, double t_s);
  /// SETUP_TASK (unchecked: the machine checks a new one).
  TaskAnswer OnSetupTask(const orbed::setup_task_t& msg);

  /// The timer's work at t_s; `utime` stamps the messages it returns.
  StepOutput Step(double t_s, int64_t utime);

  /// What the person sees now (needs GUIDANCE and ROBOT_STATE).
  Viewing CurrentView(double t_s) const;

  Phase phase() const { return phase_; }
  int joint() const { return joint_; }  ///< the joint being worked on (0-based)
  int look() const { return look_; }    ///< its look (0-based)
  const std::optional<SetupResult>& result() const { return result_; }
  const Assistant& assistant() const { return assistant_; }

 private:
  void StartSetUp(double t_s, StepOutput* out);
  void LookAtJoint(double t_s, StepOutput* out);
  void Move(double t_s, int64_t utime, StepOutput* out);
  void Finish(int64_t utime, StepOutput* out);

  const sim::RobotModel* model_;
  MachineOptions options_;
  Assistant assistant_;

  // Latest inputs.
  std::optional<orbed::guidance_t> guidance_;
  std::optional<Eigen::VectorXd> q_rad_;
  std::optional<Eigen::Isometry3d> X_WR_;
  int8_t motion_state_{0};
  std::optional<Eigen::Isometry3d> X_WV_;
  std::optional<std::pair<int64_t, Eigen::Isometry3d>> X_WH_est_, X_WH_true_;  // (seq, pose)
  std::optional<Eigen::Isometry3d> A_;   // X_WH_true · X_WH_est⁻¹ of the latest matching pair
  std::optional<Eigen::Vector3d> p_WE_;  // the true head position of that pair
  std::optional<Eigen::Vector3d> p_WD_;  // FIXED_VIEW's camera position
  double p_WD_received_s_{0};
  std::optional<Eigen::Vector3d> p_WD_turned_;  // the monitor's camera as the person turned it

  // The run.
  Phase phase_{Phase::kIdle};
  std::optional<orbed::setup_task_t> task_;           // the task being carried out or last finished
  std::optional<orbed::setup_result_t> task_result_;  // its answer, once finished
  int joint_{0};
  int look_{0};
  Eigen::VectorXd q_goal_;
  double move_started_s_{0};
  double last_command_s_{-1e9};
  SetupResult partial_;
  std::optional<SetupResult> result_;
  bool waiting_noted_{false};
};

}  // namespace orbed::assistant
