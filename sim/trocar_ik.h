#pragma once
/// @file
/// Inverse kinematics for docking the tool at a trocar: the tool tip T at the docking point and the
/// tool axis (+z of T) along the insertion direction. That is a 5-dof task (the roll about the tool
/// axis is free), so a 7-joint arm keeps a 2-dimensional self-motion (the elbow's swivel and the tool
/// roll); the solver spends it on maximising a caller-given clearance.
///
/// Method: damped least squares (Levenberg-Marquardt style) on the 5-row task Jacobian from many
/// seeded random starts within the joint limits; each converged solution is scored with the
/// clearance function; the best few are improved by a pattern search along the null space of the
/// task Jacobian, re-projected onto the task after each step, never leaving the joint limits. The
/// result is the best solution found, with its residuals; success is reported only if the residuals
/// are within tolerance and the clearance is above Options::min_clearance_m. Deterministic for a
/// given Options::seed.
///
/// Frames: everything is in the robot base frame R; units m and rad. Threading: reentrant (the
/// clearance function is called on the caller's thread).

#include <cstdint>
#include <functional>
#include <string>

#include <Eigen/Core>

#include "sim/robot_model.h"

namespace orbed::sim {

struct TrocarIkTarget {
  Eigen::Vector3d p_RT{Eigen::Vector3d::Zero()};      ///< wanted tool tip position [m]
  Eigen::Vector3d axis_R{-Eigen::Vector3d::UnitZ()};  ///< wanted tool axis, unit
};

struct TrocarIkOptions {
  int num_seeds{48};
  uint64_t seed{1};
  double position_tolerance_m{1e-5};
  double angle_tolerance_rad{1e-4};
  /// Solutions keep this far inside every joint limit [rad].
  double limit_margin_rad{0.01};
  int max_iterations{200};      ///< per projection onto the task
  int refine_best{4};           ///< how many distinct solutions the pattern search improves
  int max_refine_steps{80};     ///< accepted + rejected pattern steps per solution
  double min_clearance_m{0.0};  ///< a solution must have clearance above this
};

struct TrocarIkResult {
  bool success{false};
  std::string message;         ///< why it failed, or a one-line summary
  Eigen::VectorXd q_rad;       ///< best solution found (empty if none converged)
  double position_error_m{0};  ///< |p_RT(q) - p_RT*|
  double angle_error_rad{0};   ///< angle between the tool axis and axis_R
  double clearance_m{0};       ///< the clearance function at q_rad
  int seeds_tried{0};
  int seeds_converged{0};
};

/// Larger is better; <= 0 means in collision.
using ClearanceFunction = std::function<double(const Eigen::VectorXd& q_rad)>;

/// Solves; a null `clearance` scores every solution 0 (and then min_clearance_m must be < 0 for
/// success). Throws std::invalid_argument on a non-unit axis or non-finite target.
TrocarIkResult SolveTrocarIk(const RobotModel& model, const TrocarIkTarget& target,
                             const TrocarIkOptions& options, const ClearanceFunction& clearance);

/// Task residuals of q: position error [m] and axis angle error [rad].
void TrocarIkResiduals(const RobotModel& model, const TrocarIkTarget& target, const Eigen::VectorXd& q_rad,
                       double* position_error_m, double* angle_error_rad);

}  // namespace orbed::sim
