#include "sim/distance_closed_form.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace orbed::sim {
namespace {

using Eigen::Vector3d;
using Kind = CoreShape::Kind;

// A segment closer than this to a box or cylinder core is left to GJK/EPA (the distance gradient
// degenerates as the segment touches the core) [m].
constexpr double kTouchM = 1e-9;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Core-level result: signed core distance d_core, the core points and the unit normal from B's core
// toward A's core. The shapes' signed distance is d_core - margin_A - margin_B.
struct CoreResult {
  double d_core{0};
  Vector3d pa, pb, n;
};

// Any unit vector perpendicular to v (v != 0).
Vector3d AnyPerpendicular(const Vector3d& v) {
  const Vector3d other = std::abs(v.x()) < 0.6 ? Vector3d::UnitX() : Vector3d::UnitY();
  return v.cross(other).normalized();
}

// Fills the core result from the two closest core points; when they coincide, `fallback_n` (unit)
// is the normal.
void FromPoints(const Vector3d& pa, const Vector3d& pb, const Vector3d& fallback_n, CoreResult* r) {
  r->pa = pa;
  r->pb = pb;
  const Vector3d v = pa - pb;
  const double len = v.norm();
  r->d_core = len;
  r->n = len > 0 ? Vector3d(v / len) : fallback_n;
}

double ClosestPointSegment(const Vector3d& x, const Vector3d& a, const Vector3d& d) {
  const double dd = d.squaredNorm();
  return dd > 0 ? std::clamp((x - a).dot(d) / dd, 0.0, 1.0) : 0.0;
}

// Signed distance from p to the box core |x_i| <= e_i (frame C); *cp the closest surface point and
// *n the outward unit normal there (from the box toward p).
double ClosestOnBox(const Vector3d& p, const Vector3d& e, Vector3d* cp, Vector3d* n) {
  const Vector3d q = p.cwiseAbs() - e;
  if (q.maxCoeff() > 0) {
    *cp = p.cwiseMax(-e).cwiseMin(e);
    const Vector3d v = p - *cp;
    const double g = v.norm();
    *n = v / g;
    return g;
  }
  int i = 0;
  q.maxCoeff(&i);  // the nearest face
  const double s = p[i] < 0 ? -1.0 : 1.0;
  *cp = p;
  (*cp)[i] = s * e[i];
  *n = Vector3d::Zero();
  (*n)[i] = s;
  return q[i];
}

// Signed distance from p to the cylinder core of radius e.x and half height e.z about z (frame C).
double ClosestOnCylinder(const Vector3d& p, const Vector3d& e, Vector3d* cp, Vector3d* n) {
  const double radius = e.x(), half_height = e.z();
  const double rho = std::sqrt(p.x() * p.x() + p.y() * p.y());
  const double side = rho - radius, cap = std::abs(p.z()) - half_height;
  if (side > 0 || cap > 0) {
    const double scale = side > 0 ? radius / rho : 1.0;
    *cp = Vector3d(p.x() * scale, p.y() * scale, std::clamp(p.z(), -half_height, half_height));
    const Vector3d v = p - *cp;
    const double g = v.norm();
    *n = v / g;
    return g;
  }
  if (side >= cap) {  // nearer the side wall
    const Vector3d radial = rho > 0 ? Vector3d(p.x() / rho, p.y() / rho, 0) : Vector3d::UnitX();
    *cp = Vector3d(radial.x() * radius, radial.y() * radius, p.z());
    *n = radial;
    return side;
  }
  const double s = p.z() < 0 ? -1.0 : 1.0;
  *cp = Vector3d(p.x(), p.y(), s * half_height);
  *n = Vector3d(0, 0, s);
  return cap;
}

double ClosestOnCore(const CoreShape& b, const Vector3d& p, Vector3d* cp, Vector3d* n) {
  return b.kind == Kind::kBox ? ClosestOnBox(p, b.half_extents_m, cp, n)
                              : ClosestOnCylinder(p, b.half_extents_m, cp, n);
}

// min over t in [0, 1] of g(t) = dist(a + t d, core) for a segment outside the core (frame C). g is
// convex and C1 there with g' = n . d; the minimum is bracketed by the sign of g' and found by a
// secant step on g' (bisection when the bracket stops halving). The intersection of the tangent
// lines at the bracket ends is a lower bound on the minimum, so the search stops with a certified
// gap. False if the segment comes within kTouchM of the core or the search does not converge.
bool SegmentToCore(const Vector3d& a, const Vector3d& d, const CoreShape& core, Vector3d* p_best,
                   Vector3d* cp_best, Vector3d* n_best, double* g_best) {
  struct Sample {
    double t, g, dg;
    Vector3d p, cp, n;
  };
  auto eval = [&](double t, Sample* s) {
    s->t = t;
    s->p = a + t * d;
    s->g = ClosestOnCore(core, s->p, &s->cp, &s->n);
    s->dg = s->n.dot(d);
    return s->g > kTouchM;
  };
  Sample lo, hi;
  if (!eval(0.0, &lo) || !eval(1.0, &hi)) return false;
  Sample best = lo.g <= hi.g ? lo : hi;
  if (lo.dg >= 0) {
    best = lo;
  } else if (hi.dg <= 0) {
    best = hi;
  } else {
    bool converged = false;
    int slow = 0;
    for (int it = 0; it < 80 && !converged; ++it) {
      const double den = hi.dg - lo.dg;  // > 0: lo.dg < 0 < hi.dg
      // lo.g + lo.dg (t - lo.t) = hi.g + hi.dg (t - hi.t), inside [lo.t, hi.t] by convexity.
      const double t_cross = (lo.g - hi.g - lo.dg * lo.t + hi.dg * hi.t) / den;
      const double lower = lo.g + lo.dg * (t_cross - lo.t);
      if (best.g - lower <= kSegmentConvexTolM) {
        converged = true;
        break;
      }
      const double width = hi.t - lo.t;
      double t = lo.t - lo.dg * width / den;  // root of the secant of g'
      if (slow >= 2 || !(t > lo.t && t < hi.t)) {
        t = 0.5 * (lo.t + hi.t);
        slow = 0;
      }
      if (!(t > lo.t && t < hi.t)) {  // the bracket is down to adjacent doubles
        converged = true;
        break;
      }
      Sample s;
      if (!eval(t, &s)) return false;
      if (s.g < best.g) best = s;
      if (s.dg < 0) {
        lo = s;
      } else if (s.dg > 0) {
        hi = s;
      } else {
        best = s;
        converged = true;
      }
      slow = hi.t - lo.t > 0.5 * width ? slow + 1 : 0;
    }
    if (!converged) return false;
  }
  *p_best = best.p;
  *cp_best = best.cp;
  *n_best = best.n;
  *g_best = best.g;
  return true;
}

// Penetration of the segment [p0, p0 + d] into the box core |x_i| <= e_i (frame C) by separating
// axes: the facets of segment - box have the box's face normals or d x (box edge) as normals, so the
// least overlap over those axes is the exact depth. *n is the direction the segment moves out (from
// the box toward it), *deepest the segment end point deepest along -n. False unless every axis
// overlaps (the cores then intersect).
bool SegmentInBox(const Vector3d& p0, const Vector3d& d, const Vector3d& e, double* depth, Vector3d* n,
                  Vector3d* deepest) {
  double best = kInf;
  Vector3d best_n = Vector3d::UnitZ();
  auto axis = [&](const Vector3d& u) {
    const double a0 = u.dot(p0), a1 = a0 + u.dot(d);
    const double h_box = std::abs(u.x()) * e.x() + std::abs(u.y()) * e.y() + std::abs(u.z()) * e.z();
    const double out_plus = h_box - std::min(a0, a1), out_minus = h_box + std::max(a0, a1);
    if (out_plus < best) {
      best = out_plus;
      best_n = u;
    }
    if (out_minus < best) {
      best = out_minus;
      best_n = -u;
    }
  };
  for (int i = 0; i < 3; ++i) axis(Vector3d::Unit(i));
  const double len = d.norm();
  if (len > 0) {
    for (int i = 0; i < 3; ++i) {
      const Vector3d c = d.cross(Vector3d::Unit(i));
      const double c_len = c.norm();
      if (c_len > 1e-9 * len) axis(c / c_len);
    }
  }
  if (!(best > 0)) return false;
  *depth = best;
  *n = best_n;
  *deepest = best_n.dot(d) >= 0 ? p0 : Vector3d(p0 + d);
  return true;
}

// Core distance for kind(a) <= kind(b) (Point < Segment < Box < Cylinder).
bool CoreDistance(const CoreShape& a, const Eigen::Isometry3d& X_WA, const CoreShape& b,
                  const Eigen::Isometry3d& X_WB, CoreResult* r) {
  const Vector3d ca = X_WA.translation(), cb = X_WB.translation();
  const Vector3d za = X_WA.linear().col(2), zb = X_WB.linear().col(2);
  switch (b.kind) {
    case Kind::kPoint:  // a is a point too
      FromPoints(ca, cb, Vector3d::UnitZ(), r);
      return true;
    case Kind::kSegment: {
      const Vector3d q0 = cb - b.half_length_m * zb, db = 2 * b.half_length_m * zb;
      if (a.kind == Kind::kPoint) {
        const Vector3d pb = q0 + ClosestPointSegment(ca, q0, db) * db;
        FromPoints(ca, pb, db.squaredNorm() > 0 ? AnyPerpendicular(db) : Vector3d::UnitZ(), r);
        return true;
      }
      const Vector3d p0 = ca - a.half_length_m * za, da = 2 * a.half_length_m * za;
      double s = 0, t = 0;
      ClosestSegmentSegment(p0, p0 + da, q0, q0 + db, &s, &t);
      // Crossing cores: the depth is the sum of the radii along the normal of the plane of both axes
      // (any perpendicular if parallel), oriented from B toward A.
      Vector3d fallback = da.cross(db);
      fallback = fallback.squaredNorm() > 1e-24
                     ? Vector3d(fallback.normalized())
                     : (da.squaredNorm() > 0 ? AnyPerpendicular(da) : Vector3d::UnitZ());
      if (fallback.dot(ca - cb) < 0) fallback = -fallback;
      FromPoints(p0 + s * da, q0 + t * db, fallback, r);
      return true;
    }
    case Kind::kBox:
    case Kind::kCylinder: {
      if (a.kind != Kind::kPoint && a.kind != Kind::kSegment) return false;
      const Eigen::Matrix3d R_BW = X_WB.linear().transpose();
      const Vector3d a_B = R_BW * (ca - cb);
      Vector3d p_B, cp_B, n_B;
      double g = 0;
      if (a.kind == Kind::kPoint) {
        p_B = a_B;
        g = ClosestOnCore(b, p_B, &cp_B, &n_B);
      } else {
        const Vector3d za_B = R_BW * za;
        const Vector3d p0_B = a_B - a.half_length_m * za_B, d_B = 2 * a.half_length_m * za_B;
        if (!SegmentToCore(p0_B, d_B, b, &p_B, &cp_B, &n_B, &g)) {
          // The axis reaches the core: exact for a box, GJK/EPA for a cylinder.
          double depth = 0;
          if (b.kind != Kind::kBox || !SegmentInBox(p0_B, d_B, b.half_extents_m, &depth, &n_B, &p_B))
            return false;
          g = -depth;
          cp_B = p_B + depth * n_B;  // on the box's supporting plane along n
        }
      }
      r->d_core = g;
      r->pa = X_WB * p_B;
      r->pb = X_WB * cp_B;
      r->n = X_WB.linear() * n_B;
      return true;
    }
  }
  return false;
}

}  // namespace

double ClosestSegmentSegment(const Vector3d& p0, const Vector3d& p1, const Vector3d& q0, const Vector3d& q1,
                             double* s, double* t) {
  const Vector3d d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double sc = 0, tc = 0;
  if (a <= 0 && e <= 0) {
    sc = tc = 0;
  } else if (a <= 0) {
    tc = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 0) {
      sc = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2);
      const double denom = a * e - b * b;  // >= 0, 0 when parallel
      sc = denom > 1e-14 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      tc = (b * sc + f) / e;
      if (tc < 0) {
        tc = 0;
        sc = std::clamp(-c / a, 0.0, 1.0);
      } else if (tc > 1) {
        tc = 1;
        sc = std::clamp((b - c) / a, 0.0, 1.0);
      }
      if (denom <= 1e-6 * a * e) {
        // Nearly parallel: the clamped solution above can lose digits; the minimum is also attained
        // at an end point of one segment, so take the best of those candidates as well.
        double best = (p0 + sc * d1 - (q0 + tc * d2)).squaredNorm();
        auto consider = [&](double si, double ti) {
          const double dist2 = (p0 + si * d1 - (q0 + ti * d2)).squaredNorm();
          if (dist2 < best) {
            best = dist2;
            sc = si;
            tc = ti;
          }
        };
        consider(0.0, ClosestPointSegment(p0, q0, d2));
        consider(1.0, ClosestPointSegment(p1, q0, d2));
        consider(ClosestPointSegment(q0, p0, d1), 0.0);
        consider(ClosestPointSegment(q1, p0, d1), 1.0);
      }
    }
  }
  *s = sc;
  *t = tc;
  return (p0 + sc * d1 - (q0 + tc * d2)).squaredNorm();
}

bool ClosedFormDistance(const CoreShape& a, const Eigen::Isometry3d& X_WA, const CoreShape& b,
                        const Eigen::Isometry3d& X_WB, SignedDistance* out) {
  const bool swap = static_cast<int>(a.kind) > static_cast<int>(b.kind);
  CoreResult r;
  if (!(swap ? CoreDistance(b, X_WB, a, X_WA, &r) : CoreDistance(a, X_WA, b, X_WB, &r))) return false;
  if (swap) {
    std::swap(r.pa, r.pb);
    r.n = -r.n;
  }
  out->distance_m = r.d_core - a.margin_m - b.margin_m;
  out->normal_W = r.n;
  out->p_WA = r.pa - a.margin_m * r.n;
  out->p_WB = r.pb + b.margin_m * r.n;
  return true;
}

}  // namespace orbed::sim
