#pragma once
/// @file
/// The arm of orbed-iiwa-sim as a hand-guided iiwa in manual mode, without any bus: it holds the
/// joint vector q, a commanded target, and moves toward the target one tick at a time.
///
/// Motion law, per Step(period_s):
///   - Synchronised, straight in joint space: the whole remaining move delta = target - q is scaled
///     by one factor so that no joint exceeds its URDF velocity limit over the tick,
///       step = delta / max(1, max_i |delta_i| / (v_max_i * period_s)),
///     so every joint arrives at once and the arm follows the straight joint-space segment from the
///     current q to the target (the path `orbed-robot check` can be asked about point by point).
///     (A remainder within 1e-12 of one step is taken whole: steps are bounded by v_max * period_s
///     to that relative round-off.) The step is bounded by the nominal period, never by the time
///     actually elapsed, so a late tick cannot make a larger step.
///   - Joint limits: SetCommand() clamps the command into [lower, upper] of each joint; the arm
///     stops on the limit and reports kStoppedAtLimit naming the joint(s). The start and the target
///     are inside the limit box, so the whole segment is.
///   - Collisions: the candidate next q is checked with CollisionWorld (self pairs on non-adjacent
///     bodies + every robot-scene pair: the policy of `orbed-robot check`). The step is refused when
///     the candidate's minimum distance is below `stop_margin_m` AND smaller than the current one
///     (moving away from, or parallel to, a close pair stays allowed, so a stopped arm can always be
///     guided back out). A refused step is shortened by bisection (`bisection_steps` halvings of the
///     step) to the largest fraction that passes, so the arm comes to rest close to the margin
///     rather than up to one full step before it; state kStoppedBeforeCollision with the pair named.
///     Invariant: once below the margin the minimum distance never decreases (by more than
///     kDistanceEpsilonM per tick, round-off of the distance query); an arm that starts collision-free
///     never touches anything.
///   - A blocked arm with an unchanged target re-checks nothing (same q, static scene: same answer).
///     Likewise collision() is the query of the current q, made when the arm moved there; an arm at
///     rest is not re-queried every tick. Other arms (several arms) are not static: after their poses
///     change, the next Step re-queries the current q and lifts a refusal.
///
/// Frames: q and limits in the joint space of RobotModel (rad); the collision world in the scene
/// frame W (X_WR from the scene). Units: m, rad, rad/s, s.
///
/// Threading: not thread-safe (CollisionWorld is not); own it from one thread.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "sim/collision_world.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::sim {

struct ManualArmOptions {
  /// Refuse steps that bring the minimum distance below this (and lower than it is) [m], >= 0.
  double stop_margin_m{0.01};
  /// Pairs closer than this are listed in CollisionResult::contacts [m], >= 0.
  double report_distance_m{0.05};
  /// Halvings tried on a refused step; 0 = all or nothing.
  int bisection_steps{6};
};

/// Numbered as orbed::robot_state_t::MOTION_* (the sim copies the value into the message).
enum class MotionState : int {
  kIdle = 0,                    ///< at the target (or no command yet)
  kMoving = 1,                  ///< took a full step toward the target this tick
  kStoppedAtLimit = 2,          ///< at the target, which was clamped to a joint limit
  kStoppedBeforeCollision = 3,  ///< the step was refused or shortened by the stop margin
  kInCollision = 4,             ///< the current q penetrates (e.g. started in collision)
};
const char* MotionStateName(MotionState state);

class ManualArm {
 public:
  /// Distances may decrease by this much below the margin without counting as "decreasing" [m]
  /// (round-off of re-posing an unchanged pair).
  static constexpr double kDistanceEpsilonM = 1e-9;

  /// `model` should carry the scene's tool length already; `scene` may be null (self-collision
  /// only) and is copied. Throws std::invalid_argument on a q0_rad of the wrong size, non-finite or
  /// outside the limits (the message names the joint), or on bad options.
  ManualArm(const RobotModel& model, const Scene* scene, const Eigen::VectorXd& q0_rad,
            const ManualArmOptions& options);

  /// New target (any finite vector of num_joints(); out-of-limit joints are clamped). Throws
  /// std::invalid_argument on a wrong size or a non-finite entry.
  void SetCommand(const Eigen::VectorXd& q_command_rad);

  /// One tick of `period_s` (> 0) seconds: moves, checks, updates state, velocity and collision.
  void Step(double period_s);

  /// Several arms: another arm in the OR, checked against this one from its first
  /// SetOtherArmLinkPoses on (CollisionWorld::AddOtherArm). Returns its index.
  int AddOtherArm(const std::string& name, const RobotModel& other) {
    return world_.AddOtherArm(name, other);
  }
  /// Where the other arm's links are now (X_WL per link of its model). If anything moved (or these
  /// are its first poses), the next Step() checks the current q afresh (collision() follows the other arm
  /// even while this one rests) and lifts a refusal, since the obstacle moved. Throws as
  /// CollisionWorld::SetOtherArmLinkPoses.
  void SetOtherArmLinkPoses(int arm, const std::vector<Eigen::Isometry3d>& X_WL) {
    if (world_.SetOtherArmLinkPoses(arm, X_WL)) others_moved_ = true;
  }

  /// Fresh collision check of any joint vector (for plan checks); does not move the arm.
  CollisionResult Check(const Eigen::VectorXd& q_rad) { return world_.Check(q_rad); }

  const RobotModel& model() const { return world_.model(); }
  const CollisionWorld& world() const { return world_; }
  int num_joints() const { return model().num_joints(); }
  const Eigen::VectorXd& q_rad() const { return q_; }
  /// (q after the last Step - q before it) / period [rad/s]; zero before the first Step.
  const Eigen::VectorXd& velocity_rad_per_s() const { return v_; }
  /// The last command as given (unclamped); q0 before any command.
  const Eigen::VectorXd& command_rad() const { return command_; }
  /// The command clamped into the limits: where the arm is going.
  const Eigen::VectorXd& target_rad() const { return target_; }
  MotionState state() const { return state_; }
  /// Why the arm is short of its command ("" while idle at the command or moving).
  const std::string& stop_reason() const { return stop_reason_; }
  /// Collision state of q_rad() and the time its check took [us].
  const CollisionResult& collision() const { return collision_; }
  double collision_check_us() const { return collision_check_us_; }
  /// Per joint: -1 on the lower limit, +1 on the upper, 0 inside (within 1e-9 rad).
  std::vector<int> LimitHits() const;
  /// Number of collision queries made so far (for tests and benchmarks).
  int64_t num_checks() const { return num_checks_; }

 private:
  CollisionResult TimedCheck(const Eigen::VectorXd& q, double* duration_us);
  bool Allowed(const CollisionResult& candidate) const;
  void SetStateAfterStep(bool at_target);
  void ApplyCollisionState();  // kInCollision overrides any other state
  std::string CollisionReason(const CollisionResult& blocked) const;

  ManualArmOptions options_;
  CollisionWorld world_;
  Eigen::VectorXd lower_, upper_, v_max_;
  Eigen::VectorXd q_, v_, command_, target_;
  std::string clamp_reason_;  // non-empty when the target was clamped
  bool blocked_{false};       // the last step was refused entirely and the target is unchanged
  bool others_moved_{false};  // another arm's poses changed since the last Step
  std::string blocked_reason_;
  MotionState state_{MotionState::kIdle};
  std::string stop_reason_;
  CollisionResult collision_;
  double collision_check_us_{0};
  int64_t num_checks_{0};
};

}  // namespace orbed::sim
