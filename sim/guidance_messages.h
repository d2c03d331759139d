#pragma once
/// @file
/// The set-up messages' one definition each, for every process that reads them (orbed-guidance,
/// orbed-assistant, orbed-setup, orbed-drake-viewer, ...): the guidance modes' names, which joints
/// twist, the reader of `orbed-robot plan`'s targets, and the checks of GUIDANCE, SETUP_TASK and
/// SETUP_RESULT against a robot model. Here in
/// sim/ (beside the check of IIWA_STATUS) because they need the model, and no process may include
/// another's code.
///
/// Joint kinds: JOINT_TWIST when the joint's axis runs along its link (it turns the arm about
/// itself: iiwa joints 1, 3, 5, 7), else JOINT_REVOLVE (it swings the arm: 2, 4, 6); from the
/// model's geometry at q = 0: the axis against the direction from the joint to the next joint origin
/// down the arm that is not at the same place (the iiwa's joints 2/3, 4/5 and 6/7 share origins),
/// else to the tool tip; twisting when the angle between the two lines is below kTwistAngleDeg.
///
/// Namespace orbed::guidance (the messages' subject). Threading: pure functions.

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

/// Target `number` (1-based) of a plan written by `orbed-robot plan` (JSON: {"targets": [{"q_deg":
/// [...]}, ...]}) [rad]. Read as outside input (base/json_fields.h: at most 1 MB, 20 targets,
/// num_joints finite angles in [−360, 360] deg); throws std::runtime_error naming the file, the key
/// and what was expected, or the number when the plan has fewer targets. Joint limits are the
/// reader's check.
Eigen::VectorXd ReadPlanTarget(const std::string& path, int number, int num_joints);

}  // namespace orbed::guidance
