#pragma once
/// @file
/// orbed-iiwa-sim's core (the process is sim/iiwa_sim.h, its LCM shell): the simulated arm in its
/// scene and the sim clock's bookkeeping, without a bus or a clock. The shell hands it the messages,
/// the wall clock [us since the epoch] and a monotonic clock [ns, any epoch]; it answers with what
/// to publish. What the outputs mean, the clocks, lockstep and crash recovery are described in
/// sim/iiwa_sim.h; here only what each call decides.
///
///   Options: ResolveIiwaSimOptions resolves the default paths, the arm's channel suffixes and
///            P = period_s in whole microseconds, and checks every number (std::invalid_argument
///            naming the option).
///   Commands: AcceptCommand checks IIWA_COMMAND (CheckIiwaCommand) and its age: a command whose
///            utime is further than stale_command_s from both the wall clock and the sim clock (that
///            one's age in wall seconds, divided by realtime_rate) is refused as "stale"; an accepted
///            one becomes the arm's target (clamped to the limits by ManualArm).
///   Ticks:   Tick steps the arm K times by P, keeps the step that came closest to contact and
///            counts the tick (k + 1); against the monotonic time it keeps the pace: outside lockstep
///            a tick more than MaxLagMicros() behind its deadline jumps k to the last deadline passed
///            (the skipped ticks reported at most every 10 s); in lockstep the pace restarts from now.
///            TickDue says whether a lockstep tick's wall time has come (half a tick early).
///   Hold:    while holding (hold_for set), no step; HoldForRunning then Release end it once the
///            process runs (in lockstep: and follows the clock); the clock restarts at k = 0.
///   Outputs: IiwaStatus, RobotState, CollisionStatus, SimClock and PlanCheckReply build the
///            messages; the caller stamps nothing else.
///   State file: ShouldSave says whether the status is to be written (q changed, and the arm at rest
///            or state_save_period_s of sim time since the last save); Saved records a written one.
///
/// Units: rad, m inside; utime [us since the epoch]; sim time in ticks of K x P [us].
/// Threading: not synchronised; one thread.

#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <orbed/collision_status_t.hpp>
#include <orbed/iiwa_command_t.hpp>
#include <orbed/iiwa_status_t.hpp>
#include <orbed/plan_check_reply_t.hpp>
#include <orbed/plan_check_request_t.hpp>
#include <orbed/robot_state_t.hpp>
#include <orbed/sim_clock_t.hpp>

#include "base/source_paths.h"
#include "lcmtypes/contract/channels.h"
#include "lcmtypes/contract/session_control.h"
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

/// The options with the file paths and channels resolved and period_s = P (whole microseconds);
/// std::invalid_argument naming the option for a bad number.
IiwaSimOptions ResolveIiwaSimOptions(IiwaSimOptions options);

class ArmSim {
 public:
  /// Resolves the options, loads the URDF and scene (std::runtime_error naming the file, element/key
  /// and what was expected) and the state file if any (std::runtime_error when damaged), else
  /// starts at initial_q_deg (std::invalid_argument when not a joint vector within the limits).
  explicit ArmSim(const IiwaSimOptions& options);

  const IiwaSimOptions& options() const { return options_; }
  const Scene& scene() const { return scene_; }
  const ManualArm& arm() const { return *arm_; }
  /// Several arms: the scene's other arms, moving obstacles posed by AcceptOtherArm(index, ...).
  struct OtherArm {
    int index;
    std::string name;
  };
  const std::vector<OtherArm>& other_arms() const { return other_arms_; }
  /// P, K x P [us]; the wall time between ticks K x P / R [ns].
  int64_t period_us() const { return period_us_; }
  int64_t tick_us() const { return tick_us_; }
  int64_t tick_wall_ns() const { return tick_wall_ns_; }
  /// How far behind its deadline a tick may run before the sim clock skips ahead [us]:
  /// max(100 ms, 20 P).
  int64_t MaxLagMicros() const { return std::max<int64_t>(100'000, 20 * period_us_); }
  int64_t start_utime() const { return start_utime_; }
  /// k: the ticks made, plus any deadlines skipped after a stall.
  int64_t ticks() const { return ticks_; }
  /// The sim time of the last tick: start_utime + k x K x P [us since the epoch].
  int64_t NowUtime() const { return start_utime_ + ticks_ * tick_us_; }
  bool holding() const { return holding_; }

  /// Starts the sim clock: tick k stamped start_utime + k x K x P, due k x K x P / R after mono_ns.
  /// Holding from here when hold_for is set.
  void Start(int64_t start_utime, int64_t mono_ns);

  /// IIWA_COMMAND received at wall time wall_now_us: the refusal ("<class>", reason) or nothing
  /// (the arm's new target).
  std::optional<Refusal> AcceptCommand(const orbed::iiwa_command_t& msg, int64_t wall_now_us);
  /// Another arm's ROBOT_STATE: the refusal ("field", reason) or nothing (its links posed).
  std::optional<Refusal> AcceptOtherArm(int index, const orbed::robot_state_t& msg);
  /// The answer to a PLAN_CHECK_REQUEST stamped wall_now_us; *refusal set when it is invalid (the
  /// answer then says request_valid = false and why).
  orbed::plan_check_reply_t PlanCheckReply(const orbed::plan_check_request_t& msg, int64_t wall_now_us,
                                           std::optional<Refusal>* refusal) const;

  struct TickResult {
    CollisionResult closest;     ///< the tick's step closest to contact (COLLISION_STATUS)
    int64_t skipped_to_warn{0};  ///< > 0: deadlines skipped since the last warning, to warn of now
  };
  /// One tick at monotonic time mono_ns (not while holding): K steps of P, k + 1, the pace kept.
  TickResult Tick(int64_t mono_ns);
  /// Lockstep: whether the next tick's wall time has come at mono_ns (half a tick early).
  bool TickDue(int64_t mono_ns) const;
  /// The process held for runs.
  void HoldForRunning() { hold_for_running_ = true; }
  /// Ends the hold when the held-for process runs and (lockstep) follows the clock; the clock
  /// restarts at k = 0 with its pace from mono_ns. True when it ended now.
  bool Release(bool hold_for_follows, int64_t mono_ns);

  /// The outputs at `utime` (see sim/iiwa_sim.h for what they carry).
  orbed::iiwa_status_t IiwaStatus(int64_t utime) const;
  orbed::robot_state_t RobotState(int64_t utime);
  orbed::collision_status_t CollisionStatus(int64_t utime, const CollisionResult& r) const;
  orbed::sim_clock_t SimClock(int64_t utime, int32_t round) const;

  /// Whether `status` goes to the state file now; Saved(status) once it has.
  bool ShouldSave(const orbed::iiwa_status_t& status) const;
  void Saved(const orbed::iiwa_status_t& status);

 private:
  IiwaSimOptions options_;
  Scene scene_;
  std::unique_ptr<ManualArm> arm_;
  std::vector<OtherArm> other_arms_;
  std::vector<int> reported_links_;  // links with geometry and a finite clearance
  std::vector<Eigen::Isometry3d> X_RL_;
  std::vector<Eigen::Isometry3d> other_X_WL_;  // scratch: another arm's link poses
  int64_t period_us_{0};
  int64_t tick_us_{0};       // K x P
  int64_t tick_wall_ns_{0};  // K x P / R
  int64_t start_utime_{0};
  int64_t start_mono_ns_{0};  // when tick 0 was due
  bool holding_{false};
  bool hold_for_running_{false};
  int64_t ticks_{0};
  int64_t skipped_ticks_{0};  // since the last warning
  std::optional<int64_t> last_skip_warning_ns_;
  std::vector<double> saved_q_;  // q in the state file
  int64_t save_every_ticks_{1};
  int64_t next_save_tick_{0};
};

}  // namespace orbed::sim
