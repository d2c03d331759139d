#pragma once
/// @file
/// Joint-by-joint set-up guidance (paper Sec. II-B, Fig. 4 c-e): the assistant moves the real arm,
/// one joint after the other from the base (joint 1) to the flange, until it matches the target
/// configuration the virtual robot shows. The core, without a bus or a clock:
///
///   error_deg[i]  = (current[i] − target[i]) in degrees (the sign says which way to turn back);
///   next_joint    = the first joint, base to flange, with |error_deg| > tolerance_deg; −1 when none;
///   done          = next_joint == −1.
///   joint_kind[i] = JointKinds(model)[i]: twisting or revolving (sim/guidance_messages.h, with the
///                   mode names, the plan reader and the checks of the set-up messages).
///
/// Frames: joint angles are the URDF's [rad]; the axis and link directions are compared in the base
/// frame R. Threading: pure functions; GuidanceCore is a value.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <orbed/guidance_t.hpp>

#include "sim/guidance_messages.h"
#include "sim/robot_model.h"

namespace orbed::guidance {

struct GuidanceTarget {
  int8_t mode{orbed::guidance_t::MODE_AR};
  Eigen::VectorXd q_target_rad;
  /// A joint within this of its target is done [deg].
  double tolerance_deg{1.0};
};

class GuidanceCore {
 public:
  /// Throws std::invalid_argument when the target has the wrong size, lies outside the joint limits,
  /// or the mode or tolerance is out of range (tolerance in (0, 90] deg).
  GuidanceCore(const sim::RobotModel& model, GuidanceTarget target);

  /// GUIDANCE for the arm at q_rad (num_joints values, already checked), stamped `utime`.
  orbed::guidance_t Compute(const Eigen::VectorXd& q_rad, int64_t utime) const;

  const GuidanceTarget& target() const { return target_; }
  const std::vector<int8_t>& joint_kinds() const { return kinds_; }

 private:
  GuidanceTarget target_;
  std::vector<int8_t> kinds_;
};

}  // namespace orbed::guidance
