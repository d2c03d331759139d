#include "sim/arm_sim.h"

#include <cmath>
#include <stdexcept>

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

// Resolves default paths and checks every number before anything is loaded.
IiwaSimOptions ResolveIiwaSimOptions(IiwaSimOptions options) {
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

ArmSim::ArmSim(const IiwaSimOptions& options)
    : options_(ResolveIiwaSimOptions(options)),
      scene_(LoadSceneFile(options_.scene_path)),
      period_us_(std::llround(options_.period_s * 1e6)),
      tick_us_(options_.steps_per_tick * period_us_),
      tick_wall_ns_(std::max<int64_t>(1, tick_us_ * 1000 / options_.realtime_rate)) {
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
  // The other arms of the scene, wherever their ROBOT_STATE will say they are.
  if (!options_.arm.empty()) {
    for (const ArmPlacement& other : scene_.arms) {
      if (other.name != options_.arm)
        other_arms_.push_back({arm_->AddOtherArm(other.name, model), other.name});
    }
  }
}

void ArmSim::Start(int64_t start_utime, int64_t mono_ns) {
  start_utime_ = start_utime;
  start_mono_ns_ = mono_ns;
  holding_ = !options_.hold_for.empty();
}

std::optional<Refusal> ArmSim::AcceptCommand(const orbed::iiwa_command_t& msg, int64_t wall_now_us) {
  const auto checked = CheckIiwaCommand(msg, arm_->num_joints());
  if (const auto* refusal = std::get_if<Refusal>(&checked)) return *refusal;
  if (options_.stale_command_s > 0) {
    // A sender stamps with the wall clock, or, following SIM_CLOCK (--sim-time), with the sim clock,
    // which at a realtime rate R runs R times as fast: its age is taken in wall seconds (sim ones / R).
    // In double: a wild utime (e.g. INT64_MIN) must not overflow the subtraction.
    const double wall_age_s = (static_cast<double>(wall_now_us) - static_cast<double>(msg.utime)) * 1e-6;
    const double sim_now_us = static_cast<double>(NowUtime());
    const double sim_age_s = (sim_now_us - static_cast<double>(msg.utime)) * 1e-6 / options_.realtime_rate;
    const double age_s = std::abs(sim_age_s) < std::abs(wall_age_s) ? sim_age_s : wall_age_s;
    if (std::abs(age_s) > options_.stale_command_s) {
      return Refusal{"stale", "utime " + std::to_string(msg.utime) + " is " + Fixed(std::abs(age_s), 3) +
                                  " s " + (age_s > 0 ? "older than" : "ahead of") +
                                  " the wall and the sim clock (limit " + Fixed(options_.stale_command_s, 3) +
                                  " s)"};
    }
  }
  arm_->SetCommand(std::get<IiwaCommand>(checked).q_rad);
  return std::nullopt;
}

std::optional<Refusal> ArmSim::AcceptOtherArm(int index, const orbed::robot_state_t& msg) {
  const RobotModel& model = arm_->model();
  std::string problem = CheckRobotState(msg, model.num_joints());
  if (problem.empty() && msg.num_links != model.num_links()) {
    problem = "num_links " + std::to_string(msg.num_links) + ", expected " +
              std::to_string(model.num_links()) + " (the arms share one model)";
  }
  for (int i = 0; problem.empty() && i < msg.num_links; ++i) {
    problem = CheckPose(msg.X_RL[i], "X_RL[" + std::to_string(i) + "]");
  }
  if (!problem.empty()) return Refusal{"field", problem};
  const Eigen::Isometry3d X_WR = FromPose(msg.X_WR);
  other_X_WL_.resize(msg.X_RL.size());
  for (size_t i = 0; i < msg.X_RL.size(); ++i) other_X_WL_[i] = X_WR * FromPose(msg.X_RL[i]);
  arm_->SetOtherArmLinkPoses(index, other_X_WL_);
  return std::nullopt;
}

orbed::plan_check_reply_t ArmSim::PlanCheckReply(const orbed::plan_check_request_t& msg, int64_t wall_now_us,
                                                 std::optional<Refusal>* refusal) const {
  orbed::plan_check_reply_t reply{};
  reply.request_id = msg.request_id;
  reply.utime = wall_now_us;
  const auto checked = CheckPlanCheckRequest(msg, arm_->num_joints());
  if (const auto* refused = std::get_if<Refusal>(&checked)) {
    *refusal = *refused;
    reply.request_valid = false;
    reply.min_distance_m = std::nan("");
    reply.reason = "invalid request: " + refused->reason;
    return reply;
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
  return reply;
}

ArmSim::TickResult ArmSim::Tick(int64_t mono_ns) {
  // COLLISION_STATUS reports the step of this tick that came closest to contact, so that the near
  // misses it shows do not depend on the steps per tick.
  TickResult result;
  arm_->Step(options_.period_s);
  result.closest = arm_->collision();
  for (int step = 1; step < options_.steps_per_tick; ++step) {
    arm_->Step(options_.period_s);
    if (arm_->collision().min_distance_m < result.closest.min_distance_m) result.closest = arm_->collision();
  }
  ++ticks_;
  const int64_t due = (mono_ns - start_mono_ns_) / tick_wall_ns_;
  if ((due - ticks_) * tick_wall_ns_ <= MaxLagMicros() * 1000) return result;
  if (options_.lockstep) {
    // Waiting for the followers is not a stall of the sim: its clock never skips. After a long
    // wait the pace starts again from now instead of rushing through the ticks it owes.
    start_mono_ns_ += (due - ticks_) * tick_wall_ns_;
    return result;
  }
  // After a stall the loop skipped deadlines rather than run them: tick k jumps to the last
  // deadline passed, so the sim clock does not fall behind for good. The arm made only this
  // tick's K steps of P: the speed read from the stamps only drops.
  skipped_ticks_ += due - ticks_;
  ticks_ = due;
  if (!last_skip_warning_ns_ || mono_ns - *last_skip_warning_ns_ >= 10'000'000'000) {
    result.skipped_to_warn = skipped_ticks_;
    skipped_ticks_ = 0;
    last_skip_warning_ns_ = mono_ns;
  }
  return result;
}

bool ArmSim::TickDue(int64_t mono_ns) const {
  // Half a tick early: the poll's grid and the ticks' are the same period, in some phase.
  return mono_ns - start_mono_ns_ >= (ticks_ + 1) * tick_wall_ns_ - tick_wall_ns_ / 2;
}

bool ArmSim::Release(bool hold_for_follows, int64_t mono_ns) {
  // In lockstep the process held for must also have answered a round, so that the first tick's
  // rounds wait for it (a follower met during a round is not waited for in that round).
  if (!holding_ || !hold_for_running_ || (options_.lockstep && !hold_for_follows)) return false;
  holding_ = false;
  ticks_ = 0;
  start_mono_ns_ = mono_ns;
  return true;
}

orbed::iiwa_status_t ArmSim::IiwaStatus(int64_t utime) const {
  const int n = arm_->num_joints();
  orbed::iiwa_status_t status{};
  status.utime = utime;
  status.num_joints = n;
  status.joint_position_measured = FromVectorX(arm_->q_rad());
  status.joint_velocity_estimated = FromVectorX(arm_->velocity_rad_per_s());
  status.joint_position_commanded = FromVectorX(arm_->command_rad());
  status.joint_position_ipo = status.joint_position_measured;
  status.joint_torque_measured.assign(n, 0.0);
  status.joint_torque_commanded.assign(n, 0.0);
  status.joint_torque_external.assign(n, 0.0);
  return status;
}

orbed::robot_state_t ArmSim::RobotState(int64_t utime) {
  const RobotModel& model = arm_->model();
  model.CalcLinkPoses(arm_->q_rad(), &X_RL_);
  orbed::robot_state_t state{};
  state.utime = utime;
  state.robot_name = options_.robot_name;
  state.X_WR = ToPose(scene_.X_WR);
  state.X_RF = ToPose(X_RL_[model.flange_link()]);
  state.X_RT = ToPose(X_RL_[model.tool_tip_link()]);
  state.num_joints = model.num_joints();
  state.joint_position = FromVectorX(arm_->q_rad());
  for (int hit : arm_->LimitHits()) state.joint_limit_hit.push_back(static_cast<int8_t>(hit));
  state.num_links = model.num_links();
  for (int i = 0; i < model.num_links(); ++i) {
    state.link_names.push_back(model.links()[i].name);
    state.X_RL.push_back(ToPose(X_RL_[i]));
  }
  state.motion_state = static_cast<int8_t>(arm_->state());
  state.stop_reason = arm_->stop_reason();
  return state;
}

orbed::collision_status_t ArmSim::CollisionStatus(int64_t utime, const CollisionResult& r) const {
  orbed::collision_status_t collision{};
  collision.utime = utime;
  collision.in_collision = r.in_collision;
  collision.min_distance_m = r.min_distance_m;
  for (const PairDistance& pair : r.contacts) collision.contacts.push_back(ToContact(pair));
  collision.num_contacts = static_cast<int32_t>(collision.contacts.size());
  for (int i : reported_links_) {
    collision.link_names.push_back(arm_->model().links()[i].name);
    collision.link_clearance_m.push_back(r.link_clearance_m[i]);
  }
  collision.num_links = static_cast<int32_t>(collision.link_names.size());
  collision.check_duration_us = static_cast<int64_t>(std::llround(arm_->collision_check_us()));
  return collision;
}

orbed::sim_clock_t ArmSim::SimClock(int64_t utime, int32_t round) const {
  orbed::sim_clock_t clock{};
  clock.utime = utime;
  clock.realtime_rate = options_.realtime_rate;
  clock.start_utime = start_utime_;
  clock.lockstep_round = round;
  return clock;
}

bool ArmSim::ShouldSave(const orbed::iiwa_status_t& status) const {
  if (options_.state_file.empty() || status.joint_position_measured == saved_q_) return false;
  return arm_->state() != MotionState::kMoving || ticks_ >= next_save_tick_;
}

void ArmSim::Saved(const orbed::iiwa_status_t& status) {
  saved_q_ = status.joint_position_measured;
  next_save_tick_ = ticks_ + save_every_ticks_;
}

}  // namespace orbed::sim
