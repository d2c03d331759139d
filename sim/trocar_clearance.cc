#include "sim/trocar_clearance.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "sim/collision_world.h"

namespace orbed::sim {

namespace {

// Weight and cap of the stand-off term of the objective (see the header).
constexpr double kStandOffWeight = 0.1;
constexpr double kStandOffCap_m = 0.2;

ClearanceFunction MakeFunction(const RobotModel& model, const Scene& scene, bool with_stand_off) {
  auto full = std::make_shared<CollisionWorld>(model, &scene);
  CollisionWorld::Options objective_options;
  objective_options.min_self_separation = 3;
  auto objective = std::make_shared<CollisionWorld>(model, &scene, objective_options);
  const int tool = model.tool_link();
  return [full, objective, tool, with_stand_off](const Eigen::VectorXd& q) {
    const CollisionResult all = full->Check(q);
    if (all.in_collision) return all.min_distance_m;
    const CollisionResult arm = objective->Check(q);
    double clearance = std::numeric_limits<double>::infinity();
    for (int i = 0; i < static_cast<int>(arm.link_clearance_m.size()); ++i) {
      if (i != tool) clearance = std::min(clearance, arm.link_clearance_m[i]);
    }
    if (!with_stand_off) return clearance;
    double stand_off = 0;
    int links = 0;
    for (int i = 0; i < static_cast<int>(arm.link_clearance_m.size()); ++i) {
      if (i == tool || !std::isfinite(arm.link_clearance_m[i])) continue;
      stand_off += std::min(arm.link_clearance_m[i] - clearance, kStandOffCap_m);
      ++links;
    }
    return clearance + (links > 0 ? kStandOffWeight * stand_off / links : 0.0);
  };
}

}  // namespace

ClearanceFunction MakeTrocarClearanceFunction(const RobotModel& model, const Scene& scene) {
  return MakeFunction(model, scene, true);
}

ClearanceFunction MakeTrocarArmClearanceFunction(const RobotModel& model, const Scene& scene) {
  return MakeFunction(model, scene, false);
}

TrocarIkTarget TrocarTargetInBase(const Scene& scene) {
  const Eigen::Isometry3d X_RW = scene.X_WR.inverse();
  TrocarIkTarget target;
  target.p_RT = X_RW * scene.trocar.p_WT;
  target.axis_R = (X_RW.linear() * scene.trocar.insertion_direction_W).normalized();
  return target;
}

}  // namespace orbed::sim
