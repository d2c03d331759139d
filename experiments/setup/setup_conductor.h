#pragma once
/// @file
/// The conductor of one user's part of the paper's robot set-up study (Sec. IV-B, Tables 2-4) as a
/// phase machine without a bus or a clock. SetupProcess (setup_process.h) feeds it the decoded
/// messages and the time and publishes what it asks for.
///
/// The run, for each mode of the user's order (ar_reflective, ar, fixed in some order) and each
/// target k = 1 .. K of the plan:
///   kAlign (ar, ar_reflective only): the user aligns N times in that mode and the registration
///     server's SE(3) mean is applied (the paper: "before each AR target the user aligns three
///     times"): a ViraalConductor (experiments/viraal/viraal_conductor.h) with the alignment protocol,
///     that mode only and run id "<run_id>-<task_id>" (so session "<run_id>-<task_id>-<mode>") runs to
///     its end; its every input and tick
///     are forwarded to it, its actions passed on. Its failure fails the run.
///   kPark: IIWA_COMMAND target k's start configuration (the design's per-target start, else the
///     one start; re-sent every command_resend_s) until every joint is within tolerance_deg and the
///     motion is IDLE: the experimenter parks the arm. Every mode runs the same (start, target)
///     pairs in the same order, so the modes of a user stay paired.
///   kTask: SETUP_TASK (task "<user>-<mode>-<k>", the target, the mode; a new request id) re-sent
///     every task_resend_s until the SETUP_RESULT with its id comes back (from orbed-assistant);
///     orbed-guidance shows the target. The record: the target, the joints the sim measured after
///     the answer came (the first ROBOT_STATE handled after it with the arm not MOVING: the truth,
///     not the assistant's word; the state handled just before the answer may be older than the
///     assistant's last reading), the assistant's execution
///     time and ranges, the alignment's time (the sum of the N trials' duration_s) and its mean's
///     errors against the truth; the docking error those joints cause (DockingError); and, from
///     COLLISION_STATUS and ROBOT_STATE while the assistant moved the arm, the smallest clearance
///     to anything (self or scene) [m], whether any pair touched, and how often the sim stopped the
///     arm before a collision (the paper's Sec. IV-B "beyond": collisions and near misses).
///   kRetract (retract, the design's runs): after each set-up, before the next task's alignment or
///     park, the experimenter takes the arm up out of the way: joints 4, 2, 6 and 1 are zeroed one at
///     a time (each waypoint the reached joints with those zeroed so far), then the zero
///     configuration (the candle), each until reached as in kPark. With a scene the next joint is
///     the first of those left whose straight move the sim would let through (the manual arm's
///     rule: sampled every 2 deg, no sample both within 1 cm of a collision and closer than the
///     one before; sim/manual_arm.h); a waypoint the sim stops short of is passed over for the next
///     (0.5 s after it was commanded). The arm may stop anywhere the assistant left it, and the sim moves
///     straight in joint space and stops before a collision, so a direct move to a start or to the
///     alignment's first configuration can be blocked; the design catalog checks the moves from the
///     candle to every start and alignment configuration (experiments/setup/design.h).
/// With perfect_registration (the "registration's share" experiment beyond the paper) the
/// headset modes skip kAlign: the conductor publishes a REGISTRATION (session
/// "<run_id>-<task_id>-truth", valid, num_trials 0) whose X_WV_mean is the true base pose X_WR of
/// the latest ROBOT_STATE, with every SETUP_TASK (so a restarted reader gets it again), and the
/// hologram stands where the real robot is; only the SLAM error and the person remain.
/// A phase that waits longer than its timeout fails the run with a one-line reason naming the
/// process that did not answer.
///
/// Inputs are checked (guidance::CheckSetupResult; CheckRobotState; CheckCollisionStatus); a bad one is
/// refused (a Refusal, key "<channel>/field") and changes nothing. Results of other request ids are ignored.
///
/// Time: ConductorTime (viraal_conductor.h): t_s monotonic [s], utime wall clock [µs]. Threading:
/// one thread makes every call.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <orbed/collision_status_t.hpp>
#include <orbed/iiwa_command_t.hpp>
#include <orbed/registration_t.hpp>
#include <orbed/robot_state_t.hpp>
#include <orbed/setup_result_t.hpp>
#include <orbed/setup_task_t.hpp>

#include "experiments/viraal/protocol.h"
#include "experiments/viraal/results.h"
#include "experiments/viraal/viraal_conductor.h"
#include "lcmtypes/contract/channels.h"
#include "sim/collision_world.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::setup {

using scenario::ConductorActions;
using scenario::ConductorTime;

struct SetupRecord;

struct SetupOptions {
  std::string user{"u1"};
  std::string run_id{"setup"};
  /// guidance_t::MODE_* in the user's order (each at most once).
  std::vector<int8_t> modes;
  /// The targets [deg] (the plan or the user's draw from the design), in order; the start
  /// configuration [deg] of every target, unless starts_deg gives one per target.
  std::vector<std::vector<double>> targets_deg;
  std::vector<double> start_deg;
  /// Per target (the design, experiments/setup/design.h): its start [deg] and the catalog ids of
  /// its start and target ("ready", "medium/umbilicus/2"); empty = start_deg and no ids.
  std::vector<std::vector<double>> starts_deg;
  std::vector<std::string> start_ids, target_ids;
  /// The alignment protocol of the headset modes (its modes are replaced per task; its trials are N).
  viraal::ScenarioConfig alignment;
  int reflective_mirrors{1};
  /// Headset modes: the true registration instead of N alignments (see the file comment).
  bool perfect_registration{false};
  /// kRetract after every set-up (orbed-setup sets it with a design), its route checked in this
  /// scene ("" = unchecked: joints 4, 2, 6, 1 zeroed in that order).
  bool retract{false};
  std::string retract_scene_path;
  double tolerance_deg{0.1};
  double startup_timeout_s{10.0};
  double move_timeout_s{30.0};
  double task_timeout_s{600.0};
  /// The deadline of the alignment's requests to the headset and the registration server [s]
  /// (ConductorOptions::request_deadline_s), stated by the launch file.
  double request_deadline_s{60.0};
  double command_resend_s{0.25};
  double task_resend_s{1.0};
  std::string robot_state_channel{channels::kRobotState};
  std::string collision_status_channel{channels::kCollisionStatus};
  std::string iiwa_command_channel{channels::kIiwaCommand};
  std::string setup_task_channel{channels::kSetupTask};
  std::string setup_result_channel{channels::kSetupResult};
  std::string registration_channel{channels::kRegistration};
  /// Resuming (KeptSetups): the set-ups an earlier run of this user finished, in order; the run
  /// starts with the next one. Empty = a new run.
  std::vector<SetupRecord> kept;
};

/// One finished set-up.
struct SetupRecord {
  std::string task_id;
  int8_t mode{0};
  int order{0};   ///< the mode's place in the user's order, 1-based
  int target{0};  ///< 1-based
  /// The design's ids of the start and the target ("" without a design or in older files).
  std::string start_id, target_id;
  std::vector<double> start_deg;  ///< where the arm was parked (empty in older files)
  std::vector<double> target_deg, reached_deg, assistant_reached_deg;
  std::vector<int> twisting;  ///< 1 for a twisting joint (guidance::JointKinds)
  std::vector<int> ranges;
  double execution_s{0};
  std::optional<double> alignment_s;  ///< headset modes: the N trials' time
  std::optional<viraal::SessionResult> alignment;
  double person_scale{1};
  bool perfect_registration{false};  ///< headset mode with the true registration
  /// The docking error the joint errors cause (DockingError of target_deg and reached_deg).
  double docking_tip_mm{0}, docking_axis_deg{0};
  /// While the assistant moved the arm: the smallest COLLISION_STATUS.min_distance_m (none when no
  /// COLLISION_STATUS came), whether any pair penetrated, and how many times the motion state became
  /// STOPPED_BEFORE_COLLISION or IN_COLLISION.
  std::optional<double> min_clearance_m;
  bool contact{false};
  int collision_stops{0};
};

/// How far the tool tip T and its axis (+z of T) end up from where the target configuration puts
/// them: |p_RT(reached) − p_RT(target)| [mm] and the angle between the two tool axes [deg], by the
/// model's forward kinematics (its tool: the URDF's tool tip). At the trocar this is the docking
/// error of the paper's Fig. 4e. Throws std::invalid_argument for vectors of the wrong size.
struct Docking {
  double tip_mm{0}, axis_deg{0};
};
Docking DockingError(const sim::RobotModel& model, const std::vector<double>& target_deg,
                     const std::vector<double>& reached_deg);

struct SetupRun {
  std::string user, run_id;
  std::string provenance;  ///< the run folder's provenance record ("" = none; base/run_folder.h)
  bool ok{false};
  std::string error;
  std::vector<std::string> order;  ///< mode names
  std::vector<SetupRecord> setups;
};
/// setup_results.json's text: {"user", "run_id", "provenance" (only when the run folder has a
/// record: "provenance.json"), "status": "ok" | "failed" | "partial", "error",
/// "order", "setups": [{task_id, mode, order, target, start_id, target_id (null without a design),
/// start_deg, target_deg, reached_deg,
/// assistant_reached_deg, error_deg, twisting, ranges, execution_s, alignment_s (null for fixed),
/// person_scale, registration ("measured" | "truth" | null for fixed), docking_tip_mm, docking_axis_deg,
/// min_clearance_m (null when unknown), contact, collision_stops, alignment: null | {session_id, trials,
/// translation_error_mm, rotation_error_deg, misalignment_mm} of the mean (misalignment_mm as the
/// conductor measured it: experiments/viraal/exchange.h MeanError)}]}.
std::string SetupRunJson(const SetupRun& run, bool partial);

/// setup_results.json read back (orbed-setup --resume; `path` may be its folder), checked like any
/// file from outside (base/json_fields.h): every field with its type and range, counts bounded;
/// error_deg is derived and not read. A record's alignment comes back as what the file holds (the
/// session id, as many empty trials as it counts, the mean's three errors), so that SetupRunJson
/// writes it again byte for byte. start_id, target_id and start_deg may be absent (files written
/// before the design). `status` gets "ok", "failed" or "partial". Throws
/// orbed::JsonReadError naming the file and the key.
SetupRun ReadSetupRunFile(const std::string& path, std::string* status);
/// The same from the file's text (`source` names it in errors).
SetupRun ParseSetupRunJson(const std::string& text, const std::string& source, std::string* status);

/// What a resumed run keeps of an earlier one (`earlier`, with its `status`): all its set-ups, in
/// order. Refused (std::invalid_argument with the reason): status "ok" (nothing to run); another
/// user, run id or mode order; a set-up that is not the next of this run's (task id
/// "<user>-<mode>-<k>", mode, order and target in sequence) or whose target differs from this
/// plan's (1e-9 deg), or whose start or ids (when recorded) differ from this run's; a registration
/// ("measured" / "truth") other than this run's; as many set-ups as the run has (nothing left) or more. The
/// set-ups left are new draws of the same emulated person (the assistant's random stream starts afresh), not
/// those an uninterrupted run would have made.
std::vector<SetupRecord> KeptSetups(const SetupRun& earlier, const std::string& status,
                                    const SetupOptions& options);

/// A uniform random order of guidance modes 0, 1, 2 for a user seed (Fisher-Yates with
/// base/random.h, seeded by user_seed ^ 0x5e7a9).
std::vector<int8_t> ModeOrderForSeed(uint64_t user_seed);
/// The modes of a comma-separated list of names ("fixed,ar,ar_reflective":
/// guidance::GuidanceModeFromName, which throws std::invalid_argument naming a bad one), in order;
/// repeats are the conductor's check.
std::vector<int8_t> ModeOrderFromNames(const std::string& names);
/// The plan's first `count` targets [deg] (guidance::ReadPlanTarget: throws std::runtime_error
/// naming the file, or the number when the plan has fewer).
std::vector<std::vector<double>> PlanTargetsDeg(const std::string& plan_path, int count,
                                                const sim::RobotModel& model);

/// A message of this conductor's own to publish.
struct SetupPublication {
  std::string channel;
  std::variant<orbed::iiwa_command_t, orbed::setup_task_t, orbed::registration_t> message;
};

class SetupConductor {
 public:
  enum class Phase { kNotStarted, kWaitRobot, kAlign, kRetract, kPark, kTask, kDone };

  /// Throws std::invalid_argument for empty modes or targets, a mode twice or out of range,
  /// targets or start outside the joint limits or of the wrong size.
  SetupConductor(SetupOptions options, sim::RobotModel model);
  ~SetupConductor();

  /// Every call returns the nested ViRAAl conductor's actions (alignment) and appends this
  /// conductor's own publications, progress lines and refusals to `own`.
  struct Actions {
    ConductorActions viraal;  ///< publications, progress, logs, refusals of the alignment
    std::vector<SetupPublication> publish;
    std::vector<std::string> progress;
    std::vector<scenario::Refusal> refusals;
  };
  Actions Start(const ConductorTime& now);
  Actions OnRobotState(const orbed::robot_state_t& msg, const ConductorTime& now);
  Actions OnPlanCheckReply(const orbed::plan_check_reply_t& msg, const ConductorTime& now);
  Actions OnTrial(const orbed::alignment_trial_t& msg, const ConductorTime& now);
  Actions OnRegistration(const orbed::registration_t& msg, const ConductorTime& now);
  Actions OnLandmark(const orbed::landmark_t& msg, const ConductorTime& now);
  Actions OnMisalignment(const orbed::misalignment_t& msg, const ConductorTime& now);
  Actions OnSetupResult(const orbed::setup_result_t& msg, const ConductorTime& now);
  Actions OnCollisionStatus(const orbed::collision_status_t& msg, const ConductorTime& now);
  Actions Tick(const ConductorTime& now);
  Actions Abort(const std::string& reason, const ConductorTime& now);

  Phase phase() const { return phase_; }
  bool done() const { return phase_ == Phase::kDone; }
  const SetupRun& run() const { return run_; }

 private:
  void Begin(const ConductorTime& now);
  Actions Take();
  void Step();
  void StartTask();  // enters kAlign or kPark for task_index_
  void EnterPark();
  void EnterRetract();
  // kPark and kRetract: IIWA_COMMAND `q_deg` until the arm is there at rest; true when it is.
  bool MoveTo(const std::vector<double>& q_deg, const std::string& what);
  void SendTask();
  void Record(const orbed::setup_result_t& msg);  // the answered task's SetupRecord; then the next task
  void Fail(const std::string& reason);
  std::string TaskId() const;
  int8_t Mode() const { return options_.modes[mode_index_]; }
  const std::vector<double>& StartDeg() const;  // the current target's start

  SetupOptions options_;
  std::unique_ptr<const sim::RobotModel> model_;
  std::vector<int> twisting_;
  ConductorTime now_;
  Actions actions_;
  Phase phase_{Phase::kNotStarted};
  double phase_start_s_{0};
  double last_send_s_{-1e9};
  std::optional<orbed::robot_state_t> robot_state_;
  std::vector<std::vector<double>> retract_route_;
  std::unique_ptr<sim::Scene> retract_scene_;  // with retract_scene_path
  std::unique_ptr<sim::CollisionWorld>
      retract_world_;  // in retract_scene_  // kRetract's waypoints [deg], the next first
  // What the arm met during the current kTask (reset when it starts).
  std::optional<double> task_min_clearance_m_;
  bool task_contact_{false};
  int task_collision_stops_{0};
  // The current task's answer, until a ROBOT_STATE with the arm at rest follows it.
  std::optional<orbed::setup_result_t> pending_result_;
  size_t mode_index_{0};
  size_t target_index_{0};
  std::unique_ptr<scenario::ViraalConductor> alignment_;
  std::optional<viraal::SessionResult> alignment_result_;
  orbed::setup_task_t task_{};
  int64_t request_id_base_{0};
  int64_t next_request_id_{1};
  SetupRun run_;
};

}  // namespace orbed::setup
