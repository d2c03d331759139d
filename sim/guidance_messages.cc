#include "sim/guidance_messages.h"

#include <cmath>
#include <stdexcept>

#include "base/format.h"
#include "base/json_fields.h"
#include "base/units.h"
#include "lcmtypes/contract/validation.h"

namespace orbed::guidance {
namespace {

// Copies of lcm-gen's in-class constants (it emits no out-of-line definitions to bind a reference to).
constexpr int8_t kTwist = orbed::guidance_t::JOINT_TWIST;
constexpr int8_t kRevolve = orbed::guidance_t::JOINT_REVOLVE;

}  // namespace

std::vector<int8_t> JointKinds(const sim::RobotModel& model) {
  const std::vector<Eigen::Isometry3d> X_RL = model.CalcLinkPoses(Eigen::VectorXd::Zero(model.num_joints()));
  const double cos_twist = std::cos(kTwistAngleDeg * kDegToRad);
  std::vector<int8_t> kinds;
  for (int j = 0; j < model.num_joints(); ++j) {
    const int link = model.joints()[j].link;
    const Eigen::Vector3d p_RJ = X_RL[link].translation();
    const Eigen::Vector3d axis_R = X_RL[link].linear() * model.links()[link].axis_J;
    // The next point down the arm that is not at this joint's origin: a later joint's origin, else
    // the tool tip.
    Eigen::Vector3d along = Eigen::Vector3d::Zero();
    for (int k = j + 1; k < model.num_joints() && along.norm() < 1e-6; ++k) {
      along = X_RL[model.joints()[k].link].translation() - p_RJ;
    }
    if (along.norm() < 1e-6) along = X_RL[model.tool_tip_link()].translation() - p_RJ;
    const bool twist = along.norm() >= 1e-6 && std::abs(axis_R.dot(along.normalized())) >= cos_twist;
    kinds.push_back(twist ? kTwist : kRevolve);
  }
  return kinds;
}

int8_t GuidanceModeFromName(const std::string& name) {
  if (name == "ar") return orbed::guidance_t::MODE_AR;
  if (name == "ar_reflective") return orbed::guidance_t::MODE_AR_REFLECTIVE;
  if (name == "fixed") return orbed::guidance_t::MODE_FIXED_DISPLAY;
  throw std::invalid_argument("guidance mode '" + EscapeText(name) +
                              "': expected ar, ar_reflective or fixed");
}

const char* GuidanceModeName(int8_t mode) {
  switch (mode) {
    case orbed::guidance_t::MODE_AR:
      return "ar";
    case orbed::guidance_t::MODE_AR_REFLECTIVE:
      return "ar_reflective";
    case orbed::guidance_t::MODE_FIXED_DISPLAY:
      return "fixed";
  }
  return "?";
}

std::string CheckGuidance(const orbed::guidance_t& msg, const sim::RobotModel& model, double slack_rad) {
  const int n = model.num_joints();
  std::string problem = FirstError({CheckSize(msg.num_joints, n, "GUIDANCE.num_joints"),
                                    CheckEnum(msg.mode, 0, 2, "GUIDANCE.mode"),
                                    CheckEnum(msg.next_joint, -1, n - 1, "GUIDANCE.next_joint")});
  if (!problem.empty()) return problem;
  for (int8_t kind : msg.joint_kind) {
    problem = CheckEnum(kind, orbed::guidance_t::JOINT_TWIST, orbed::guidance_t::JOINT_REVOLVE,
                        "GUIDANCE.joint_kind");
    if (!problem.empty()) return problem;
  }
  const std::string target =
      model.ValidateJointVector(Eigen::Map<const Eigen::VectorXd>(msg.target_position.data(), n), slack_rad);
  if (!target.empty()) return "GUIDANCE.target_position: " + target;
  const std::string current =
      model.ValidateJointVector(Eigen::Map<const Eigen::VectorXd>(msg.current_position.data(), n), slack_rad);
  if (!current.empty()) return "GUIDANCE.current_position: " + current;
  return "";
}

namespace {
std::string CheckTaskHeader(int64_t request_id, const std::string& task_id, int8_t mode, int32_t num_joints,
                            const sim::RobotModel& model, const std::string& what) {
  if (request_id == 0) return what + ".request_id: 0 (a task needs an id)";
  if (task_id.empty() || task_id.size() > 256) {
    return what + ".task_id: " + std::to_string(task_id.size()) + " bytes, expected 1 ... 256";
  }
  return FirstError({CheckEnum(mode, 0, 2, what + ".mode"),
                     CheckSize(num_joints, model.num_joints(), what + ".num_joints")});
}
}  // namespace

std::string CheckSetupTask(const orbed::setup_task_t& msg, const sim::RobotModel& model, double slack_rad) {
  const std::string header =
      CheckTaskHeader(msg.request_id, msg.task_id, msg.mode, msg.num_joints, model, "SETUP_TASK");
  if (!header.empty()) return header;
  const std::string target = model.ValidateJointVector(
      Eigen::Map<const Eigen::VectorXd>(msg.target_position.data(), msg.num_joints), slack_rad);
  return target.empty() ? "" : "SETUP_TASK.target_position: " + target;
}

std::string CheckSetupResult(const orbed::setup_result_t& msg, const sim::RobotModel& model,
                             double slack_rad) {
  const std::string header =
      CheckTaskHeader(msg.request_id, msg.task_id, msg.mode, msg.num_joints, model, "SETUP_RESULT");
  if (!header.empty()) return header;
  const std::string reached = model.ValidateJointVector(
      Eigen::Map<const Eigen::VectorXd>(msg.reached_position.data(), msg.num_joints), slack_rad);
  if (!reached.empty()) return "SETUP_RESULT.reached_position: " + reached;
  for (int32_t r : msg.ranges) {
    if (r < 0) return "SETUP_RESULT.ranges: " + std::to_string(r) + " < 0";
  }
  if (!(std::isfinite(msg.execution_s) && msg.execution_s >= 0 && msg.execution_s < 1e6)) {
    return "SETUP_RESULT.execution_s: not a finite time in [0, 1e6) s";
  }
  if (!(std::isfinite(msg.person_scale) && msg.person_scale >= 0 && msg.person_scale < 1e3)) {
    return "SETUP_RESULT.person_scale: not finite in [0, 1000)";
  }
  return "";
}

Eigen::VectorXd ReadPlanTarget(const std::string& path, int number, int num_joints) {
  const JsonFields f(path);
  const nlohmann::json doc = f.ReadFile(path, 1 << 20, 8);
  const JsonAt targets = f.Member({doc, ""}, "targets");
  const size_t count = f.ArraySize(targets, 20);
  if (number < 1 || static_cast<size_t>(number) > count) {
    throw std::runtime_error(path + ": has " + std::to_string(count) + " target(s); there is no target " +
                             std::to_string(number));
  }
  const JsonAt target = f.Element(targets, static_cast<size_t>(number - 1));
  const std::vector<double> q_deg = f.Numbers(f.Member(target, "q_deg"), num_joints, -360.0, 360.0);
  return Eigen::Map<const Eigen::VectorXd>(q_deg.data(), num_joints) * kDegToRad;
}

}  // namespace orbed::guidance
