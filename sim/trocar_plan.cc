#include "sim/trocar_plan.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "base/format.h"
#include "base/units.h"
#include "sim/trocar_clearance.h"
#include "sim/trocar_ik.h"

namespace orbed::sim {

double LargestJointDifferenceDeg(const Eigen::VectorXd& a_rad, const Eigen::VectorXd& b_rad, int joints) {
  const Eigen::Index n = joints < 0 ? a_rad.size() : std::min<Eigen::Index>(joints, a_rad.size());
  if (n == 0) return 0.0;
  return (a_rad.head(n) - b_rad.head(n)).cwiseAbs().maxCoeff() * kRadToDeg;
}

double BranchShortfallDeg(const Eigen::VectorXd& q_rad, const std::vector<int>& joint_signs,
                          double min_bend_deg) {
  double shortfall = 0;
  for (size_t i = 0; i < joint_signs.size() && static_cast<Eigen::Index>(i) < q_rad.size(); ++i) {
    if (joint_signs[i] != 0) shortfall += std::max(0.0, min_bend_deg - joint_signs[i] * q_rad[i] * kRadToDeg);
  }
  return shortfall;
}

std::vector<PlannedTarget> PlanTrocarTargets(const RobotModel& model, const Scene& scene,
                                             const TrocarPlanOptions& options) {
  if (options.num_targets < 1 || options.num_targets > 20) {
    throw std::invalid_argument("plan: num_targets must be 1..20, not " +
                                std::to_string(options.num_targets));
  }
  if (!(options.min_separation_deg >= 0 && options.min_separation_deg <= 180)) {
    throw std::invalid_argument("plan: min_separation_deg must be in [0, 180]");
  }
  if (!(options.min_clearance_m >= 0 && std::isfinite(options.min_clearance_m))) {
    throw std::invalid_argument("plan: min_clearance_m must be >= 0");
  }
  if (options.starts < 1 || options.starts > 1000)
    throw std::invalid_argument("plan: starts must be 1..1000");
  if (!options.joint_signs.empty()) {
    if (static_cast<int>(options.joint_signs.size()) != model.num_joints())
      throw std::invalid_argument("plan: joint_signs must have one entry per joint");
    for (int s : options.joint_signs) {
      if (s < -1 || s > 1) throw std::invalid_argument("plan: joint_signs must be -1, 0 or 1");
    }
  }
  if (!(options.min_bend_deg >= 0 && options.min_bend_deg <= 90))
    throw std::invalid_argument("plan: min_bend_deg must be in [0, 90]");

  const ClearanceFunction clearance = MakeTrocarClearanceFunction(model, scene);
  const ClearanceFunction arm_clearance = MakeTrocarArmClearanceFunction(model, scene);
  const TrocarIkTarget target = TrocarTargetInBase(scene);
  std::vector<PlannedTarget> plan;
  for (int k = 0; k < options.num_targets; ++k) {
    const int compared = model.num_joints() - 1;  // not the flange's roll
    const auto separation = [&plan, compared](const Eigen::VectorXd& q) {
      double smallest = std::numeric_limits<double>::infinity();
      for (const PlannedTarget& t : plan) {
        smallest = std::min(smallest, LargestJointDifferenceDeg(q, t.q_rad, compared));
      }
      return smallest;
    };
    const auto branch = [&options](const Eigen::VectorXd& q) {
      return BranchShortfallDeg(q, options.joint_signs, options.min_bend_deg);
    };
    // Inside the separation and the branch: the clearance objective [m]; outside: minus the
    // shortfalls [rad], below any clearance the IK accepts.
    const ClearanceFunction objective = [&](const Eigen::VectorXd& q) {
      const double shortfall_deg = std::max(0.0, options.min_separation_deg - separation(q)) + branch(q);
      return shortfall_deg > 0 ? -1.0 - shortfall_deg * kDegToRad : clearance(q);
    };
    TrocarIkOptions ik_options;
    ik_options.seed = options.seed + static_cast<std::uint64_t>(k);
    ik_options.num_seeds = options.starts;
    ik_options.min_clearance_m = options.min_clearance_m;
    const TrocarIkResult ik = SolveTrocarIk(model, target, ik_options, objective);
    const std::string which =
        "plan: target " + std::to_string(k + 1) + " of " + std::to_string(options.num_targets);
    if (ik.q_rad.size() == 0) throw std::runtime_error(which + ": no IK solution (" + ik.message + ")");
    PlannedTarget t;
    t.q_rad = ik.q_rad;
    t.clearance_m = arm_clearance(ik.q_rad);
    t.separation_deg = plan.empty() ? 0.0 : separation(ik.q_rad);
    t.position_error_m = ik.position_error_m;
    t.angle_error_deg = ik.angle_error_rad * kRadToDeg;
    if (!plan.empty() && t.separation_deg < options.min_separation_deg) {
      throw std::runtime_error(which + ": the best configuration found is " + Fixed(t.separation_deg, 1) +
                               " deg from an earlier target, less than " +
                               Fixed(options.min_separation_deg, 1) +
                               " (fewer targets or a smaller separation)");
    }
    if (branch(ik.q_rad) > 0) {
      throw std::runtime_error(which + ": the best configuration found is outside the branch (" +
                               Fixed(branch(ik.q_rad), 1) + " deg short)");
    }
    if (!ik.success || t.clearance_m < options.min_clearance_m) {
      throw std::runtime_error(which +
                               ": no configuration with clearance >= " + Fixed(options.min_clearance_m, 3) +
                               " m (best " + Fixed(t.clearance_m, 3) + " m; " + ik.message + ")");
    }
    plan.push_back(t);
  }
  return plan;
}

}  // namespace orbed::sim
