#include "hmd_emulator/gaze.h"

#include <cmath>
#include <stdexcept>

namespace orbed::hmd {
namespace {

// The nearest boundary crossing at t >= 0 among candidates offered one at a time (ray in G).
struct Nearest {
  double t{std::numeric_limits<double>::infinity()};
  Eigen::Vector3d n_G{Eigen::Vector3d::Zero()};
  void Offer(double t_candidate, const Eigen::Vector3d& n) {
    if (t_candidate >= 0 && t_candidate < t) {
      t = t_candidate;
      n_G = n;
    }
  }
};

// Offers the real roots of |o + t d - c|^2 = r^2 (d unit) whose point satisfies accept(point).
template <typename Accept>
void SphereRoots(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& c, double r,
                 Accept accept, Nearest* out) {
  const Eigen::Vector3d oc = o - c;
  const double b = oc.dot(d);
  const double disc = b * b - (oc.squaredNorm() - r * r);
  if (disc < 0) return;
  const double s = std::sqrt(disc);
  for (double t : {-b - s, -b + s}) {
    const Eigen::Vector3d p = o + t * d;
    if (accept(p)) out->Offer(t, (p - c) / r);
  }
}

// Roots of the infinite cylinder x^2 + y^2 = r^2 whose z lies in [-h, h].
void SideRoots(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double r, double h, Nearest* out) {
  const double a = d.x() * d.x() + d.y() * d.y();
  if (!(a > 1e-18)) return;  // parallel to the axis: the side is never crossed
  const double b = o.x() * d.x() + o.y() * d.y();
  const double c = o.x() * o.x() + o.y() * o.y() - r * r;
  const double disc = b * b - a * c;
  if (disc < 0) return;
  const double s = std::sqrt(disc);
  for (double t : {(-b - s) / a, (-b + s) / a}) {
    const Eigen::Vector3d p = o + t * d;
    if (std::abs(p.z()) <= h) out->Offer(t, Eigen::Vector3d(p.x(), p.y(), 0) / r);
  }
}

}  // namespace

RayHit IntersectPrimitive(const render::Primitive& g, const Eigen::Vector3d& p_WO,
                          const Eigen::Vector3d& direction_W, double max_distance_m) {
  const Eigen::Matrix3d R_GW = g.X_WG.linear().transpose();
  const Eigen::Vector3d o = R_GW * (p_WO - g.X_WG.translation());
  const Eigen::Vector3d d = R_GW * direction_W;
  Nearest best;
  switch (g.shape) {
    case render::Primitive::Shape::kBox: {
      // Slab test: the ray is inside all three slabs for t in [t_enter, t_exit].
      const Eigen::Vector3d h = 0.5 * g.size_m;
      double t_enter = -std::numeric_limits<double>::infinity();
      double t_exit = std::numeric_limits<double>::infinity();
      int enter_axis = -1, exit_axis = -1;
      for (int i = 0; i < 3; ++i) {
        if (std::abs(d[i]) < 1e-15) {
          if (std::abs(o[i]) > h[i]) return RayHit{};
          continue;
        }
        double t1 = (-h[i] - o[i]) / d[i], t2 = (h[i] - o[i]) / d[i];
        if (t1 > t2) std::swap(t1, t2);
        if (t1 > t_enter) {
          t_enter = t1;
          enter_axis = i;
        }
        if (t2 < t_exit) {
          t_exit = t2;
          exit_axis = i;
        }
      }
      if (t_enter > t_exit || t_exit < 0) return RayHit{};
      if (t_enter >= 0) {
        Eigen::Vector3d n = Eigen::Vector3d::Zero();
        n[enter_axis] = d[enter_axis] > 0 ? -1 : 1;
        best.Offer(t_enter, n);
      } else {  // starts inside: the exit face
        Eigen::Vector3d n = Eigen::Vector3d::Zero();
        n[exit_axis] = d[exit_axis] > 0 ? 1 : -1;
        best.Offer(t_exit, n);
      }
      break;
    }
    case render::Primitive::Shape::kSphere:
      SphereRoots(
          o, d, Eigen::Vector3d::Zero(), g.radius_m, [](const Eigen::Vector3d&) { return true; }, &best);
      break;
    case render::Primitive::Shape::kCylinder: {
      const double h = 0.5 * g.length_m, r = g.radius_m;
      SideRoots(o, d, r, h, &best);
      if (std::abs(d.z()) > 1e-18) {
        for (double s : {-1.0, 1.0}) {  // end caps z = ±h
          const double t = (s * h - o.z()) / d.z();
          const Eigen::Vector3d p = o + t * d;
          if (p.x() * p.x() + p.y() * p.y() <= r * r) best.Offer(t, Eigen::Vector3d(0, 0, s));
        }
      }
      break;
    }
    case render::Primitive::Shape::kCapsule: {
      const double h = 0.5 * g.length_m, r = g.radius_m;
      SideRoots(o, d, r, h, &best);
      // Only the outer hemispheres of the two end spheres are on the capsule's surface.
      SphereRoots(
          o, d, Eigen::Vector3d(0, 0, h), r, [h](const Eigen::Vector3d& p) { return p.z() >= h; }, &best);
      SphereRoots(
          o, d, Eigen::Vector3d(0, 0, -h), r, [h](const Eigen::Vector3d& p) { return p.z() <= -h; }, &best);
      break;
    }
  }
  RayHit hit;
  if (!std::isfinite(best.t) || best.t > max_distance_m) return hit;
  hit.hit = true;
  hit.distance_m = best.t;
  hit.p_WQ = p_WO + best.t * direction_W;
  hit.normal_W = g.X_WG.linear() * best.n_G;
  return hit;
}

RayHit CastRay(const render::SceneGeometry& geometry, const Eigen::Vector3d& p_WO,
               const Eigen::Vector3d& direction_W, render::KindMask kinds, double max_distance_m) {
  const double len = direction_W.norm();
  if (!std::isfinite(len) || !(len > 0) || !p_WO.allFinite())
    throw std::invalid_argument("CastRay: origin and direction must be finite, direction non-zero");
  const Eigen::Vector3d d = direction_W / len;
  RayHit best;
  for (const render::Primitive& p : geometry.primitives()) {
    if (!(kinds & render::KindBit(geometry.bodies()[p.body].kind))) continue;
    RayHit h = IntersectPrimitive(p, p_WO, d, std::min(max_distance_m, best.distance_m));
    if (h.hit && h.distance_m < best.distance_m) {
      best = h;
      best.body = p.body;
    }
  }
  if (best.hit) best.body_name = geometry.bodies()[best.body].name;
  return best;
}

}  // namespace orbed::hmd
