#include "sim/manual_arm.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "base/format.h"
#include "base/units.h"

namespace orbed::sim {
namespace {

constexpr double kLimitToleranceRad = 1e-9;

CollisionWorld::Options WorldOptions(const ManualArmOptions& options) {
  CollisionWorld::Options world;
  world.report_distance_m = options.report_distance_m;
  return world;  // the rest as `orbed-robot check`: every non-adjacent self pair, all scene pairs
}

}  // namespace

const char* MotionStateName(MotionState state) {
  switch (state) {
    case MotionState::kIdle:
      return "idle";
    case MotionState::kMoving:
      return "moving";
    case MotionState::kStoppedAtLimit:
      return "stopped at limit";
    case MotionState::kStoppedBeforeCollision:
      return "stopped before collision";
    case MotionState::kInCollision:
      return "in collision";
  }
  return "?";
}

ManualArm::ManualArm(const RobotModel& model, const Scene* scene, const Eigen::VectorXd& q0_rad,
                     const ManualArmOptions& options)
    : options_(options), world_(model, scene, WorldOptions(options)) {
  if (!(std::isfinite(options.stop_margin_m) && options.stop_margin_m >= 0)) {
    throw std::invalid_argument("stop margin must be a finite number >= 0 m");
  }
  if (!(std::isfinite(options.report_distance_m) && options.report_distance_m >= 0)) {
    throw std::invalid_argument("report distance must be a finite number >= 0 m");
  }
  if (options.bisection_steps < 0 || options.bisection_steps > 30) {
    throw std::invalid_argument("bisection steps must be in [0, 30]");
  }
  const int n = model.num_joints();
  if (q0_rad.size() != n) {
    throw std::invalid_argument("initial joint vector: expected " + std::to_string(n) + " values, got " +
                                std::to_string(q0_rad.size()));
  }
  const std::string why = model.ValidateJointVector(q0_rad);
  if (!why.empty()) throw std::invalid_argument("initial joint vector: " + why);
  lower_ = model.lower_limits_rad();
  upper_ = model.upper_limits_rad();
  v_max_ = model.velocity_limits_rad_per_s();
  q_ = q0_rad;
  v_ = Eigen::VectorXd::Zero(n);
  command_ = q0_rad;
  target_ = q0_rad;
  collision_ = TimedCheck(q_, &collision_check_us_);
  SetStateAfterStep(true);
  ApplyCollisionState();
}

void ManualArm::SetCommand(const Eigen::VectorXd& q_command_rad) {
  const int n = num_joints();
  if (q_command_rad.size() != n) {
    throw std::invalid_argument("command: expected " + std::to_string(n) + " joint values, got " +
                                std::to_string(q_command_rad.size()));
  }
  if (!q_command_rad.allFinite()) throw std::invalid_argument("command: non-finite joint value");
  command_ = q_command_rad;
  const Eigen::VectorXd target = q_command_rad.cwiseMax(lower_).cwiseMin(upper_);
  clamp_reason_.clear();
  for (int i = 0; i < n; ++i) {
    if (target[i] == q_command_rad[i]) continue;
    const bool upper = q_command_rad[i] > upper_[i];
    if (!clamp_reason_.empty()) clamp_reason_ += "; ";
    clamp_reason_ += model().joints()[i].name + " commanded " + Fixed(q_command_rad[i] * kRadToDeg, 1) +
                     " deg, stopped at its " + (upper ? "upper" : "lower") + " limit " +
                     Fixed((upper ? upper_[i] : lower_[i]) * kRadToDeg, 1) + " deg";
  }
  if (target != target_) blocked_ = false;  // a new target: the old refusal no longer applies
  target_ = target;
}

void ManualArm::Step(double period_s) {
  if (!(period_s > 0) || !std::isfinite(period_s)) throw std::invalid_argument("Step: period must be > 0 s");
  const Eigen::VectorXd q_before = q_;
  if (others_moved_) {
    // Another arm moved: the current q's distances changed, and so may a refusal.
    collision_ = TimedCheck(q_, &collision_check_us_);
    blocked_ = false;
    others_moved_ = false;
  }
  const Eigen::VectorXd delta = target_ - q_;
  if (delta.cwiseAbs().maxCoeff() == 0.0) {
    blocked_ = false;
    SetStateAfterStep(true);
  } else if (blocked_) {
    // Same q, same target, static scene: the refusal stands without another query.
    state_ = MotionState::kStoppedBeforeCollision;
    stop_reason_ = blocked_reason_;
  } else {
    // One factor for all joints: the fastest-limited joint moves at its limit, the rest in step.
    const double scale = (delta.cwiseAbs().array() / (v_max_.array() * period_s)).maxCoeff();
    // Round-off slack: a remainder of 1 + 1e-12 steps is taken as one step, not a full step plus a
    // sub-nanoradian one.
    const bool reaches_target = scale <= 1.0 + 1e-12;
    const Eigen::VectorXd step = reaches_target ? delta : Eigen::VectorXd(delta / scale);
    // Reaching the target lands on it exactly (a clamped joint sits exactly on its limit).
    const Eigen::VectorXd full =
        reaches_target ? target_ : Eigen::VectorXd((q_ + step).cwiseMax(lower_).cwiseMin(upper_));
    double check_us = 0;
    CollisionResult candidate = TimedCheck(full, &check_us);
    if (Allowed(candidate)) {
      q_ = full;
      collision_ = std::move(candidate);
      collision_check_us_ = check_us;
      SetStateAfterStep(reaches_target);
    } else {
      // Shorten the step: the largest fraction lo (a multiple of 2^-bisection_steps) that passes.
      double lo = 0.0, hi = 1.0;
      CollisionResult blocking = std::move(candidate), best;
      double best_us = 0;
      for (int k = 0; k < options_.bisection_steps; ++k) {
        const double mid = 0.5 * (lo + hi);
        const Eigen::VectorXd q_mid = (q_ + mid * step).cwiseMax(lower_).cwiseMin(upper_);
        CollisionResult r = TimedCheck(q_mid, &check_us);
        if (Allowed(r)) {
          lo = mid;
          best = std::move(r);
          best_us = check_us;
        } else {
          hi = mid;
          blocking = std::move(r);
        }
      }
      if (lo > 0) {
        q_ = (q_ + lo * step).cwiseMax(lower_).cwiseMin(upper_);
        collision_ = std::move(best);
        collision_check_us_ = best_us;
      } else {
        blocked_ = true;
      }
      blocked_reason_ = CollisionReason(blocking);
      state_ = MotionState::kStoppedBeforeCollision;
      stop_reason_ = blocked_reason_;
    }
  }
  v_ = (q_ - q_before) / period_s;
  ApplyCollisionState();
}

void ManualArm::ApplyCollisionState() {
  if (!collision_.in_collision) return;
  state_ = MotionState::kInCollision;
  const PairDistance& c = collision_.closest;
  stop_reason_ =
      "in collision: " + c.body_a + " vs " + c.body_b + " penetrate by " + Fixed(-c.distance_m, 4) + " m";
}

std::vector<int> ManualArm::LimitHits() const {
  std::vector<int> hits(num_joints(), 0);
  for (int i = 0; i < num_joints(); ++i) {
    if (q_[i] <= lower_[i] + kLimitToleranceRad) hits[i] = -1;
    if (q_[i] >= upper_[i] - kLimitToleranceRad) hits[i] = +1;
  }
  return hits;
}

CollisionResult ManualArm::TimedCheck(const Eigen::VectorXd& q, double* duration_us) {
  const auto start = std::chrono::steady_clock::now();
  CollisionResult r = world_.Check(q);
  *duration_us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  ++num_checks_;
  return r;
}

bool ManualArm::Allowed(const CollisionResult& candidate) const {
  return candidate.min_distance_m >= options_.stop_margin_m ||
         candidate.min_distance_m >= collision_.min_distance_m - kDistanceEpsilonM;
}

void ManualArm::SetStateAfterStep(bool at_target) {
  if (!at_target) {
    state_ = MotionState::kMoving;
    stop_reason_.clear();
  } else if (!clamp_reason_.empty()) {
    state_ = MotionState::kStoppedAtLimit;
    stop_reason_ = clamp_reason_;
  } else {
    state_ = MotionState::kIdle;
    stop_reason_.clear();
  }
}

std::string ManualArm::CollisionReason(const CollisionResult& blocked) const {
  const PairDistance& c = blocked.closest;
  return "stopped before collision: " + c.body_a + " vs " + c.body_b + (c.self ? " (self)" : "") +
         " would come within " + Fixed(c.distance_m, 4) + " m (stop margin " +
         Fixed(options_.stop_margin_m, 4) + " m; now " + Fixed(collision_.min_distance_m, 4) + " m)";
}

}  // namespace orbed::sim
