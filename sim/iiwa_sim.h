#pragma once
/// @file
/// The orbed-iiwa-sim process: a simulated KUKA LBR iiwa 7 R800 in the OR scene, driven like a
/// hand-guided arm in manual mode (the motion law is ManualArm's, sim/manual_arm.h: synchronised
/// straight joint-space moves at the URDF velocity limits, commands clamped to the joint limits,
/// steps refused before a collision). What decides is the core ArmSim (sim/arm_sim.h: options,
/// command acceptance, ticks and the sim clock's pace, the outputs' content, the state file's
/// saves); IiwaSim below is its LCM shell: subscriptions, the lockstep rounds, publications, the
/// state file's write. This comment describes the process as a whole.
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

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <orbed/sim_clock_ack_t.hpp>

#include "runtime/process.h"
#include "runtime/sim_clock.h"
#include "sim/arm_sim.h"

namespace orbed::sim {

/// The LCM shell around ArmSim (sim/arm_sim.h, the core that decides): it subscribes, hands the
/// core the messages and the clocks, publishes what it answers, writes the state file and keeps the
/// lockstep rounds (LockstepBarrier).
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
  const IiwaSimOptions& options() const { return core_.options(); }
  /// The sim clock (see Clocks): P [us], start_utime [us since the epoch], k of the last tick (the
  /// number of Tick() calls, plus any deadlines skipped after a stall); the last outputs carry
  /// start_utime() + ticks() * period_us().
  int64_t period_us() const { return core_.period_us(); }
  int64_t start_utime() const { return core_.start_utime(); }
  int64_t ticks() const { return core_.ticks(); }
  /// Whether the clock is still held (IiwaSimOptions::hold_for).
  bool holding() const { return core_.holding(); }
  /// Sim time per tick K x P [us].
  int64_t tick_us() const { return core_.tick_us(); }
  /// Lockstep: the followers waited for, the current tick's round (0 before the first).
  std::vector<std::string> lockstep_followers() const { return barrier_.followers(); }
  int32_t lockstep_round() const { return round_; }
  /// How far behind its deadline a tick may run before the sim clock skips ahead [us].
  int64_t MaxLagMicros() const { return core_.MaxLagMicros(); }
  const Scene& scene() const { return core_.scene(); }
  const ManualArm& arm() const { return core_.arm(); }

  /// One tick: step the arm by P, advance the sim clock by P and publish IIWA_STATUS, ROBOT_STATE,
  /// COLLISION_STATUS stamped with it (the timer's callback; public so tests can drive it without
  /// waiting).
  void Tick();
  /// Lockstep: the next round, or the next tick once the round is complete, nobody published and
  /// the tick is due; nothing while the clock is held (the poll's callback after the hold, and
  /// each answer's; public so tests can drive it).
  void Advance();

 private:
  void Reject(const std::string& channel, const Refusal& refusal);
  // IIWA_STATUS, ROBOT_STATE, COLLISION_STATUS at `utime` (saving the state file).
  void PublishState(int64_t utime, const CollisionResult& r);
  // SIM_CLOCK at `utime` (nothing without a sim_clock_channel); in lockstep round `round_`, which
  // the barrier then waits on.
  void PublishClock(int64_t utime);
  void OnAck(const orbed::sim_clock_ack_t& msg, const std::string& channel);
  // Ends the hold once hold_for runs (in lockstep: and has answered a round).
  void MaybeRelease();

  ArmSim core_;
  std::unique_ptr<orbed::Process> process_;
  LockstepBarrier barrier_;
  int32_t round_{0};           // the round out (lockstep), 0 before the first
  double round_sent_s_{-1e9};  // when it (or the held clock's last round) went out [monotonic s]
  std::optional<CollisionResult> unpublished_state_;  // lockstep: the tick's state, for round 2
  int64_t save_failures_{0};
};

}  // namespace orbed::sim
