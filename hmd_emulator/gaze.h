#pragma once
/// @file
/// Gaze ray casting against the analytic primitives of a SceneGeometry (the headset's spatial map):
/// box (slab test), finite capped cylinder, sphere and capsule, each intersected exactly in the
/// primitive's frame G. Returns the nearest hit along the ray: point, distance, outward normal and
/// body; a miss is reported with hit = false.
///
/// Frames: the ray is p_WO + t · d_W, t >= 0 [m], d_W a unit vector in W (normalised here). A ray
/// that starts inside a primitive hits that primitive's surface where it leaves it.
///
/// Threading: pure functions of their arguments; thread-safe.

#include <limits>
#include <string>

#include <Eigen/Core>

#include "render/scene_geometry.h"

namespace orbed::hmd {

struct RayHit {
  bool hit{false};
  Eigen::Vector3d p_WQ{Eigen::Vector3d::Zero()};               ///< hit point Q [m] (when hit)
  Eigen::Vector3d normal_W{Eigen::Vector3d::Zero()};           ///< outward unit surface normal at Q
  double distance_m{std::numeric_limits<double>::infinity()};  ///< t at Q
  int body{-1};                                                ///< index into render::SceneGeometry::bodies()
  std::string body_name;                                       ///< "" on a miss
};

/// Nearest ray hit of one primitive with t in [0, max_distance_m], or hit = false. `direction_W`
/// must be a unit vector; body / body_name are left empty.
RayHit IntersectPrimitive(const render::Primitive& primitive, const Eigen::Vector3d& p_WO,
                          const Eigen::Vector3d& direction_W,
                          double max_distance_m = std::numeric_limits<double>::infinity());

/// Nearest hit over the primitives whose body kind is in `kinds` (default: the real world, i.e.
/// scene objects and the real robot, not the hologram). Throws std::invalid_argument when the
/// direction is not finite and non-zero.
RayHit CastRay(const render::SceneGeometry& geometry, const Eigen::Vector3d& p_WO,
               const Eigen::Vector3d& direction_W, render::KindMask kinds = render::kRealWorld,
               double max_distance_m = std::numeric_limits<double>::infinity());

}  // namespace orbed::hmd
