#pragma once
/// @file
/// Exact signed distances between the convex primitives of the collision world without GJK/EPA: the
/// fast path of CollisionWorld (sim/collision_world.h), which keeps Bullet's GJK/EPA for the rest.
///
/// Shape model: every primitive is a core swept by a ball, exactly as Bullet's convex shapes are
/// (GJK runs on the cores, the margins are added afterwards):
///   sphere   = point                               + ball(radius)   (btSphereShape)
///   capsule  = segment of half length h along z   + ball(radius)   (btCapsuleShapeZ)
///   box      = box of half extents e               + ball(margin)   (btBoxShape: e = size/2 - margin)
///   cylinder = cylinder of radius R, half height H along z + ball(margin)  (btCylinderShapeZ)
/// The core dimensions and margins are read from the Bullet shapes themselves (CollisionWorld), so
/// both paths see the same geometry.
///
/// Which pairs are covered (A, B in either order):
///   point-point, point-segment, segment-segment: closed form, including penetration (the core
///     distance minus both radii is the exact signed distance of the swept shapes, also when the
///     segments cross: the Minkowski difference of two segments is flat, so depth = r_A + r_B);
///   point-box, point-cylinder: closed form, including penetration (exact signed distance of a
///     point to the core box / cylinder);
///   segment-box, segment-cylinder while the segment stays outside the core: the distance from the
///     segment to the core is a convex, C1 function of the segment parameter; it is minimised by a
///     bracketed secant search on its derivative whose convexity (tangent-line) lower bound
///     certifies the result to kSegmentConvexTolM;
///   segment-box with the segment reaching the core: exact depth by separating axes (the facet
///     normals of segment - box are the box's face normals and d x box edges);
///   segment-cylinder with the segment reaching the core: not covered.
///   box-box, box-cylinder, cylinder-cylinder: not covered.
/// Not covered means the function returns false and the caller uses GJK/EPA.
///
/// Result convention (Bullet's, as CollisionWorld reports it): distance < 0 is a penetration depth;
/// normal_W is a unit vector from B toward A (the direction A moves to separate); p_WB is the
/// closest (deepest) point on B's surface and p_WA = p_WB + normal_W * distance. All in frame W,
/// metres. Where the closest points are not unique (parallel features) one valid pair is returned,
/// not necessarily the one GJK would pick; the distance is the same.
///
/// Threading: pure functions, no state; safe from any thread.

#include <Eigen/Geometry>

namespace orbed::sim {

/// A convex primitive as core + ball(margin_m), in its own frame C (axis along z).
struct CoreShape {
  enum class Kind { kPoint, kSegment, kBox, kCylinder };
  Kind kind{Kind::kPoint};
  double half_length_m{0};  ///< kSegment: core from -h to +h on z
  Eigen::Vector3d half_extents_m{
      Eigen::Vector3d::Zero()};  ///< kBox: core half extents;
                                 ///< kCylinder: x = core radius, z = core half height
  double margin_m{0};            ///< ball radius swept over the core
};

/// Signed distance and closest points of two primitives (see the file comment for conventions).
struct SignedDistance {
  double distance_m{0};
  Eigen::Vector3d p_WA{Eigen::Vector3d::Zero()};
  Eigen::Vector3d p_WB{Eigen::Vector3d::Zero()};
  Eigen::Vector3d normal_W{Eigen::Vector3d::UnitZ()};
};

/// Convergence tolerance of the segment-box / segment-cylinder search [m]: the returned distance
/// exceeds the true one by at most this (it is an attained distance, never below the true one).
inline constexpr double kSegmentConvexTolM = 1e-13;

/// Exact signed distance of a posed at X_WA and b posed at X_WB; false if the pair (or this
/// configuration of it, see above) is not covered, leaving *out unspecified.
bool ClosedFormDistance(const CoreShape& a, const Eigen::Isometry3d& X_WA, const CoreShape& b,
                        const Eigen::Isometry3d& X_WB, SignedDistance* out);

/// Closest points of segments [p0, p1] and [q0, q1] (either may be degenerate): parameters s, t in
/// [0, 1] of the closest pair p0 + s (p1 - p0), q0 + t (q1 - q0). Returns the squared distance.
double ClosestSegmentSegment(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& q0,
                             const Eigen::Vector3d& q1, double* s, double* t);

}  // namespace orbed::sim
