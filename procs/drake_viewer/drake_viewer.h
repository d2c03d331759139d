#pragma once
/// @file
/// The testbed as Drake's viewer (Meldis, drake-visualizer) draws it: DRAKE_VIEWER_LOAD_ROBOT says
/// what there is, DRAKE_VIEWER_DRAW where it is (orbed's viewer_*_t types are Drake's lcmt_viewer_*,
/// fingerprint for fingerprint). Three "robots" (robot_num):
///   kRealRobot     the simulated iiwa: every link of the model with its collision primitives
///                  (cylinders, spheres, boxes, capsules) as geometry, grey; drawn at X_WR · X_RL(q);
///   kVirtualRobot  the hologram: the same links, translucent green; drawn at X_WV · X_RL(q_v) with
///                  X_WV the registration and q_v the guidance's target (set-up) or the real q
///                  (alignment); drawn only once there is a registration, else hidden under the
///                  real one (its draw repeats the real poses);
///   kScene         each scene object (table, patient, carts ...) as a link of its own, at X_WO.
/// Geometry poses are in their link frame, link poses in W; quaternions (w, x, y, z); floats, as
/// Drake's types have them. Sizes follow Drake's convention: BOX full sides, SPHERE radius,
/// CYLINDER and CAPSULE radius then length (along the geometry's z).
///
/// Threading: pure functions.

#include <cstdint>
#include <optional>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <orbed/viewer_draw_t.hpp>
#include <orbed/viewer_load_robot_t.hpp>

#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::viewer {

inline constexpr int32_t kRealRobot = 0;
inline constexpr int32_t kVirtualRobot = 1;
inline constexpr int32_t kScene = 2;

/// Everything there is: the real and the virtual robot's links, and the scene's objects (none when
/// `scene` is null).
orbed::viewer_load_robot_t MakeLoadRobot(const sim::RobotModel& model, const sim::Scene* scene);

/// Where it is at `utime` [µs]: q_real and q_virtual [rad] of the model's size (checked by the
/// caller), X_WV absent before a registration.
orbed::viewer_draw_t MakeDraw(const sim::RobotModel& model, const sim::Scene* scene,
                              const Eigen::Isometry3d& X_WR, const Eigen::VectorXd& q_real,
                              const std::optional<Eigen::Isometry3d>& X_WV, const Eigen::VectorXd& q_virtual,
                              int64_t utime);

}  // namespace orbed::viewer
