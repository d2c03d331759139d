#pragma once
/// @file
/// Landmark triangulation from gaze rays (paper Sec. III-B): the point closest, in least squares,
/// to N ≥ 2 rays h_i + s·u_i,
///   x* = argmin_x Σ ‖(I − u_i u_iᵀ)(x − h_i)‖²,  i.e.  (Σ P_i) x* = Σ P_i h_i,  P_i = I − u_i u_iᵀ.
///
/// Frames and units: origins h_i (the head, p_WH [m]) and unit directions u_i are expressed in W;
/// x* is p_WX [m]. Angles reported in [deg].
///
/// Rejected (valid = false, with a reason naming the ray): fewer than 2 rays, sizes differ,
/// non-finite values, a direction whose norm is not 1 within 1e-6, rays whose lines are all
/// near-parallel (the largest acute angle between any two lines below min_ray_angle_deg; the
/// normal matrix is then ill-conditioned and the depth meaningless), and a point behind any origin
/// ((x* − h_i)·u_i < 0: the rays meet behind the viewer, so the gaze cannot have seen it).
///
/// Reported: ray_angle_deg, the largest angle between any two ray directions [deg] in [0, 180];
/// gap_m, the RMS distance from x* to the rays [m]; depth_m per ray, (x* − h_i)·u_i [m].
///
/// Threading: pure function, reentrant.

#include <string>
#include <vector>

#include <Eigen/Core>

namespace orbed::geometry {

struct TriangulationOptions {
  /// Rays whose lines are all within this angle of each other are near-parallel [deg].
  double min_ray_angle_deg = 2.0;
  /// |‖u_i‖ − 1| above this rejects the ray.
  double unit_tolerance = 1e-6;
};

struct TriangulationResult {
  bool valid = false;
  std::string reason;
  /// The landmark p_WX [m] (computed when possible, also for a point behind an origin).
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();
  double ray_angle_deg = 0.0;
  double gap_m = 0.0;
  std::vector<double> depth_m;
};

TriangulationResult TriangulateRays(const std::vector<Eigen::Vector3d>& origin_W_m,
                                    const std::vector<Eigen::Vector3d>& direction_W,
                                    const TriangulationOptions& options = {});

}  // namespace orbed::geometry
