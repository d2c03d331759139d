#include "procs/guidance/guidance.h"

#include <cmath>
#include <stdexcept>
#include <utility>

#include "base/format.h"
#include "base/units.h"
#include "lcmtypes/contract/validation.h"

namespace orbed::guidance {

GuidanceCore::GuidanceCore(const sim::RobotModel& model, GuidanceTarget target)
    : target_(std::move(target)), kinds_(JointKinds(model)) {
  if (GuidanceModeName(target_.mode)[0] == '?') {
    throw std::invalid_argument("guidance mode " + std::to_string(target_.mode) + " is not one of 0, 1, 2");
  }
  const std::string limits = model.ValidateJointVector(target_.q_target_rad);
  if (!limits.empty()) throw std::invalid_argument("guidance target: " + limits);
  if (!(target_.tolerance_deg > 0 && target_.tolerance_deg <= 90)) {
    throw std::invalid_argument("guidance tolerance " + Fixed(target_.tolerance_deg, 3) +
                                " deg is not in (0, 90]");
  }
}

orbed::guidance_t GuidanceCore::Compute(const Eigen::VectorXd& q_rad, int64_t utime) const {
  orbed::guidance_t g{};
  g.utime = utime;
  g.mode = target_.mode;
  g.num_joints = static_cast<int32_t>(target_.q_target_rad.size());
  g.next_joint = -1;
  for (int i = 0; i < g.num_joints; ++i) {
    const double error_deg = (q_rad[i] - target_.q_target_rad[i]) * kRadToDeg;
    g.target_position.push_back(target_.q_target_rad[i]);
    g.current_position.push_back(q_rad[i]);
    g.error_deg.push_back(error_deg);
    g.joint_kind.push_back(kinds_[i]);
    if (g.next_joint < 0 && std::abs(error_deg) > target_.tolerance_deg) g.next_joint = i;
  }
  g.done = g.next_joint < 0;
  return g;
}

}  // namespace orbed::guidance
