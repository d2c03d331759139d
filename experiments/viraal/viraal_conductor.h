#pragma once
/// @file
/// The conductor of the paper's ViRAAl experiment (Sec. III-B, Table 1) as a phase machine without
/// a bus or a clock. ViraalScenario (scenario_process.h) feeds it the decoded messages and the time
/// and publishes what it asks for; tests drive it directly, in emulated time.
///
/// The run, for each mode (ar_reflective with its mirrors, ar with 0; order from the scenario file):
///   wait for ROBOT_STATE → PLAN_CHECK_REQUEST for every configuration, wait for every
///   PLAN_CHECK_REPLY → START(session "<run_id>-<mode>", method) → for trial i = 0..N−1:
///   IIWA_COMMAND q_i (configuration i mod K), wait until ROBOT_STATE has every |q − q_i| <
///   tolerance_deg and motion IDLE → REQUEST_TRIAL → the ALIGNMENT_TRIAL (session, index i) →
///   if the user annotated the landmarks (the trial's gaze rays), a LANDMARK_REQUEST per landmark
///   and side, and once every LANDMARK is in, the MISALIGNMENT_REQUEST of the triangulated pairs
///   (else at once, of the truth's pairs); wait for the REGISTRATION (reason TRIAL, that
///   trial's utime, num_trials i+1) and the MISALIGNMENT answer → after N trials COMPUTE → the
///   REGISTRATION (reason COMPUTE) = the session mean → MISALIGNMENT_REQUEST of the mean's pairs →
///   the answer → STOP. After the last mode the status is kSucceeded. A timeout, an infeasible
///   configuration or a refused request makes it kFailed with a one-line reason naming the process
///   that did not answer; results() then holds what was finished.
///
/// Resuming (ConductorOptions::kept_sessions, from an earlier run's results.json checked by
/// resume.h): the kept sessions that have their mean are not run again; the session in progress
/// starts with START, then its kept trials re-sent on ALIGNMENT_TRIAL (the registration server
/// averages them, the headset moves its next index past them), then its next trial; the trials it
/// re-sent, coming back, are ignored.
///
/// Errors (experiments/viraal/metrics.h, scored by experiments/viraal/exchange.h): X_WR from the latest
/// ROBOT_STATE (the sim's truth); translation_error_mm at the robot centroid, rotation_error_deg the geodesic
/// angle of R_WR^T R_WV; misalignment_mm = MISALIGNMENT.mean_error_norm_m (the paper's ‖t̄‖₂) of the user's
/// annotated landmark pairs (the paper's measurement, in the headset's map), or for a trial without
/// annotation of the truth's pairs real = X_WR·X_RL(q)·0, virtual = X_WV·X_RL(q)·0, q = the trial's
/// joint_position [rad]; truth_misalignment_mm always from the truth's pairs. A session mean
/// X_WV_mean is measured over the session's trial configurations: against the real landmarks the
/// user annotated in the session's trials, its virtual ones placed by the mean (landmarks
/// "gaze_real"; kept trials carry theirs in results.json), or with the truth's pairs when a trial
/// has no annotation.
///
/// Inputs: each On*() takes a decoded message and the time it arrived; Tick() only the time. Every
/// message is checked (sizes, finite values, unit quaternions, enum ranges); a bad one is refused
/// (a Refusal action, key "<channel>/<class>"), and the last refusal is quoted if the phase then
/// times out. Messages that belong to someone else (other request ids, other sessions, periodic
/// REGISTRATION) are ignored, not refused. Handlers advance the phases at once where they can;
/// Tick() enforces the timeouts and the retries below, and re-sends IIWA_COMMAND every
/// command_resend_s while the arm is short of the target.
///
/// Requests and retries (datagrams may be lost, duplicated or reordered): every request carries a
/// request id, distinct within the run (the Start() utime + 1, + 2, ...): PLAN_CHECK_REQUEST,
/// SESSION_CONTROL (START, REQUEST_TRIAL, COMPUTE, STOP), LANDMARK_REQUEST and MISALIGNMENT_REQUEST.
/// An answer counts only when it echoes the id of the request the phase waits for: PLAN_CHECK_REPLY,
/// LANDMARK and MISALIGNMENT their request's, ALIGNMENT_TRIAL its REQUEST_TRIAL's, REGISTRATION the COMPUTE's
/// (reason COMPUTE) or the trial's (reason TRIAL, with the trial's utime and num_trials i + 1). An answer
/// with an id this run used before (a repeat, a late duplicate) is ignored, not refused. While a
/// phase waits, what is unanswered is re-sent, byte for byte, retry_initial_s after the phase began,
/// then after intervals doubling up to retry_max_s, until the phase's timeout: the plan checks not
/// yet answered; the REQUEST_TRIAL, preceded by the session's START (a receiver that missed the
/// START opens the session; one that has it ignores the repeated id), until the trial is both
/// received and registered (the headset answers a repeated REQUEST_TRIAL with the same trial, the
/// server a repeat of that trial with the same REGISTRATION); the LANDMARK_REQUESTs not yet
/// answered, then the MISALIGNMENT_REQUEST; the COMPUTE. STOP is not retried: the next START replaces the
/// session in every receiver.
///
/// Outputs: every call returns the actions it produced, in order: messages to publish (with their
/// channel), progress lines for the operator, log entries and refusals. The caller carries them out
/// in that order. Nothing else leaves the machine.
///
/// Time: ConductorTime::t_s is monotonic [s] and times the phases, timeouts, retries, resends and
/// the stopped grace; ConductorTime::utime [µs since the epoch] stamps the messages out and, at
/// Start(), the request ids. Neither is read from a clock here: identical calls give identical
/// actions.
///
/// Threading: not thread-safe; one thread makes every call.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <orbed/alignment_trial_t.hpp>
#include <orbed/iiwa_command_t.hpp>
#include <orbed/landmark_request_t.hpp>
#include <orbed/landmark_t.hpp>
#include <orbed/misalignment_request_t.hpp>
#include <orbed/misalignment_t.hpp>
#include <orbed/plan_check_reply_t.hpp>
#include <orbed/plan_check_request_t.hpp>
#include <orbed/registration_t.hpp>
#include <orbed/robot_state_t.hpp>
#include <orbed/session_control_t.hpp>

#include "base/log.h"
#include "experiments/viraal/metrics.h"
#include "experiments/viraal/protocol.h"
#include "experiments/viraal/results.h"
#include "lcmtypes/contract/channels.h"
#include "sim/robot_model.h"

namespace orbed::scenario {

/// The time of an input, as two clocks read together by the caller.
struct ConductorTime {
  /// Monotonic time [s], any origin (steady_clock on the bus, a fake clock in tests).
  double t_s{0};
  /// Wall-clock time [µs since the Unix epoch], for the utimes of messages out.
  int64_t utime{0};
};

struct ConductorOptions {
  viraal::ScenarioConfig config;
  /// Session ids are "<run_id>-<mode>"; must not be empty.
  std::string run_id;
  /// Recorded in the results (the process's --seed).
  uint64_t seed{0};
  /// How close every joint must be to the configuration [deg] (with motion IDLE).
  double tolerance_deg{0.1};
  /// Waiting for the first ROBOT_STATE [s] (orbed-iiwa-sim).
  double startup_timeout_s{10.0};
  /// The deadline of every request [s]: how long a phase waits for the PLAN_CHECK_REPLYs, the
  /// user's ALIGNMENT_TRIAL after REQUEST_TRIAL (orbed-hmd), a REGISTRATION, the LANDMARKs or a
  /// MISALIGNMENT (orbed-registration), re-sending what is unanswered meanwhile (the retries
  /// below). One number for all, stated by the launch file (--request-deadline-s): a host
  /// partitioned for less than it costs the run nothing but the wait.
  double request_deadline_s{60.0};
  /// Waiting for the arm to reach a configuration [s].
  double move_timeout_s{30.0};
  /// An arm that reports a stop (limit / collision) this long while short of the target fails [s].
  double stopped_grace_s{0.5};
  /// Period of the IIWA_COMMAND re-sends while the arm moves [s].
  double command_resend_s{0.25};
  /// An unanswered request is first re-sent this long after it went out [s]; each later retry waits
  /// twice as long as the one before, at most retry_max_s (>= retry_initial_s).
  double retry_initial_s{0.2};
  double retry_max_s{0.5};
  /// Sessions kept from an earlier run (resume.h): the finished ones first, then at most one in
  /// progress; empty = a new run.
  std::vector<viraal::SessionResult> kept_sessions;
  /// The results file they came from (results.json "resumed_from").
  std::string resumed_from;
  /// Channels: the machine names them in refusal keys and reasons, and addresses its messages.
  std::string robot_state_channel{channels::kRobotState};
  std::string iiwa_command_channel{channels::kIiwaCommand};
  std::string plan_check_request_channel{channels::kPlanCheckRequest};
  std::string plan_check_reply_channel{channels::kPlanCheckReply};
  std::string session_control_channel{channels::kSessionControl};
  std::string trial_channel{channels::kAlignmentTrial};
  std::string registration_channel{channels::kRegistration};
  std::string landmark_request_channel{channels::kLandmarkRequest};
  std::string landmark_channel{channels::kLandmark};
  std::string misalignment_request_channel{channels::kMisalignmentRequest};
  std::string misalignment_channel{channels::kMisalignment};
};

/// One of several headsets and arms: the session's channels (SESSION_CONTROL,
/// ALIGNMENT_TRIAL, REGISTRATION, LANDMARK*, MISALIGNMENT*) get the headset's suffix, the arm's
/// (ROBOT_STATE, IIWA_COMMAND, PLAN_CHECK_*) the arm's (channels::ForHeadset, ForArm); "" keeps them.
void UseInstanceChannels(ConductorOptions* options, const std::string& headset, const std::string& arm);

/// Throws std::invalid_argument naming the flag of the first duration or tolerance in `options`
/// that is not a finite number > 0, or when retry_max_s < retry_initial_s.
void CheckConductorOptions(const ConductorOptions& options);

/// A message to publish on `channel`.
struct Publication {
  using Message =
      std::variant<orbed::plan_check_request_t, orbed::session_control_t, orbed::iiwa_command_t,
                   orbed::landmark_request_t, orbed::misalignment_request_t, orbed::alignment_trial_t>;
  std::string channel;
  Message message;
};
/// A line for the operator (orbed-scenario's stdout).
struct ProgressLine {
  std::string text;
};
/// A line for the process log.
struct LogEntry {
  orbed::LogLevel level{orbed::LogLevel::kInfo};
  std::string text;
};
/// A refused input: class `key` ("<channel>/field", "<channel>/unexpected") and a one-line reason.
struct Refusal {
  std::string key;
  std::string reason;
};
using ConductorAction = std::variant<Publication, ProgressLine, LogEntry, Refusal>;
using ConductorActions = std::vector<ConductorAction>;

class ViraalConductor {
 public:
  enum class Phase {
    kNotStarted,
    kWaitRobot,
    kCheckPlans,
    kMove,
    kAwaitTrial,
    kAwaitTrialResults,
    kAwaitMean,
    kAwaitMeanMisalignment,
    kDone,
  };
  enum class Status { kRunning, kSucceeded, kFailed };

  /// Checks `options` (CheckConductorOptions), the configurations against the model's joint limits
  /// and the landmarks against its links; throws std::invalid_argument with the reason.
  ViraalConductor(ConductorOptions options, orbed::sim::RobotModel model);
  ~ViraalConductor();
  ViraalConductor(const ViraalConductor&) = delete;
  ViraalConductor& operator=(const ViraalConductor&) = delete;

  /// Starts the run clock and waits for the robot. Call once, before any other input (they throw
  /// std::logic_error before it).
  ConductorActions Start(const ConductorTime& now);

  ConductorActions OnRobotState(const orbed::robot_state_t& msg, const ConductorTime& now);
  ConductorActions OnPlanCheckReply(const orbed::plan_check_reply_t& msg, const ConductorTime& now);
  ConductorActions OnTrial(const orbed::alignment_trial_t& msg, const ConductorTime& now);
  ConductorActions OnRegistration(const orbed::registration_t& msg, const ConductorTime& now);
  ConductorActions OnLandmark(const orbed::landmark_t& msg, const ConductorTime& now);
  ConductorActions OnMisalignment(const orbed::misalignment_t& msg, const ConductorTime& now);
  /// Advances what waits on time: timeouts, arrival checks, IIWA_COMMAND re-sends.
  ConductorActions Tick(const ConductorTime& now);
  /// Fails a run that has not finished with `reason` (e.g. stopped from outside); else nothing.
  ConductorActions Abort(const std::string& reason, const ConductorTime& now);

  Phase phase() const { return phase_; }
  Status status() const;
  bool done() const { return phase_ == Phase::kDone; }
  /// The results so far; final once done(). rejected_inputs counts this machine's refusals (the
  /// shell replaces it with its process's total, which also counts undecodable messages).
  const viraal::RunResults& results() const { return results_; }
  /// Requests re-sent so far (each re-sent message counts once).
  int64_t retries() const { return retries_; }
  const ConductorOptions& options() const { return options_; }
  const orbed::sim::RobotModel& model() const { return *model_; }

 private:
  // Sets the time of the call and clears the action list; throws before Start().
  void Begin(const ConductorTime& now);
  ConductorActions TakeActions();
  // The timer's work; handlers call it too once they recorded an input.
  void Step();

  // Phase entries: each emits what starts the phase. Enter() also starts the retry schedule.
  void Enter(Phase phase);
  void StartPlanChecks();
  void StartSession();
  // Emits the trial's IIWA_COMMAND; `first` enters kMove (else a re-send).
  void StartMove(bool first);
  void RequestTrial();
  void RequestMean();
  void SendMisalignment(const viraal::AlignmentError& error);
  void FinishTrial();
  void FinishSession();
  void FinishRun();
  void FailRun(const std::string& reason);
  // A SESSION_CONTROL of the current session with a new request id, published and returned.
  orbed::session_control_t SendSessionControl(int8_t command);
  // Re-sends what the phase still waits for when the retry is due, and schedules the next one.
  void RetryIfDue();
  int64_t NewRequestId() { return request_id_base_ + next_request_id_++; }
  // True for an id this run gave a request (so an answer carrying it is a repeat, not a stranger).
  bool IssuedRequestId(int64_t id) const {
    return id > request_id_base_ && id < request_id_base_ + next_request_id_;
  }
  // Every LANDMARK_REQUEST of the trial is answered (true when there are none).
  bool LandmarksAnswered() const;
  // The trial is in and the server registered it (REGISTRATION reason TRIAL for it).
  bool TrialRegistered() const;
  // ", sent N times": how often the phase's request went out, for timeout reasons.
  std::string Attempts() const;

  double PhaseSeconds() const { return now_.t_s - phase_start_s_; }
  const std::vector<double>& TargetDeg() const;
  std::string StepLabel() const;
  void Refuse(const std::string& key, const std::string& reason);
  void Say(const std::string& line);
  void Log(orbed::LogLevel level, const std::string& text);
  template <class Msg>
  void Publish(const std::string& channel, const Msg& msg) {
    actions_.push_back(Publication{channel, msg});
  }

  ConductorOptions options_;
  std::unique_ptr<const orbed::sim::RobotModel> model_;
  std::unique_ptr<viraal::RobotPointSet> points_;

  ConductorTime now_;
  ConductorActions actions_;
  Phase phase_{Phase::kNotStarted};
  double run_start_s_{0};
  double phase_start_s_{0};
  double last_command_s_{0};
  std::optional<double> stopped_since_s_;
  std::string last_refusal_;
  int64_t refusals_{0};

  // Latest truth from the sim.
  std::optional<orbed::robot_state_t> robot_state_;
  double robot_state_received_s_{0};

  // Request ids: request_id_base_ + 1, + 2, ... (the base is Start()'s utime).
  int64_t request_id_base_{0};
  int64_t next_request_id_{1};
  // The retry schedule of the phase's requests (set by Enter()).
  double next_retry_s_{0};
  double retry_interval_s_{0};
  int attempts_{0};
  int64_t retries_{0};

  // Plan checks: one request per configuration, as sent.
  std::vector<orbed::plan_check_request_t> plan_requests_;
  std::vector<bool> plan_answered_;

  // Where the run is, and the requests of the current session and trial, as sent.
  size_t mode_index_{0};
  int trial_index_{0};
  orbed::session_control_t start_request_;
  std::vector<orbed::alignment_trial_t> kept_trials_;  // resuming: re-sent after START
  orbed::session_control_t trial_request_;
  orbed::session_control_t compute_request_;
  // The trial's landmark requests, as sent, and their answers (empty: not annotated).
  std::vector<orbed::landmark_request_t> landmark_requests_;
  std::vector<std::optional<orbed::landmark_t>> landmark_answers_;
  orbed::misalignment_request_t misalignment_request_;
  std::optional<orbed::alignment_trial_t> trial_;
  std::optional<orbed::registration_t> trial_registration_;
  double reach_s_{0};
  std::optional<orbed::misalignment_t> misalignment_;
  std::optional<orbed::registration_t> mean_registration_;
  viraal::AlignmentError pending_error_;
  std::vector<viraal::RobotPoints> session_points_;

  viraal::RunResults results_;
};

}  // namespace orbed::scenario
