#pragma once
/// @file
/// The orbed-iiwa-sim process: a simulated KUKA LBR iiwa 7 R800 in the OR scene, driven like a
/// hand-guided arm in manual mode (the motion law is ManualArm's, sim/manual_arm.h: synchronised
/// straight joint-space moves at the URDF velocity limits, commands clamped to the joint limits,
/// steps refused before a collision).
///
///   Subscribes: IIWA_COMMAND (iiwa_command_t, Drake's lcmt_iiwa_command layout) — the target;
///               PLAN_CHECK_REQUEST (plan_check_request_t).
///   Publishes, every tick (period_s, default 5 ms = 200 Hz), all with the same utime (the sim
///   clock, below):
///               IIWA_STATUS (iiwa_status_t, Drake's lcmt_iiwa_status layout), ROBOT_STATE
///               (robot_state_t: true X_WR from the scene, X_RF, X_RT, every link's X_RL, limit
///               flags, motion state and stop reason), COLLISION_STATUS (collision_status_t: pairs
///               closer than report_distance_m, per-link clearance, the duration of the query that
///               produced it — made when the arm last moved; the scene is static);
///               PLAN_CHECK_REPLY (plan_check_reply_t) answering each request, echoing request_id —
///               an invalid request gets request_valid = false and a reason, never silence; the
///               answer is a pure function of the request's q and the static scene, so a repeated
///               request (a client's retry) gets the same answer (only its utime differs);
///               PROCESS_STATUS at 1 Hz (Process), with rejections counted per class and the
///               tick deadlines the loop skipped under load counted as the drop "timer/tick".
///
/// IIWA_STATUS fields: joint_position_measured = q after this tick's step; joint_velocity_estimated
/// = that step / P (the period, below); joint_position_commanded = the last accepted command as sent
/// (unclamped; q0 before any); joint_position_ipo = the set point tracked this tick (= measured:
/// the simulated servo is perfect); torques 0 (no dynamics).
///
/// Rejected commands (Process::Reject, keys "<channel>/<class>"), the process keeps running:
///   num_joints (!= the arm's), num_torques (neither 0 nor num_joints), non_finite (a NaN or inf
///   position or torque), stale (utime more than stale_command_s away from the wall clock, older
///   or ahead; 0 disables), decode (undecodable bytes, by Process).
/// A command beyond a joint limit is not rejected: it is clamped, and the arm stops at the limit
/// with motion_state STOPPED_AT_LIMIT and the joint named in stop_reason.
///
/// Clocks: IIWA_STATUS, ROBOT_STATE and COLLISION_STATUS carry the sim clock. P = period_s
/// rounded to whole microseconds (>= 1 us). Tick k steps the arm by exactly P and stamps its outputs
///     utime_k = start_utime + k * P,
/// start_utime being the wall clock (NowMicros) when the constructor set up the tick timer, whose
/// deadlines are k * P after that on the monotonic clock. Each Tick() call is the next tick
/// (k + 1), however late it runs: late ticks keep their stamps, and the Process loop runs a few
/// missed deadlines back to back (catch-up), so the sim clock stays within a few periods of the wall
/// clock. Only when a tick finds itself more than MaxLagMicros() = max(100 ms, 20 P) behind its
/// deadline (a stall, whose deadlines the loop skipped) does k jump to the last deadline passed
/// (logged, at most every 10 s): the sim clock never falls behind for good, and the jump never puts
/// it ahead of the schedule. So utime strictly increases by whole multiples of P (exactly P but after a
/// stall), a step never exceeds v_max * P (ManualArm), and the speed read from the stamps, |q_k - q_j| /
/// (utime_k - utime_j), never exceeds the joint's velocity limit, however loaded the machine: utime says when
/// the state holds in simulated time, not when it was computed. Tick() called directly (tests) advances k by
/// one per call the same way. Wall clock: the stale-command check (senders stamp commands with their wall
/// clocks, or with this sim clock when they follow it: a command near either is fresh),
/// PLAN_CHECK_REPLY and PROCESS_STATUS.
///
/// Faster than real time (realtime_rate R > 1, for studies without a person in the loop): a tick
/// steps the arm K times by P (steps_per_tick, default K = R; each step checked for collisions as
/// at R = 1), ticks are K * P / R of wall time apart, and tick k is stamped
///     utime_k = start_utime + k * K * P,
/// so the sim clock runs R times faster than the wall clock and the arm moves R times faster in
/// wall time while every step, and the speed read from the stamps, keeps the joint's velocity
/// limit in sim time. The outputs go out once per tick (at K = R: 200 Hz of wall time, 200/R Hz of
/// sim time), COLLISION_STATUS with the tick's step that came closest to contact (so near misses
/// are seen at every rate). Each tick's stamp goes out first on SIM_CLOCK (sim_clock_t), the clock
/// the processes started with --sim-time follow (runtime/sim_clock.h); with hold_for it stays
/// at start_utime, and the arm does not step, until that process runs. The others keep the wall
/// clock.
///
/// Lockstep (lockstep, --lockstep; for runs that must not depend on the machine's speed): the sim
/// does not step on while a follower still works on the tick. Each tick's SIM_CLOCK alone is round
/// 1 (the followers' timers run on the previous tick's state); once every follower has answered it
/// on SIM_CLOCK_ACK (runtime/sim_clock.h), the tick's IIWA_STATUS, ROBOT_STATE and
/// COLLISION_STATUS go out and the stamp again as round 2, and while any answer (or the sim itself,
/// a PLAN_CHECK_REPLY) says it published something, the sim repeats the stamp in the next round; the next
/// tick comes once a round is quiet and its wall time K * P / R has come (R is then the fastest the sim runs:
/// a slow follower slows it down, and after a wait of more than MaxLagMicros() the pace starts again from
/// there rather than rushing to catch up; no stall jump). So every follower sees each tick's state, and every
/// reply to what it sent, before the next tick, however loaded the machine and whatever R: with the same K, a
/// run at R = 1 and one at R = 10 are the same run. A follower that has not answered a round within
/// lockstep_timeout_s (killed, hung) is left out, counted as the drop "lockstep/<name>" and logged, and taken
/// back with its next answer; a held clock waits for nobody (its rounds let the followers join; in lockstep
/// it is released only once the process it holds for has answered one). Answers are checked
/// (CheckSimClockAck; refused as "<channel>/field"), at most kMaxLockstepFollowers names.
///
/// Crash recovery (state_file, sim_state.h): the sim saves its measured q while the arm moves, at most
/// every state_save_period_s of sim time and whenever the arm comes to rest, and a sim started on an
/// existing state file starts there instead of at initial_q_deg (a damaged file: it does not start).
/// A respawned sim therefore resumes at most one save period of motion behind where the arm was, at
/// rest exactly where it was; the next IIWA_COMMAND (the conductor re-sends it while the arm is short
/// of the target) moves it on.
///
/// Threading: everything on the Process::Run() thread.

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <orbed/iiwa_command_t.hpp>
#include <orbed/iiwa_status_t.hpp>
#include <orbed/plan_check_request_t.hpp>
#include <orbed/robot_state_t.hpp>
#include <orbed/sim_clock_ack_t.hpp>

#include "base/source_paths.h"
#include "lcmtypes/contract/channels.h"
#include "runtime/process.h"
#include "runtime/sim_clock.h"
#include "sim/manual_arm.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::sim {

/// The most steps of P one tick may make (and K x P at most kMaxSimClockStepUs).
inline constexpr int kMaxStepsPerTick = 1000;
/// Lockstep: a round still missing answers after this long [s of wall time] is sent again (a lost
/// datagram; the default of IiwaSimOptions::lockstep_resend_s); a tick steps on after this many rounds
/// (counted as the drop "lockstep/rounds"); a held clock's rounds go out at most this often [Hz].
inline constexpr double kLockstepResendS = 0.1;
inline constexpr int32_t kMaxLockstepRounds = 1000;
inline constexpr double kHeldRoundsHz = 20.0;

struct IiwaSimOptions {
  /// URDF and scene files; "" = the files shipped in the source tree (SourceTreePath()).
  std::string urdf_path;
  std::string scene_path;
  /// Tick = status period [s]; rounded to whole microseconds, which must leave >= 1 us.
  double period_s{0.005};
  /// Sim seconds per wall second, 1..kMaxRealtimeRate (Drake's target realtime rate, whole numbers
  /// here; in lockstep the most, see Lockstep).
  int realtime_rate{1};
  /// K: each tick steps the arm K times by P and publishes once (see Clocks); 0 = realtime_rate.
  /// At most kMaxStepsPerTick.
  int steps_per_tick{0};
  /// Lockstep (see Lockstep): before each step, wait until the followers have answered.
  bool lockstep{false};
  /// How long a lockstep round waits for a follower before leaving it out [s of wall time], > 0.
  double lockstep_timeout_s{10.0};
  /// A lockstep round still missing answers after this long is sent again [s of wall time], > 0.
  double lockstep_resend_s{kLockstepResendS};
  /// Initial joint vector [deg]; empty = all zero (the arm upright). Must be within the limits.
  std::vector<double> initial_q_deg;
  /// The state file (sim_state.h): read at start (over initial_q_deg) and written as the arm moves;
  /// "" = none.
  std::string state_file;
  /// Longest time between two saves while the arm moves [s of sim time], > 0.
  double state_save_period_s{0.1};
  /// Commands whose utime is further than this from the wall clock are rejected [s]; 0 = never.
  double stale_command_s{1.0};
  /// Motion stops this far before contact [m] (ManualArmOptions::stop_margin_m).
  double stop_margin_m{0.01};
  /// COLLISION_STATUS lists pairs closer than this [m].
  double report_distance_m{0.05};
  /// robot_state_t::robot_name (with `arm`, unless set: the arm's name).
  std::string robot_name{"iiwa7"};
  /// Several arms: "" = the single arm (the scene's robot.base_pose, plain channel
  /// names). Else the name of one of the scene's `arms:`: its base, every channel below suffixed
  /// with channels::ForArm (IIWA_STATUS_A1, ...; SIM_CLOCK too: each arm's sim keeps its own
  /// clock), and every other arm of the scene a moving obstacle, posed from its ROBOT_STATE_<NAME>
  /// (checked as CheckRobotState, its link count the model's, each X_RL a pose; refused as
  /// "<channel>/field"), not checked until its first.
  std::string arm;
  std::string iiwa_status_channel{channels::kIiwaStatus};
  std::string iiwa_command_channel{channels::kIiwaCommand};
  std::string robot_state_channel{channels::kRobotState};
  std::string collision_status_channel{channels::kCollisionStatus};
  std::string plan_check_request_channel{channels::kPlanCheckRequest};
  std::string plan_check_reply_channel{channels::kPlanCheckReply};
  /// SIM_CLOCK (sim_clock_t, each tick's stamp, before the tick's other outputs); "" = not published.
  std::string sim_clock_channel{channels::kSimClock};
  /// "" = the clock runs from the start. Else the sim holds its clock (publishes only SIM_CLOCK, at
  /// the start stamp, and does not step) until PROCESS_STATUS shows the process of this name
  /// running: a launch whose last process is NAME then starts every follower of the sim clock at
  /// the same sim moment, whatever the rate and however long each took to start.
  std::string hold_for;
};

class IiwaSim {
 public:
  /// Loads the URDF and scene (std::runtime_error naming the file, element/key and what was
  /// expected), validates the options (std::invalid_argument naming the option), then opens LCM
  /// (std::runtime_error naming the URL).
  IiwaSim(const orbed::CommonFlags& flags, const IiwaSimOptions& options);
  ~IiwaSim();

  int Run() { return process_->Run(); }
  orbed::Process& process() { return *process_; }
  /// The options with the file paths resolved and period_s = P (whole microseconds).
  const IiwaSimOptions& options() const { return options_; }
  /// The sim clock (see Clocks): P [us], start_utime [us since the epoch], k of the last tick (the
  /// number of Tick() calls, plus any deadlines skipped after a stall); the last outputs carry
  /// start_utime() + ticks() * period_us().
  int64_t period_us() const { return period_us_; }
  int64_t start_utime() const { return start_utime_; }
  int64_t ticks() const { return ticks_; }
  /// Whether the clock is still held (IiwaSimOptions::hold_for).
  bool holding() const { return holding_; }
  /// Sim time per tick K x P [us].
  int64_t tick_us() const { return tick_us_; }
  /// Lockstep: the followers waited for, the current tick's round (0 before the first).
  std::vector<std::string> lockstep_followers() const { return barrier_.followers(); }
  int32_t lockstep_round() const { return round_; }
  /// How far behind its deadline a tick may run before the sim clock skips ahead [us].
  int64_t MaxLagMicros() const;
  const Scene& scene() const { return scene_; }
  const ManualArm& arm() const { return *arm_; }

  /// One tick: step the arm by P, advance the sim clock by P and publish IIWA_STATUS, ROBOT_STATE,
  /// COLLISION_STATUS stamped with it (the timer's callback; public so tests can drive it without
  /// waiting).
  void Tick();
  /// Lockstep: the next round, or the next tick once the round is complete, nobody published and
  /// the tick is due; nothing while the clock is held (the poll's callback after the hold, and
  /// each answer's; public so tests can drive it).
  void Advance();

 private:
  void OnCommand(const orbed::iiwa_command_t& msg, const std::string& channel);
  void OnPlanCheck(const orbed::plan_check_request_t& msg, const std::string& channel);
  void OnOtherArm(int index, const orbed::robot_state_t& msg, const std::string& channel);
  // SIM_CLOCK, then PublishState.
  void PublishAll(int64_t utime, const CollisionResult& r);
  // IIWA_STATUS, ROBOT_STATE, COLLISION_STATUS at `utime` (saving the state file).
  void PublishState(int64_t utime, const CollisionResult& r);
  // SIM_CLOCK at `utime` (nothing without a sim_clock_channel); in lockstep round `round_`, which
  // the barrier then waits on.
  void PublishClock(int64_t utime);
  void OnAck(const orbed::sim_clock_ack_t& msg, const std::string& channel);
  // Ends the hold once hold_for runs (in lockstep: and has answered a round).
  void MaybeRelease();
  // The round that is out, again (SIM_CLOCK; the barrier keeps the answers it has).
  void ResendClock();
  // The sim time of the last tick [us since the epoch].
  int64_t NowUtime() const { return start_utime_ + ticks_ * tick_us_; }
  void SaveState(const orbed::iiwa_status_t& status);

  IiwaSimOptions options_;
  Scene scene_;
  std::unique_ptr<ManualArm> arm_;
  std::unique_ptr<orbed::Process> process_;
  std::vector<int> reported_links_;  // links with geometry and a finite clearance
  std::vector<Eigen::Isometry3d> X_RL_;
  std::vector<Eigen::Isometry3d> other_X_WL_;  // scratch: another arm's link poses
  int64_t period_us_{0};
  int steps_per_tick_{1};    // K
  int64_t tick_us_{0};       // K x P
  int64_t tick_wall_ns_{0};  // K x P / R: the wall time between ticks
  int64_t start_utime_{0};
  LockstepBarrier barrier_;
  int32_t round_{0};           // the round out (lockstep), 0 before the first
  double round_sent_s_{-1e9};  // when it (or the held clock's last round) went out [monotonic s]
  std::optional<CollisionResult> unpublished_state_;  // lockstep: the tick's state, for round 2
  std::chrono::steady_clock::time_point start_mono_;
  bool holding_{false};
  bool hold_for_running_{false};
  int64_t ticks_{0};
  int64_t skipped_ticks_{0};  // since the last warning
  std::chrono::steady_clock::time_point last_skip_warning_{};
  std::vector<double> saved_q_;  // q in the state file
  int64_t save_every_ticks_{1};
  int64_t next_save_tick_{0};
  int64_t save_failures_{0};
};

}  // namespace orbed::sim
