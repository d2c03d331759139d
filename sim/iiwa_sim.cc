#include "sim/iiwa_sim.h"

#include <algorithm>
#include <chrono>
#include <string>

#include "base/log.h"
#include "lcmtypes/contract/conversions.h"
#include "sim/sim_state.h"

namespace orbed::sim {
namespace {

int64_t MonotonicNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}
double MonotonicS() { return 1e-9 * static_cast<double>(MonotonicNs()); }

}  // namespace

IiwaSim::IiwaSim(const orbed::CommonFlags& flags, const IiwaSimOptions& options)
    : core_(options), barrier_(core_.options().lockstep_timeout_s) {
  const IiwaSimOptions& o = core_.options();
  process_ = std::make_unique<orbed::Process>(flags);
  for (const ArmSim::OtherArm& other : core_.other_arms()) {
    process_->Subscribe<orbed::robot_state_t>(
        channels::ForArm(channels::kRobotState, other.name),
        [this, index = other.index](const orbed::robot_state_t& msg, const std::string& channel, int64_t) {
          if (const auto refusal = core_.AcceptOtherArm(index, msg)) Reject(channel, *refusal);
        });
  }
  process_->Subscribe<orbed::iiwa_command_t>(
      o.iiwa_command_channel, [this](const orbed::iiwa_command_t& msg, const std::string& channel, int64_t) {
        if (const auto refusal = core_.AcceptCommand(msg, NowMicros())) Reject(channel, *refusal);
      });
  process_->Subscribe<orbed::plan_check_request_t>(
      o.plan_check_request_channel,
      [this](const orbed::plan_check_request_t& msg, const std::string& channel, int64_t) {
        std::optional<Refusal> refusal;
        orbed::plan_check_reply_t reply = core_.PlanCheckReply(msg, NowMicros(), &refusal);
        reply.utime = NowMicros();  // as the reply leaves, after the collision check
        if (refusal) Reject(channel, *refusal);
        process_->Publish(core_.options().plan_check_reply_channel, reply);
      });
  // The sim clock starts with the timer: tick k is due k x K x P / R from now (after the hold, if
  // any, from the release).
  core_.Start(NowMicros(), MonotonicNs());
  if (core_.holding()) {
    process_->Subscribe<orbed::process_status_t>(
        channels::kProcessStatus, [this](const orbed::process_status_t& msg, const std::string&, int64_t) {
          if (!core_.holding() || msg.name != core_.options().hold_for ||
              msg.state != orbed::process_status_t::STATE_RUNNING)
            return;
          core_.HoldForRunning();
          MaybeRelease();
        });
    process_->AddTimer(5.0, [this] {
      if (core_.holding())
        ORBED_LOG(kInfo) << "holding the sim clock until " << core_.options().hold_for << " runs";
    });
  }
  const double tick_wall_s = 1e-9 * static_cast<double>(core_.tick_wall_ns());
  if (o.lockstep) {
    process_->Subscribe<orbed::sim_clock_ack_t>(
        channels::ForArm(channels::kSimClockAck, o.arm),
        [this](const orbed::sim_clock_ack_t& msg, const std::string& channel, int64_t) {
          OnAck(msg, channel);
        });
    // The ticks come from Advance(): from this poll and from each answer.
    process_->AddWallPoll(tick_wall_s, [this] {
      if (!core_.holding()) return Advance();
      // The held clock's rounds only let the followers join: at most kHeldRoundsHz.
      if (MonotonicS() - round_sent_s_ < 1.0 / kHeldRoundsHz) return;
      Tick();
    });
  } else {
    // Deadlines the loop skips (more than a few periods behind) are counted as "timer/tick" drops:
    // no IIWA_STATUS, ROBOT_STATE or COLLISION_STATUS went out for them.
    process_->AddTimer(
        tick_wall_s, [this] { Tick(); }, "tick");
  }
  ORBED_LOG(kInfo) << "robot " << o.urdf_path << " (" << core_.arm().num_joints() << " joints), scene "
                   << o.scene_path << ", tick " << o.period_s * 1e3 << " ms"
                   << ", " << o.steps_per_tick << " step(s) of " << core_.period_us() << " us per tick"
                   << (o.realtime_rate > 1
                           ? ", " + std::to_string(o.realtime_rate) + "x faster than real time"
                           : std::string())
                   << (o.lockstep ? ", in lockstep with the processes that follow its clock" : "");
}

IiwaSim::~IiwaSim() = default;

void IiwaSim::Reject(const std::string& channel, const Refusal& refusal) {
  process_->Reject(channel + "/" + refusal.key, refusal.reason);
}

void IiwaSim::Tick() {
  if (core_.holding()) return PublishClock(core_.start_utime());
  const ArmSim::TickResult tick = core_.Tick(MonotonicNs());
  if (tick.skipped_to_warn > 0) {
    ORBED_LOG(kWarn) << "the process loop skipped " << tick.skipped_to_warn << " tick(s) of "
                     << core_.tick_wall_ns() / 1000
                     << " us (stalled); the sim clock jumped to the current tick";
  }
  // The clock first: a process that follows it (--sim-time) runs its timers up to this tick while
  // it still holds the previous tick's state, as it would at real time.
  PublishClock(core_.NowUtime());
  if (!core_.options().lockstep) return PublishState(core_.NowUtime(), tick.closest);
  // Lockstep: round 1 is the clock alone (the followers' timers run on the previous tick's state).
  // The state opens round 2, after everything round 1 caused, so each follower handles it in the
  // same order relative to what the others sent.
  unpublished_state_ = tick.closest;
}

void IiwaSim::Advance() {
  if (core_.holding()) return;  // the held clock's rounds (the poll's) wait for nobody
  // Each pass either waits (returns) or sends something; with nobody to wait for, a round is
  // complete at once and the loop goes on to the next, up to the end of one tick per call (the
  // poll's pace).
  bool ticked = false;
  for (;;) {
    const double now_s = MonotonicS();
    if (round_ > 0) {
      const LockstepBarrier::Status status = barrier_.Check(now_s);
      for (const std::string& name : status.left_out) {
        process_->CountDrop("lockstep/" + name);
        ORBED_LOG(kWarn) << "lockstep: " << name << " did not answer round " << round_ << " of tick "
                         << core_.ticks() << " within " << core_.options().lockstep_timeout_s
                         << " s; going on without it until it answers again";
      }
      if (!status.complete) {
        // A lost SIM_CLOCK or answer: the round again (a follower answers a repeat as before).
        if (now_s - round_sent_s_ >= core_.options().lockstep_resend_s) {
          round_sent_s_ = now_s;
          process_->PublishControl(core_.options().sim_clock_channel,
                                   core_.SimClock(core_.NowUtime(), round_));
        }
        return;
      }
      // What the sim published during the round counts too (PLAN_CHECK_REPLY; the tick's state in
      // round 1): someone may still be handling it.
      bool published = process_->TakePublished();
      if (unpublished_state_) {
        PublishState(core_.NowUtime(), *unpublished_state_);
        unpublished_state_.reset();
        process_->TakePublished();  // the state is round 2's cause, the followers' answers its effects
        published = true;
      }
      if ((status.published || published) && round_ < kMaxLockstepRounds) {
        ++round_;
        PublishClock(core_.NowUtime());
        continue;
      }
      if (round_ >= kMaxLockstepRounds) {
        // Followers that keep answering each other would hold the arm for ever.
        process_->CountDrop("lockstep/rounds");
        ORBED_LOG(kWarn) << "lockstep: tick " << core_.ticks() << " still busy after " << round_
                         << " rounds; stepping on";
      }
    }
    // A quiet round: the next tick once its wall time has come.
    if (ticked || !core_.TickDue(MonotonicNs())) return;
    ticked = true;
    round_ = 1;
    Tick();
  }
}

void IiwaSim::MaybeRelease() {
  const std::vector<std::string> followers = barrier_.followers();
  const bool follows =
      std::find(followers.begin(), followers.end(), core_.options().hold_for) != followers.end();
  if (core_.Release(follows, MonotonicNs())) {
    ORBED_LOG(kInfo) << "the sim clock runs: " << core_.options().hold_for << " is running";
  }
}

void IiwaSim::OnAck(const orbed::sim_clock_ack_t& msg, const std::string& channel) {
  const std::string problem = CheckSimClockAck(msg);
  if (!problem.empty()) return process_->Reject(channel + "/field", problem);
  if (msg.start_utime != core_.start_utime()) return;  // a follower of another sim
  switch (barrier_.OnAck(msg)) {
    case LockstepBarrier::Answer::kJoined:
      ORBED_LOG(kInfo) << "lockstep: " << msg.process << " follows the clock";
      break;
    case LockstepBarrier::Answer::kUnsent:
      return process_->Reject(channel + "/unsent", "'" + msg.process + "' answers round " +
                                                       std::to_string(msg.lockstep_round) + " at " +
                                                       std::to_string(msg.utime) + ", which was not sent");
    case LockstepBarrier::Answer::kRefused:
      return process_->Reject(channel + "/followers", "more than " + std::to_string(kMaxLockstepFollowers) +
                                                          " followers; '" + msg.process +
                                                          "' is not waited for");
    case LockstepBarrier::Answer::kCounted:
    case LockstepBarrier::Answer::kOther:
      break;
  }
  MaybeRelease();
  Advance();
}

void IiwaSim::PublishClock(int64_t utime) {
  if (core_.options().sim_clock_channel.empty()) return;
  int32_t round = 0;
  if (core_.options().lockstep) {
    round = std::max<int32_t>(1, round_);
    round_sent_s_ = MonotonicS();
    barrier_.BeginRound(utime, core_.start_utime(), round, round_sent_s_);
  }
  process_->PublishControl(core_.options().sim_clock_channel, core_.SimClock(utime, round));
}

void IiwaSim::PublishState(int64_t utime, const CollisionResult& r) {
  const orbed::iiwa_status_t status = core_.IiwaStatus(utime);
  process_->Publish(core_.options().iiwa_status_channel, status);
  if (core_.ShouldSave(status)) {
    std::string error;
    if (WriteSimState(core_.options().state_file, status, &error)) {
      core_.Saved(status);
    } else {
      process_->SetLastError(error);
      if (save_failures_++ % 1000 == 0) ORBED_LOG(kError) << error << " (" << save_failures_ << " time(s))";
    }
  }
  process_->Publish(core_.options().robot_state_channel, core_.RobotState(utime));
  process_->Publish(core_.options().collision_status_channel, core_.CollisionStatus(utime, r));
}

}  // namespace orbed::sim
