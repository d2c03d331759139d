#pragma once
/// @file
/// Joint-by-joint set-up guidance (paper Sec. II-B, Fig. 4 c-e): the assistant moves the real arm,
/// one joint after the other from the base (joint 1) to the flange, until it matches the target
/// configuration the virtual robot shows. The core, without a bus or a clock:
///
///   error_deg[i]  = (current[i] − target[i]) in degrees (the sign says which way to turn back);
///   next_joint    = the first joint, base to flange, with |error_deg| > tolerance_deg; −1 when none;
///   done          = next_joint == −1.
///   joint_kind[i] = JOINT_TWIST when the joint's axis runs along its link (it turns the arm about
///                   itself: iiwa joints 1, 3, 5, 7), else JOINT_REVOLVE (it swings the arm: 2, 4, 6);
///                   from the model's geometry at q = 0: the axis against the direction from the
///                   joint to the next joint origin down the arm that is not at the same place (the
///                   iiwa's joints 2/3, 4/5 and 6/7 share origins), else to the tool tip; twisting
///                   when the angle between the two lines is below kTwistAngleDeg.
///
/// Frames: joint angles are the URDF's [rad]; the axis and link directions are compared in the base
/// frame R. Threading: pure functions; GuidanceCore is a value.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <orbed/guidance_t.hpp>
#include <orbed/setup_result_t.hpp>
#include <orbed/setup_task_t.hpp>

#include "sim/robot_model.h"

namespace orbed::guidance {

/// A joint axis within this angle of its link's direction twists [deg].
inline constexpr double kTwistAngleDeg = 15.0;

/// JOINT_TWIST or JOINT_REVOLVE for each actuated joint (see the file comment).
std::vector<int8_t> JointKinds(const sim::RobotModel& model);

/// "ar" | "ar_reflective" | "fixed" → guidance_t::MODE_*; throws std::invalid_argument naming the
/// accepted names otherwise.
int8_t GuidanceModeFromName(const std::string& name);
const char* GuidanceModeName(int8_t mode);

struct GuidanceTarget {
  int8_t mode{orbed::guidance_t::MODE_AR};
  Eigen::VectorXd q_target_rad;
  /// A joint within this of its target is done [deg].
  double tolerance_deg{1.0};
};

/// Target `number` (1-based) of a plan written by `orbed-robot plan` (JSON: {"targets": [{"q_deg":
/// [...]}, ...]}) [rad]. Read as outside input (base/json_fields.h: at most 1 MB, 20 targets,
/// num_joints finite angles in [−360, 360] deg); throws std::runtime_error naming the file, the key
/// and what was expected, or the number when the plan has fewer targets. Joint limits are the
/// GuidanceCore's check.
Eigen::VectorXd ReadPlanTarget(const std::string& path, int number, int num_joints);

/// The check of a GUIDANCE message its readers make (the one definition): num_joints equal to the
/// model's, mode and joint kinds in range, next_joint in [-1, num_joints), target and current joint
/// vectors finite and within the joint limits (+ slack_rad). Returns "" or a one-line reason naming
/// the field.
std::string CheckGuidance(const orbed::guidance_t& msg, const sim::RobotModel& model, double slack_rad);

/// The checks of the set-up study's messages (setup_task_t, setup_result_t), one definition each:
/// request_id != 0, task_id of 1 ... 256 bytes, mode in range, num_joints equal to the model's, joint
/// vectors within the joint limits (+ slack_rad); the result also ranges >= 0 and finite
/// execution_s and person_scale >= 0. Returns "" or a one-line reason naming the field.
std::string CheckSetupTask(const orbed::setup_task_t& msg, const sim::RobotModel& model, double slack_rad);
std::string CheckSetupResult(const orbed::setup_result_t& msg, const sim::RobotModel& model,
                             double slack_rad);

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
