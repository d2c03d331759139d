#pragma once
/// @file
/// orbed-scenario: the conductor of the paper's ViRAAl experiment (Sec. III-B, Table 1) over the bus.
///
///   Subscribes: ROBOT_STATE (robot_state_t: true X_WR, q, motion state), PLAN_CHECK_REPLY,
///               ALIGNMENT_TRIAL (alignment_trial_t, from orbed-hmd's emulated user),
///               REGISTRATION (registration_t), MISALIGNMENT (misalignment_t).
///   Publishes:  PLAN_CHECK_REQUEST (each configuration once, before anything moves),
///               SESSION_CONTROL (START / REQUEST_TRIAL / COMPUTE / STOP), IIWA_COMMAND (the trial
///               configurations; re-sent every command_resend_s while the arm moves),
///               MISALIGNMENT_REQUEST (the landmark pairs of each trial and of each mean),
///               PROCESS_STATUS at 1 Hz (Process).
///
/// The run, for each mode (ar_reflective with its mirrors, ar with 0; order from the scenario file):
///   START(session "<run_id>-<mode>", method) → for trial i = 0..N−1: IIWA_COMMAND q_i, wait until
///   ROBOT_STATE has every |q − q_i| < tolerance_deg and motion IDLE → REQUEST_TRIAL → the
///   ALIGNMENT_TRIAL (session, index i) → the REGISTRATION (reason TRIAL, that trial's utime,
///   num_trials i+1) and the MISALIGNMENT of the trial's landmark pairs → after N trials COMPUTE →
///   the REGISTRATION (reason COMPUTE) = the session mean → MISALIGNMENT of the mean → STOP.
/// Then it writes results.json (viraal_results.h) to results_dir, prints the table and stops with
/// exit code 0. Any timeout, infeasible configuration or refused request stops it with exit code 1
/// and a one-line reason naming the process that did not answer (results.json is still written,
/// status "failed", with what was finished).
///
/// Errors against the truth (viraal_errors.h): X_WR from the latest ROBOT_STATE (the sim's truth);
/// translation_error_mm at the robot centroid, rotation_error_deg the geodesic angle of
/// R_WR^T R_WV, misalignment_mm = MISALIGNMENT.mean_error_norm_m (the paper's ‖t̄‖₂) of the three
/// landmark pairs real = X_WR·X_RL(q)·0, virtual = X_WV·X_RL(q)·0, q = the trial's joint_position.
///
/// The conductor is a state machine: message handlers record what arrived and a timer (tick_s)
/// advances phases and enforces timeouts; nothing blocks the Run() thread.
///
/// Validation: every received message is checked (sizes, finite values, unit quaternions, enum
/// ranges); a bad one is refused and counted on PROCESS_STATUS (key "<channel>/<class>"), and the
/// last refusal is quoted if the phase then times out. Messages that belong to someone else (other
/// request ids, other sessions, periodic REGISTRATION) are ignored, not counted.
///
/// Clocks: timeouts on the monotonic clock; utimes of published messages from the wall clock.
/// Threading: everything on the Process::Run() thread.

#include <chrono>
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/misalignment_t.hpp>
#include <orbed/plan_check_reply_t.hpp>
#include <orbed/registration_t.hpp>
#include <orbed/robot_state_t.hpp>

#include "procs/common/channels.h"
#include "procs/common/process.h"
#include "viraal/protocol.h"
#include "viraal/metrics.h"
#include "viraal/results.h"
#include "sim/robot_model.h"

namespace orbed::scenario {

struct ScenarioOptions {
  ScenarioConfig config;
  /// Session ids are "<run_id>-<mode>"; "" = "viraal-<UTC start time>".
  std::string run_id;
  /// Folder of results.json; "" = $ORBED_LOG_DIR if set, else the working directory.
  std::string results_dir;
  /// Robot model for the landmark and centroid FK; "" = sim/models/iiwa7.urdf under
  /// $ORBED_SOURCE_DIR, else under the source tree this library was built from.
  std::string urdf_path;
  /// How close every joint must be to the configuration [deg] (with motion IDLE).
  double tolerance_deg{0.1};
  /// Waiting for the first ROBOT_STATE [s] (orbed-iiwa-sim).
  double startup_timeout_s{10.0};
  /// Waiting for a PLAN_CHECK_REPLY, a REGISTRATION or a MISALIGNMENT [s].
  double reply_timeout_s{5.0};
  /// Waiting for the arm to reach a configuration [s].
  double move_timeout_s{30.0};
  /// Waiting for the user's ALIGNMENT_TRIAL after REQUEST_TRIAL [s] (orbed-hmd).
  double trial_timeout_s{60.0};
  /// An arm that reports a stop (limit / collision) this long while short of the target fails [s].
  double stopped_grace_s{0.5};
  double command_resend_s{0.25};
  double tick_s{0.01};
  /// Progress lines and the final table go here (nullptr = nowhere).
  std::ostream* out{nullptr};
  std::string robot_state_channel{channels::kRobotState};
  std::string iiwa_command_channel{channels::kIiwaCommand};
  std::string plan_check_request_channel{channels::kPlanCheckRequest};
  std::string plan_check_reply_channel{channels::kPlanCheckReply};
  std::string session_control_channel{channels::kSessionControl};
  std::string trial_channel{channels::kAlignmentTrial};
  std::string registration_channel{channels::kRegistration};
  std::string misalignment_request_channel{channels::kMisalignmentRequest};
  std::string misalignment_channel{channels::kMisalignment};
};

/// `relative` under $ORBED_SOURCE_DIR if set, else under the source tree this library was built from.
std::string ScenarioSourcePath(const std::string& relative);

class ViraalScenario {
 public:
  /// Loads the robot model, checks the configuration against its limits and the landmarks against
  /// its links (std::invalid_argument / std::runtime_error with the reason), then opens LCM
  /// (std::runtime_error naming the URL).
  ViraalScenario(const orbed::CommonFlags& flags, const ScenarioOptions& options);
  ~ViraalScenario();

  /// Runs the experiment; returns 0 when it completed, 1 on a failure (reason on stderr, on the
  /// heartbeat and in results.json).
  int Run();
  orbed::Process& process() { return *process_; }
  const RunResults& results() const { return results_; }
  /// Path of the results.json written at the end ("" before).
  const std::string& results_path() const { return results_path_; }

  /// The timer's callback (public so that tests can drive it).
  void Tick();

 private:
  enum class Phase {
    kWaitRobot,
    kCheckPlans,
    kMove,
    kAwaitTrial,
    kAwaitTrialResults,
    kAwaitMean,
    kAwaitMeanMisalignment,
    kDone,
  };
  using Clock = std::chrono::steady_clock;

  // Handlers: validate, record, advance.
  void OnRobotState(const orbed::robot_state_t& msg, const std::string& channel);
  void OnPlanCheckReply(const orbed::plan_check_reply_t& msg, const std::string& channel);
  void OnTrial(const orbed::alignment_trial_t& msg, const std::string& channel);
  void OnRegistration(const orbed::registration_t& msg, const std::string& channel);
  void OnMisalignment(const orbed::misalignment_t& msg, const std::string& channel);

  // Phase entries: each publishes what starts the phase.
  void Enter(Phase phase);
  void StartPlanChecks();
  void StartSession();
  /// Publishes the trial's IIWA_COMMAND; `first` enters kMove (else a resend).
  void StartMove(bool first);
  void RequestTrial();
  void RequestMean();
  int64_t SendMisalignment(const AlignmentError& error);
  void FinishTrial();
  void FinishSession();
  void FinishRun();
  /// Ends the run with exit code 1: writes results.json (status failed) and says why.
  void FailRun(const std::string& reason);
  double PhaseSeconds() const;
  void Refuse(const std::string& key, const std::string& reason);
  void Say(const std::string& line);
  std::string StepLabel() const;
  void SendSessionControl(int8_t command);

  ScenarioOptions options_;
  std::unique_ptr<orbed::sim::RobotModel> model_;
  std::unique_ptr<RobotPointSet> points_;
  std::unique_ptr<orbed::Process> process_;

  Phase phase_{Phase::kWaitRobot};
  Clock::time_point phase_start_;
  Clock::time_point run_start_;
  Clock::time_point last_command_;
  std::optional<Clock::time_point> stopped_since_;
  std::string last_refusal_;

  // Latest truth from the sim.
  std::optional<orbed::robot_state_t> robot_state_;
  Clock::time_point robot_state_received_;

  // Plan checks: one request id per configuration.
  int64_t plan_request_base_{0};
  std::vector<bool> plan_answered_;

  // Where the run is.
  size_t mode_index_{0};
  int trial_index_{0};
  std::optional<orbed::alignment_trial_t> trial_;
  std::optional<orbed::registration_t> last_trial_registration_;
  double reach_s_{0};
  int64_t misalignment_request_id_{0};
  std::optional<orbed::misalignment_t> misalignment_;
  std::optional<orbed::registration_t> mean_registration_;
  AlignmentError pending_error_;
  std::vector<RobotPoints> session_points_;
  int64_t next_request_id_{1};

  RunResults results_;
  std::string results_path_;
};

}  // namespace orbed::scenario
