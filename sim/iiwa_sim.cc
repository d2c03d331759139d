#include "sim/iiwa_sim.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <orbed/collision_status_t.hpp>
#include <orbed/iiwa_status_t.hpp>
#include <orbed/plan_check_reply_t.hpp>
#include <orbed/robot_state_t.hpp>

#include "base/format.h"
#include "base/log.h"
#include "lcmtypes/contract/conversions.h"
#include "lcmtypes/contract/requests.h"
#include "lcmtypes/contract/validation.h"
#include "sim/sim_state.h"

namespace orbed::sim {
namespace {

static_assert(static_cast<int>(MotionState::kIdle) == orbed::robot_state_t::MOTION_IDLE &&
                  static_cast<int>(MotionState::kMoving) == orbed::robot_state_t::MOTION_MOVING &&
                  static_cast<int>(MotionState::kStoppedAtLimit) ==
                      orbed::robot_state_t::MOTION_STOPPED_AT_LIMIT &&
                  static_cast<int>(MotionState::kStoppedBeforeCollision) ==
                      orbed::robot_state_t::MOTION_STOPPED_BEFORE_COLLISION &&
                  static_cast<int>(MotionState::kInCollision) == orbed::robot_state_t::MOTION_IN_COLLISION,
              "MotionState must number as robot_state_t::MOTION_*");

// Resolves default paths and checks every number before anything is loaded.
IiwaSimOptions Resolved(IiwaSimOptions options) {
  if (!options.arm.empty()) {
    // One of several arms: every channel of its own gets the arm's suffix.
    for (std::string* channel :
         {&options.iiwa_status_channel, &options.iiwa_command_channel, &options.robot_state_channel,
          &options.collision_status_channel, &options.plan_check_request_channel,
          &options.plan_check_reply_channel, &options.sim_clock_channel}) {
      if (!channel->empty()) *channel = channels::ForArm(*channel, options.arm);
    }
    if (options.robot_name == IiwaSimOptions{}.robot_name) options.robot_name = options.arm;
  }
  if (options.urdf_path.empty()) options.urdf_path = SourceTreePath(RobotModel::kDefaultUrdfRelativePath);
  if (options.scene_path.empty()) options.scene_path = SourceTreePath(kDefaultSceneRelativePath);
  // The sim clock counts whole microseconds (utime): the tick is P = period_s rounded to them, and
  // the arm steps by exactly P, so that stamps and steps agree.
  if (!(options.period_s > 0) || !(options.period_s <= 3600) || std::llround(options.period_s * 1e6) < 1) {
    throw std::invalid_argument(
        "--period-s must be a number of seconds in [1e-6, 3600] (it is rounded to "
        "whole microseconds)");
  }
  options.period_s = static_cast<double>(std::llround(options.period_s * 1e6)) / 1e6;
  if (!(options.stale_command_s >= 0) || !std::isfinite(options.stale_command_s)) {
    throw std::invalid_argument("--stale-command-s must be a finite number >= 0 (0 disables the check)");
  }
  if (!(options.stop_margin_m >= 0) || !std::isfinite(options.stop_margin_m)) {
    throw std::invalid_argument("--stop-margin-m must be a finite number >= 0");
  }
  if (!(options.report_distance_m >= 0) || !std::isfinite(options.report_distance_m)) {
    throw std::invalid_argument("--report-distance-m must be a finite number >= 0");
  }
  if (!(options.state_save_period_s > 0) || !std::isfinite(options.state_save_period_s)) {
    throw std::invalid_argument("--state-save-period-s must be a finite number > 0");
  }
  if (options.realtime_rate < 1 || options.realtime_rate > kMaxRealtimeRate) {
    throw std::invalid_argument("--realtime-rate must be a whole number in [1, " +
                                std::to_string(kMaxRealtimeRate) + "], not " +
                                std::to_string(options.realtime_rate));
  }
  if (options.steps_per_tick == 0) options.steps_per_tick = options.realtime_rate;
  if (options.steps_per_tick < 1 || options.steps_per_tick > kMaxStepsPerTick) {
    throw std::invalid_argument("--steps-per-tick must be a whole number in [1, " +
                                std::to_string(kMaxStepsPerTick) + "] (or 0: the realtime rate), not " +
                                std::to_string(options.steps_per_tick));
  }
  if (static_cast<int64_t>(options.steps_per_tick) * std::llround(options.period_s * 1e6) >
      kMaxSimClockStepUs) {
    throw std::invalid_argument("--steps-per-tick x --period-s must be at most " +
                                std::to_string(kMaxSimClockStepUs / 1'000'000) +
                                " s of sim time per tick (the largest step a follower's clock takes)");
  }
  if (options.lockstep && options.sim_clock_channel.empty()) {
    throw std::invalid_argument("--lockstep needs the sim clock channel (--sim-clock-channel)");
  }
  if (!(options.lockstep_resend_s > 0) || !std::isfinite(options.lockstep_resend_s)) {
    throw std::invalid_argument("the lockstep resend period must be a finite number > 0");
  }
  if (!(options.lockstep_timeout_s > 0) || !std::isfinite(options.lockstep_timeout_s)) {
    throw std::invalid_argument("--lockstep-timeout-s must be a finite number > 0");
  }
  return options;
}

double MonotonicS() {
  return 1e-9 * static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::steady_clock::now().time_since_epoch())
                                        .count());
}

Eigen::VectorXd InitialQ(const RobotModel& model, const std::vector<double>& q_deg) {
  if (q_deg.empty()) return Eigen::VectorXd::Zero(model.num_joints());
  if (static_cast<int>(q_deg.size()) != model.num_joints()) {
    throw std::invalid_argument("--initial-q-deg: expected " + std::to_string(model.num_joints()) +
                                " angles in deg, got " + std::to_string(q_deg.size()));
  }
  const Eigen::VectorXd q = DegToRad(ToVectorX(q_deg));
  const std::string why = model.ValidateJointVector(q);
  if (!why.empty()) throw std::invalid_argument("--initial-q-deg: " + why);
  return q;
}

orbed::contact_t ToContact(const PairDistance& pair) {
  orbed::contact_t c{};
  c.body_a = pair.body_a;
  c.body_b = pair.body_b;
  c.distance_m = pair.distance_m;
  FromVector3(pair.p_WA, c.p_WA_m);
  FromVector3(pair.p_WB, c.p_WB_m);
  FromVector3(pair.normal_W, c.normal_W);
  return c;
}

}  // namespace

IiwaSim::IiwaSim(const orbed::CommonFlags& flags, const IiwaSimOptions& options)
    : options_(Resolved(options)),
      scene_(LoadSceneFile(options_.scene_path)),
      period_us_(std::llround(options_.period_s * 1e6)),
      steps_per_tick_(options_.steps_per_tick),
      tick_us_(steps_per_tick_ * period_us_),
      tick_wall_ns_(std::max<int64_t>(1, tick_us_ * 1000 / options_.realtime_rate)),
      barrier_(options_.lockstep_timeout_s) {
  scene_.StandAt(options_.arm);
  const RobotModel model = LoadRobotForScene(options_.urdf_path, scene_);
  ManualArmOptions arm_options;
  arm_options.stop_margin_m = options_.stop_margin_m;
  arm_options.report_distance_m = options_.report_distance_m;
  std::optional<Eigen::VectorXd> q0;
  if (!options_.state_file.empty()) q0 = ReadSimState(options_.state_file, model);
  if (q0) {
    ORBED_LOG(kInfo) << "starting at the last measured configuration in " << options_.state_file;
  } else {
    q0 = InitialQ(model, options_.initial_q_deg);
  }
  arm_ = std::make_unique<ManualArm>(model, &scene_, *q0, arm_options);
  saved_q_ = FromVectorX(*q0);
  save_every_ticks_ =
      std::max<int64_t>(1, std::llround(options_.state_save_period_s * 1e6 / static_cast<double>(tick_us_)));
  for (int i = 0; i < model.num_links(); ++i) {
    if (!arm_->world().LinkPrimitives(i).empty() && std::isfinite(arm_->collision().link_clearance_m[i])) {
      reported_links_.push_back(i);
    }
  }
  if (arm_->collision().in_collision) {
    ORBED_LOG(kWarn) << "the initial joint vector is in collision: " << arm_->stop_reason();
  }

  process_ = std::make_unique<orbed::Process>(flags);
  if (!options_.arm.empty()) {
    // The other arms of the scene, wherever their ROBOT_STATE says they are.
    for (const ArmPlacement& other : scene_.arms) {
      if (other.name == options_.arm) continue;
      const int index = arm_->AddOtherArm(other.name, model);
      process_->Subscribe<orbed::robot_state_t>(
          channels::ForArm(channels::kRobotState, other.name),
          [this, index](const orbed::robot_state_t& msg, const std::string& channel, int64_t) {
            OnOtherArm(index, msg, channel);
          });
    }
  }
  process_->Subscribe<orbed::iiwa_command_t>(
      options_.iiwa_command_channel, [this](const orbed::iiwa_command_t& msg, const std::string& channel,
                                            int64_t) { OnCommand(msg, channel); });
  process_->Subscribe<orbed::plan_check_request_t>(
      options_.plan_check_request_channel,
      [this](const orbed::plan_check_request_t& msg, const std::string& channel, int64_t) {
        OnPlanCheck(msg, channel);
      });
  // The sim clock starts with the timer: tick k is due k * P after start_mono_ (after the hold, if
  // any, from the release).
  start_utime_ = NowMicros();
  start_mono_ = std::chrono::steady_clock::now();
  holding_ = !options_.hold_for.empty();
  if (holding_) {
    process_->Subscribe<orbed::process_status_t>(
        channels::kProcessStatus, [this](const orbed::process_status_t& msg, const std::string&, int64_t) {
          if (!holding_ || msg.name != options_.hold_for ||
              msg.state != orbed::process_status_t::STATE_RUNNING)
            return;
          hold_for_running_ = true;
          MaybeRelease();
        });
    process_->AddTimer(5.0, [this] {
      if (holding_) ORBED_LOG(kInfo) << "holding the sim clock until " << options_.hold_for << " runs";
    });
  }
  const double tick_wall_s = 1e-9 * static_cast<double>(tick_wall_ns_);
  if (options_.lockstep) {
    process_->Subscribe<orbed::sim_clock_ack_t>(
        channels::ForArm(channels::kSimClockAck, options_.arm),
        [this](const orbed::sim_clock_ack_t& msg, const std::string& channel, int64_t) {
          OnAck(msg, channel);
        });
    // The ticks come from Advance(): from this poll and from each answer.
    process_->AddWallPoll(tick_wall_s, [this] {
      if (!holding_) return Advance();
      // The held clock's rounds only let the followers join: at most kHeldRoundsHz.
      const double now_s = MonotonicS();
      if (now_s - round_sent_s_ < 1.0 / kHeldRoundsHz) return;
      Tick();
    });
  } else {
    // Deadlines the loop skips (more than a few periods behind) are counted as "timer/tick" drops:
    // no IIWA_STATUS, ROBOT_STATE or COLLISION_STATUS went out for them.
    process_->AddTimer(
        tick_wall_s, [this] { Tick(); }, "tick");
  }
  ORBED_LOG(kInfo) << "robot " << options_.urdf_path << " (" << model.num_joints() << " joints), scene "
                   << options_.scene_path << ", tick " << options_.period_s * 1e3 << " ms"
                   << ", " << steps_per_tick_ << " step(s) of " << period_us_ << " us per tick"
                   << (options_.realtime_rate > 1
                           ? ", " + std::to_string(options_.realtime_rate) + "x faster than real time"
                           : std::string())
                   << (options_.lockstep ? ", in lockstep with the processes that follow its clock" : "");
}

IiwaSim::~IiwaSim() = default;

void IiwaSim::OnCommand(const orbed::iiwa_command_t& msg, const std::string& channel) {
  const auto checked = CheckIiwaCommand(msg, arm_->num_joints());
  if (const auto* refusal = std::get_if<Refusal>(&checked)) {
    process_->Reject(channel + "/" + refusal->key, refusal->reason);
    return;
  }
  const IiwaCommand& command = std::get<IiwaCommand>(checked);
  if (options_.stale_command_s > 0) {
    // A sender stamps with the wall clock, or, following SIM_CLOCK (--sim-time), with the sim clock,
    // which at a realtime rate R runs R times as fast: its age is taken in wall seconds (sim ones / R).
    // In double: a wild utime (e.g. INT64_MIN) must not overflow the subtraction.
    const double wall_age_s = (static_cast<double>(NowMicros()) - static_cast<double>(msg.utime)) * 1e-6;
    const double sim_now_us = static_cast<double>(NowUtime());
    const double sim_age_s = (sim_now_us - static_cast<double>(msg.utime)) * 1e-6 / options_.realtime_rate;
    const double age_s = std::abs(sim_age_s) < std::abs(wall_age_s) ? sim_age_s : wall_age_s;
    if (std::abs(age_s) > options_.stale_command_s) {
      process_->Reject(channel + "/stale",
                       "utime " + std::to_string(msg.utime) + " is " + Fixed(std::abs(age_s), 3) + " s " +
                           (age_s > 0 ? "older than" : "ahead of") + " the wall and the sim clock (limit " +
                           Fixed(options_.stale_command_s, 3) + " s)");
      return;
    }
  }
  arm_->SetCommand(command.q_rad);
}

void IiwaSim::OnOtherArm(int index, const orbed::robot_state_t& msg, const std::string& channel) {
  const RobotModel& model = arm_->model();
  std::string problem = CheckRobotState(msg, model.num_joints());
  if (problem.empty() && msg.num_links != model.num_links()) {
    problem = "num_links " + std::to_string(msg.num_links) + ", expected " +
              std::to_string(model.num_links()) + " (the arms share one model)";
  }
  for (int i = 0; problem.empty() && i < msg.num_links; ++i) {
    problem = CheckPose(msg.X_RL[i], "X_RL[" + std::to_string(i) + "]");
  }
  if (!problem.empty()) {
    process_->Reject(channel + "/field", problem);
    return;
  }
  const Eigen::Isometry3d X_WR = FromPose(msg.X_WR);
  other_X_WL_.resize(msg.X_RL.size());
  for (size_t i = 0; i < msg.X_RL.size(); ++i) other_X_WL_[i] = X_WR * FromPose(msg.X_RL[i]);
  arm_->SetOtherArmLinkPoses(index, other_X_WL_);
}

void IiwaSim::OnPlanCheck(const orbed::plan_check_request_t& msg, const std::string& channel) {
  orbed::plan_check_reply_t reply{};
  reply.request_id = msg.request_id;
  const auto checked = CheckPlanCheckRequest(msg, arm_->num_joints());
  if (const auto* refusal = std::get_if<Refusal>(&checked)) {
    process_->Reject(channel + "/" + refusal->key, refusal->reason);
    reply.utime = NowMicros();
    reply.request_valid = false;
    reply.min_distance_m = std::nan("");
    reply.reason = "invalid request: " + refusal->reason;
    process_->Publish(options_.plan_check_reply_channel, reply);
    return;
  }
  const Eigen::VectorXd& q = std::get<PlanCheckRequest>(checked).q_rad;
  const std::string limits = arm_->model().ValidateJointVector(q);
  const CollisionResult r = arm_->Check(q);
  reply.request_valid = true;
  reply.within_limits = limits.empty();
  reply.in_collision = r.in_collision;
  reply.feasible = reply.within_limits && !reply.in_collision;
  reply.min_distance_m = r.min_distance_m;
  for (const PairDistance& pair : r.contacts) reply.pairs.push_back(ToContact(pair));
  if (reply.pairs.empty() && r.closest.valid()) reply.pairs.push_back(ToContact(r.closest));
  reply.num_pairs = static_cast<int32_t>(reply.pairs.size());
  if (!limits.empty()) reply.reason = "outside the limits: " + limits;
  if (r.in_collision) {
    if (!reply.reason.empty()) reply.reason += "; ";
    reply.reason += "in collision: " + r.closest.body_a + " vs " + r.closest.body_b + " penetrate by " +
                    Fixed(-r.closest.distance_m, 4) + " m";
  }
  reply.utime = NowMicros();
  process_->Publish(options_.plan_check_reply_channel, reply);
}

void IiwaSim::Tick() {
  if (holding_) return PublishClock(start_utime_);
  // COLLISION_STATUS reports the step of this tick that came closest to contact, so that the near
  // misses it shows do not depend on the steps per tick.
  arm_->Step(options_.period_s);
  CollisionResult closest = arm_->collision();
  for (int step = 1; step < steps_per_tick_; ++step) {
    arm_->Step(options_.period_s);
    if (arm_->collision().min_distance_m < closest.min_distance_m) closest = arm_->collision();
  }
  ++ticks_;
  const auto now = std::chrono::steady_clock::now();
  const int64_t elapsed_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(now - start_mono_).count();
  const int64_t due = elapsed_ns / tick_wall_ns_;
  if (options_.lockstep) {
    // Waiting for the followers is not a stall of the sim: its clock never skips. After a long
    // wait the pace starts again from now instead of rushing through the ticks it owes.
    if ((due - ticks_) * tick_wall_ns_ > MaxLagMicros() * 1000) {
      start_mono_ += std::chrono::nanoseconds((due - ticks_) * tick_wall_ns_);
    }
  } else if ((due - ticks_) * tick_wall_ns_ > MaxLagMicros() * 1000) {
    // After a stall the loop skipped deadlines rather than run them: tick k jumps to the last
    // deadline passed, so the sim clock does not fall behind for good. The arm made only this
    // tick's K steps of P: the speed read from the stamps only drops.
    skipped_ticks_ += due - ticks_;
    ticks_ = due;
    if (now - last_skip_warning_ >= std::chrono::seconds(10)) {
      ORBED_LOG(kWarn) << "the process loop skipped " << skipped_ticks_ << " tick(s) of "
                       << tick_wall_ns_ / 1000 << " us (stalled); the sim clock jumped to the current tick";
      skipped_ticks_ = 0;
      last_skip_warning_ = now;
    }
  }
  if (options_.lockstep) {
    // Round 1 is the clock alone: the followers' timers run on the previous tick's state. The state
    // opens round 2, after everything round 1 caused, so each follower handles it in the same order
    // relative to what the others sent.
    PublishClock(NowUtime());
    unpublished_state_ = closest;
    return;
  }
  PublishAll(NowUtime(), closest);
}

void IiwaSim::Advance() {
  if (holding_) return;  // the held clock's rounds (the poll's) wait for nobody
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
                         << ticks_ << " within " << options_.lockstep_timeout_s
                         << " s; going on without it until it answers again";
      }
      if (!status.complete) {
        // A lost SIM_CLOCK or answer: the round again (a follower answers a repeat as before).
        if (now_s - round_sent_s_ >= options_.lockstep_resend_s) {
          round_sent_s_ = now_s;
          ResendClock();
        }
        return;
      }
      // What the sim published during the round counts too (PLAN_CHECK_REPLY; the tick's state in
      // round 1): someone may still be handling it.
      bool published = process_->TakePublished();
      if (unpublished_state_) {
        PublishState(NowUtime(), *unpublished_state_);
        unpublished_state_.reset();
        process_->TakePublished();  // the state is round 2's cause, the followers' answers its effects
        published = true;
      }
      if ((status.published || published) && round_ < kMaxLockstepRounds) {
        ++round_;
        PublishClock(NowUtime());
        continue;
      }
      if (round_ >= kMaxLockstepRounds) {
        // Followers that keep answering each other would hold the arm for ever.
        process_->CountDrop("lockstep/rounds");
        ORBED_LOG(kWarn) << "lockstep: tick " << ticks_ << " still busy after " << round_
                         << " rounds; stepping on";
      }
    }
    // A quiet round: the next tick once its wall time has come (half a poll early: the poll's grid
    // and the ticks' are the same period, in some phase).
    const int64_t elapsed_ns =
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start_mono_)
            .count();
    if (ticked || elapsed_ns < (ticks_ + 1) * tick_wall_ns_ - tick_wall_ns_ / 2) return;
    ticked = true;
    round_ = 1;
    Tick();
  }
}

void IiwaSim::ResendClock() {
  orbed::sim_clock_t clock{};
  clock.utime = NowUtime();
  clock.realtime_rate = options_.realtime_rate;
  clock.start_utime = start_utime_;
  clock.lockstep_round = round_;
  process_->PublishControl(options_.sim_clock_channel, clock);
}

void IiwaSim::MaybeRelease() {
  // In lockstep the process held for must also have answered a round, so that the first tick's
  // rounds wait for it (a follower met during a round is not waited for in that round).
  if (!holding_ || !hold_for_running_) return;
  if (options_.lockstep) {
    const std::vector<std::string> followers = barrier_.followers();
    if (std::find(followers.begin(), followers.end(), options_.hold_for) == followers.end()) return;
  }
  holding_ = false;
  ticks_ = 0;
  start_mono_ = std::chrono::steady_clock::now();
  ORBED_LOG(kInfo) << "the sim clock runs: " << options_.hold_for << " is running";
}

void IiwaSim::OnAck(const orbed::sim_clock_ack_t& msg, const std::string& channel) {
  const std::string problem = CheckSimClockAck(msg);
  if (!problem.empty()) return process_->Reject(channel + "/field", problem);
  if (msg.start_utime != start_utime_) return;  // a follower of another sim
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

int64_t IiwaSim::MaxLagMicros() const { return std::max<int64_t>(100'000, 20 * period_us_); }

void IiwaSim::PublishClock(int64_t utime) {
  if (options_.sim_clock_channel.empty()) return;
  orbed::sim_clock_t clock{};
  clock.utime = utime;
  clock.realtime_rate = options_.realtime_rate;
  clock.start_utime = start_utime_;
  if (options_.lockstep) {
    clock.lockstep_round = std::max<int32_t>(1, round_);
    round_sent_s_ = MonotonicS();
    barrier_.BeginRound(utime, start_utime_, clock.lockstep_round, round_sent_s_);
  }
  process_->PublishControl(options_.sim_clock_channel, clock);
}

void IiwaSim::PublishAll(int64_t utime, const CollisionResult& r) {
  // The clock first: a process that follows it (--sim-time) runs its timers up to this tick while
  // it still holds the previous tick's state, as it would at real time.
  PublishClock(utime);
  PublishState(utime, r);
}

void IiwaSim::PublishState(int64_t utime, const CollisionResult& r) {
  const RobotModel& model = arm_->model();
  const int n = model.num_joints();
  const std::vector<double> q = FromVectorX(arm_->q_rad());

  orbed::iiwa_status_t status{};
  status.utime = utime;
  status.num_joints = n;
  status.joint_position_measured = q;
  status.joint_velocity_estimated = FromVectorX(arm_->velocity_rad_per_s());
  status.joint_position_commanded = FromVectorX(arm_->command_rad());
  status.joint_position_ipo = q;
  status.joint_torque_measured.assign(n, 0.0);
  status.joint_torque_commanded.assign(n, 0.0);
  status.joint_torque_external.assign(n, 0.0);
  process_->Publish(options_.iiwa_status_channel, status);
  SaveState(status);

  model.CalcLinkPoses(arm_->q_rad(), &X_RL_);
  orbed::robot_state_t state{};
  state.utime = utime;
  state.robot_name = options_.robot_name;
  state.X_WR = ToPose(scene_.X_WR);
  state.X_RF = ToPose(X_RL_[model.flange_link()]);
  state.X_RT = ToPose(X_RL_[model.tool_tip_link()]);
  state.num_joints = n;
  state.joint_position = q;
  for (int hit : arm_->LimitHits()) state.joint_limit_hit.push_back(static_cast<int8_t>(hit));
  state.num_links = model.num_links();
  for (int i = 0; i < model.num_links(); ++i) {
    state.link_names.push_back(model.links()[i].name);
    state.X_RL.push_back(ToPose(X_RL_[i]));
  }
  state.motion_state = static_cast<int8_t>(arm_->state());
  state.stop_reason = arm_->stop_reason();
  process_->Publish(options_.robot_state_channel, state);

  orbed::collision_status_t collision{};
  collision.utime = utime;
  collision.in_collision = r.in_collision;
  collision.min_distance_m = r.min_distance_m;
  for (const PairDistance& pair : r.contacts) collision.contacts.push_back(ToContact(pair));
  collision.num_contacts = static_cast<int32_t>(collision.contacts.size());
  for (int i : reported_links_) {
    collision.link_names.push_back(model.links()[i].name);
    collision.link_clearance_m.push_back(r.link_clearance_m[i]);
  }
  collision.num_links = static_cast<int32_t>(collision.link_names.size());
  collision.check_duration_us = static_cast<int64_t>(std::llround(arm_->collision_check_us()));
  process_->Publish(options_.collision_status_channel, collision);
}

void IiwaSim::SaveState(const orbed::iiwa_status_t& status) {
  if (options_.state_file.empty() || status.joint_position_measured == saved_q_) return;
  if (arm_->state() == MotionState::kMoving && ticks_ < next_save_tick_) return;
  std::string error;
  if (!WriteSimState(options_.state_file, status, &error)) {
    process_->SetLastError(error);
    if (save_failures_++ % 1000 == 0) ORBED_LOG(kError) << error << " (" << save_failures_ << " time(s))";
    return;
  }
  saved_q_ = status.joint_position_measured;
  next_save_tick_ = ticks_ + save_every_ticks_;
}

}  // namespace orbed::sim
