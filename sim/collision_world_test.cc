// Tests of the Bullet collision world against closed forms: segment-segment (capsules), point-box,
// sphere-sphere, and hand-computed robot poses.
#include "sim/collision_world.h"
#include "base/source_paths.h"
#include "base/units.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <map>
#include <random>
#include <string>
#include <tuple>

#include <gtest/gtest.h>

namespace orbed::sim {
namespace {

using Kind = CollisionPrimitive::Kind;

RobotModel LoadIiwa() {
  return RobotModel::LoadFile(orbed::SourceTreePath(RobotModel::kDefaultUrdfRelativePath));
}

Eigen::VectorXd Deg(std::initializer_list<double> v) {
  Eigen::VectorXd q(v.size());
  int i = 0;
  for (double x : v) q[i++] = x * kDegToRad;
  return q;
}

// Closed-form distance between segments [p0,p1] and [q0,q1] (clamped parametric minimum; the
// textbook construction, handling parallel segments by also testing the four end points).
double SegmentSegmentDistance(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& q0,
                              const Eigen::Vector3d& q1) {
  auto point_segment = [](const Eigen::Vector3d& x, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    const Eigen::Vector3d ab = b - a;
    if (ab.squaredNorm() < 1e-18) return (x - a).norm();
    const double t = std::clamp((x - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
    return (x - (a + t * ab)).norm();
  };
  double best = std::min(std::min(point_segment(p0, q0, q1), point_segment(p1, q0, q1)),
                         std::min(point_segment(q0, p0, p1), point_segment(q1, p0, p1)));
  const Eigen::Vector3d d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.dot(d1), e = d2.dot(d2), b = d1.dot(d2), c = d1.dot(r), f = d2.dot(r);
  const double denom = a * e - b * b;
  if (denom > 1e-14) {
    const double s = (b * f - c * e) / denom, t = (a * f - b * c) / denom;
    if (s > 0 && s < 1 && t > 0 && t < 1) best = std::min(best, ((p0 + s * d1) - (q0 + t * d2)).norm());
  }
  return best;
}

CollisionPrimitive Capsule(double r, double len) {
  CollisionPrimitive g;
  g.kind = Kind::kCapsule;
  g.radius_m = r;
  g.length_m = len;
  return g;
}

Eigen::Isometry3d RandomPose(std::mt19937_64& rng, double spread) {
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
  X.translation() = spread * Eigen::Vector3d(u(rng), u(rng), u(rng));
  return X;
}

TEST(CollisionWorldTest, CapsuleCapsuleMatchesSegmentDistance) {
  std::mt19937_64 rng(7);
  int penetrating = 0;
  for (int i = 0; i < 300; ++i) {
    const CollisionPrimitive a = Capsule(0.07, 0.2), b = Capsule(0.05, 0.3);
    const Eigen::Isometry3d XA = RandomPose(rng, 0.3), XB = RandomPose(rng, 0.3);
    const Eigen::Vector3d za = XA.linear().col(2), zb = XB.linear().col(2);
    const double seg = SegmentSegmentDistance(XA.translation() - 0.1 * za, XA.translation() + 0.1 * za,
                                              XB.translation() - 0.15 * zb, XB.translation() + 0.15 * zb);
    if (seg < 1e-3) continue;  // cores intersect: depth is not a segment distance
    const double expected = seg - 0.12;
    const PairDistance d = CollisionWorld::PrimitiveDistance(a, XA, b, XB);
    EXPECT_NEAR(d.distance_m, expected, 1e-6) << i;
    EXPECT_NEAR((d.p_WA - d.p_WB).norm(), std::abs(expected), 1e-6);
    penetrating += expected < 0;
  }
  EXPECT_GT(penetrating, 5);  // the exactness covers penetration too
}

TEST(CollisionWorldTest, SphereSphereAndSphereBoxClosedForms) {
  CollisionPrimitive s;
  s.kind = Kind::kSphere;
  s.radius_m = 0.1;
  Eigen::Isometry3d XA = Eigen::Isometry3d::Identity(), XB = Eigen::Isometry3d::Identity();
  XB.translation() = Eigen::Vector3d(0.3, 0.1, -0.2);
  PairDistance d = CollisionWorld::PrimitiveDistance(s, XA, s, XB);
  EXPECT_NEAR(d.distance_m, std::sqrt(0.14) - 0.2, 1e-9);
  // The normal points from B toward A.
  EXPECT_GT(d.normal_W.dot(XA.translation() - XB.translation()), 0.99 * std::sqrt(0.14));
  XB.translation() = Eigen::Vector3d(0.15, 0, 0);
  EXPECT_NEAR(CollisionWorld::PrimitiveDistance(s, XA, s, XB).distance_m, -0.05, 1e-9);

  CollisionPrimitive box;
  box.kind = Kind::kBox;
  box.size_m = Eigen::Vector3d(1.0, 0.6, 0.2);  // half extents 0.5, 0.3, 0.1
  for (const Eigen::Vector3d& c :
       {Eigen::Vector3d(0.2, 0.1, 0.35), Eigen::Vector3d(0.2, 0.1, 0.15), Eigen::Vector3d(0.0, 0.45, 0.0)}) {
    XA.translation() = c;
    const double face = std::max(std::abs(c.z()) - 0.1, std::abs(c.y()) - 0.3);
    EXPECT_NEAR(CollisionWorld::PrimitiveDistance(s, XA, box, Eigen::Isometry3d::Identity()).distance_m,
                face - 0.1, 1e-7)
        << c.transpose();
  }
}

Scene FloorScene(double top_z) {
  Scene scene;
  scene.source = "test";
  SceneObject table;
  table.name = "operating_table";
  table.shape = SceneObject::Shape::kBox;
  table.size_m = Eigen::Vector3d(3, 3, 0.1);
  table.X_WO.translation() = Eigen::Vector3d(0, 0, top_z - 0.05);
  table.ignore_links = {"iiwa_link_0", "iiwa_link_1"};
  scene.objects.push_back(table);
  return scene;
}

TEST(CollisionWorldTest, ArmLaidOverTableHasHandComputedClearance) {
  const RobotModel m = LoadIiwa();
  // q2 = 90 deg lays the arm horizontal at the joint-2 height 0.34 m; the arm capsules (r 0.07)
  // are then the lowest parts: clearance = 0.34 - 0.07 - top.
  const Eigen::VectorXd q = Deg({0, 90, 0, 0, 0, 0, 0});
  {
    const Scene scene = FloorScene(0.20);
    CollisionWorld world(m, &scene);
    const CollisionResult r = world.Check(q);
    EXPECT_FALSE(r.in_collision);
    EXPECT_NEAR(r.closest_environment.distance_m, 0.07, 1e-7);
    EXPECT_EQ(r.closest_environment.body_b, "operating_table");
    EXPECT_NEAR(r.link_clearance_m[m.FindLink("iiwa_link_6")], std::min(0.34 - 0.065 - 0.20, 0.095), 1e-7);
  }
  {
    const Scene scene = FloorScene(0.30);
    CollisionWorld world(m, &scene);
    const CollisionResult r = world.Check(q);
    EXPECT_TRUE(r.in_collision);
    EXPECT_NEAR(r.min_distance_m, -0.03, 1e-6);
    EXPECT_EQ(r.closest.body_b, "operating_table");
    EXPECT_FALSE(r.closest.self);
  }
}

// The capsule of each arm link in the DH frames, as in the URDF: link frame L_i = DH frame i-1
// turned by q_i, so segment points are DH-frame origins plus offsets along known axes.
struct Seg {
  Eigen::Vector3d a, b;
  double r;
};
std::vector<Seg> ArmCapsules(const RobotModel& m, const Eigen::VectorXd& q) {
  const auto X = m.CalcLinkPoses(q);
  auto L = [&](int i) { return X[m.FindLink("iiwa_link_" + std::to_string(i))]; };
  std::vector<Seg> s(7);
  s[1] = {L(1) * Eigen::Vector3d(0, 0, 0.20), L(1) * Eigen::Vector3d(0, 0, 0.34), 0.07};
  s[2] = {L(2) * Eigen::Vector3d(0, -0.06, 0), L(2) * Eigen::Vector3d(0, -0.17, 0), 0.07};
  s[3] = {L(3) * Eigen::Vector3d(0, 0, 0.21), L(3) * Eigen::Vector3d(0, 0, 0.40), 0.07};
  s[4] = {L(4) * Eigen::Vector3d(0, 0.06, 0), L(4) * Eigen::Vector3d(0, 0.17, 0), 0.07};
  s[5] = {L(5) * Eigen::Vector3d(0, 0, 0.21), L(5) * Eigen::Vector3d(0, 0, 0.27), 0.065};
  s[6] = {L(6).translation(), L(6).translation(), 0.065};
  return s;
}

// The pair a-b in r.contacts, or nullptr. The pointer points into `r`, so a temporary result is
// refused at compile time (it would be destroyed at the end of the caller's statement).
const PairDistance* FindPair(const CollisionResult& r, const std::string& a, const std::string& b) {
  for (const auto& p : r.contacts) {
    if ((p.body_a == a && p.body_b == b) || (p.body_a == b && p.body_b == a)) return &p;
  }
  return nullptr;
}
const PairDistance* FindPair(CollisionResult&&, const std::string&, const std::string&) = delete;

TEST(CollisionWorldTest, SelfDistancesMatchSegmentDistancesAndSelfCollisionExists) {
  const RobotModel m = LoadIiwa();
  CollisionWorld::Options all;
  all.report_distance_m = 1e9;  // report every pair
  CollisionWorld world(m, nullptr, all);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  int collisions = 0, checked = 0, any_self_collision = 0;
  std::string example;
  for (int n = 0; n < 3000; ++n) {
    Eigen::VectorXd q(7);
    for (int i = 0; i < 7; ++i)
      q[i] = m.joints()[i].lower_rad + u(rng) * (m.joints()[i].upper_rad - m.joints()[i].lower_rad);
    const CollisionResult r = world.Check(q);
    const auto caps = ArmCapsules(m, q);
    if (r.closest_self.distance_m < 0) {
      ++any_self_collision;
      example = r.closest_self.body_a + "/" + r.closest_self.body_b;
    }
    for (int i = 1; i <= 6; ++i) {
      for (int j = i + 2; j <= 6; ++j) {
        const PairDistance* p =
            FindPair(r, "iiwa_link_" + std::to_string(i), "iiwa_link_" + std::to_string(j));
        ASSERT_NE(p, nullptr) << i << "," << j;
        const double seg = SegmentSegmentDistance(caps[i].a, caps[i].b, caps[j].a, caps[j].b);
        if (seg < 1e-3) continue;
        EXPECT_NEAR(p->distance_m, seg - caps[i].r - caps[j].r, 1e-6) << i << "," << j;
        ++checked;
        if (p->distance_m < 0) ++collisions;
      }
    }
  }
  EXPECT_GT(checked, 10000);
  // Within the limits the folded arm can hit itself.
  EXPECT_GT(any_self_collision, 0);
  std::cout << "self-collisions in " << any_self_collision << " of 3000 random joint vectors (e.g. "
            << example << "); among the capsule links 1-6: " << collisions << "\n";
}

TEST(CollisionWorldTest, FoldedArmHitsItsBaseByHandComputedDepth) {
  // q2 = 120 tilts the upper arm 30 deg below horizontal (toward +x), q4 = -120 folds the forearm
  // back to 240 deg from vertical: direction (-sin 60, -cos 60). The link-5 capsule's lower cap
  // centre, 0.27 m down the forearm from joint 4, is then at
  //   x = 0.4 sin 120 + 0.27 sin 240 = 0.13 sin 60 = 0.112583 m,  z = 0.34 + 0.4 cos 120 + 0.27 cos 240 =
  //   0.005 m,
  // inside the base cylinder's height (0..0.15 m) and 0.012583 m out from its side (r 0.1), so the
  // capsule (r 0.065) sinks 0.065 - 0.012583 = 0.052417 m into the base.
  const RobotModel m = LoadIiwa();
  CollisionWorld world(m, nullptr);
  const CollisionResult r = world.Check(Deg({0, 120, 0, -120, 0, 0, 0}));
  EXPECT_TRUE(r.in_collision);
  ASSERT_TRUE(r.closest_self.valid());
  EXPECT_EQ(r.closest_self.body_a, "iiwa_link_0");
  EXPECT_EQ(r.closest_self.body_b, "iiwa_link_5");
  const double depth = 0.065 - (0.13 * std::sin(kPi / 3) - 0.1);
  // Penetration depth comes from EPA, which converges on a curved surface to within a few um
  // (separation distances are exact to ~1e-9).
  EXPECT_NEAR(r.closest_self.distance_m, -depth, 1e-5);
  EXPECT_NEAR(r.closest_self.normal_W.x(), -1.0, 1e-4);  // from link 5 toward the base: -x
}

TEST(CollisionWorldTest, LinksTwoApartNeverTouchWithinLimits) {
  // Each such pair's relative pose depends on one joint only (the links are symmetric about the
  // axes of the joints that could also move them), so a 0.05 deg sweep of that joint is a proof up
  // to a 0.5 mm sampling bound (< 0.6 m lever x 0.00087 rad); we require 1 mm.
  const RobotModel m = LoadIiwa();
  CollisionWorld::Options all;
  all.report_distance_m = 1e9;
  CollisionWorld world(m, nullptr, all);
  struct Case {
    const char* a;
    const char* b;
    int joint;
  };
  const Case cases[] = {{"iiwa_link_0", "iiwa_link_2", 1}, {"iiwa_link_1", "iiwa_link_3", 1},
                        {"iiwa_link_2", "iiwa_link_4", 3}, {"iiwa_link_3", "iiwa_link_5", 3},
                        {"iiwa_link_4", "iiwa_link_6", 4}, {"iiwa_link_5", "iiwa_link_7", 5},
                        {"iiwa_link_5", "iiwa_tool", 5}};
  for (const Case& c : cases) {
    double min_d = 1e9;
    const auto& j = m.joints()[c.joint];
    for (double x = j.lower_rad; x <= j.upper_rad + 1e-12; x += 0.05 * kPi / 180) {
      Eigen::VectorXd q = Deg({0, 0, 0, 0, 0, 0, 0});
      q[c.joint] = std::min(x, j.upper_rad);
      const CollisionResult r = world.Check(q);
      const PairDistance* p = FindPair(r, c.a, c.b);
      ASSERT_NE(p, nullptr);
      min_d = std::min(min_d, p->distance_m);
    }
    EXPECT_GT(min_d, 1e-3) << c.a << " vs " << c.b;
  }
}

TEST(CollisionWorldTest, ResultsAreFreshAndPruningChangesNothing) {
  const RobotModel m = LoadIiwa();
  const Scene scene = LoadSceneFile(orbed::SourceTreePath(kDefaultSceneRelativePath));
  CollisionWorld pruned(m, &scene);
  CollisionWorld::Options no_prune;
  no_prune.prune = false;
  CollisionWorld full(m, &scene, no_prune);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  for (int n = 0; n < 200; ++n) {
    Eigen::VectorXd q(7);
    for (int i = 0; i < 7; ++i)
      q[i] = m.joints()[i].lower_rad + u(rng) * (m.joints()[i].upper_rad - m.joints()[i].lower_rad);
    const CollisionResult a = pruned.Check(q), b = full.Check(q);
    EXPECT_EQ(a.in_collision, b.in_collision);
    EXPECT_DOUBLE_EQ(a.min_distance_m, b.min_distance_m);
    EXPECT_EQ(a.closest.body_a + a.closest.body_b, b.closest.body_a + b.closest.body_b);
    EXPECT_DOUBLE_EQ(a.closest_self.distance_m, b.closest_self.distance_m);
    EXPECT_DOUBLE_EQ(a.closest_environment.distance_m, b.closest_environment.distance_m);
    for (int i = 0; i < m.num_links(); ++i) EXPECT_DOUBLE_EQ(a.link_clearance_m[i], b.link_clearance_m[i]);
    EXPECT_EQ(a.contacts.size(), b.contacts.size());
  }
  // Colliding, free, colliding again: no state carries over.
  const Scene table = FloorScene(0.30);
  CollisionWorld world(m, &table);
  const Eigen::VectorXd down = Deg({0, 90, 0, 0, 0, 0, 0}), up = Eigen::VectorXd::Zero(7);
  const double d1 = world.Check(down).min_distance_m;
  EXPECT_FALSE(world.Check(up).in_collision);
  EXPECT_EQ(world.Check(down).min_distance_m, d1);
  EXPECT_EQ(pruned.num_self_pairs(), 27);
  EXPECT_THROW(world.Check(Eigen::VectorXd::Zero(6)), std::invalid_argument);
}

// --- The closed-form fast path against Bullet's GJK/EPA (Options::fast_path = false) ---

// Bullet's margin of a primitive: the radius of a sphere or capsule, kMarginM for boxes and
// cylinders. A pair whose distance exceeds -(margin_a + margin_b) has disjoint cores, so GJK (not
// EPA) decides it.
double Margin(const CollisionPrimitive& g) {
  return g.kind == Kind::kSphere || g.kind == Kind::kCapsule ? g.radius_m : CollisionWorld::kMarginM;
}

// Both paths exact: sphere, capsule and box pairs with disjoint cores (GJK on polytope cores stops
// at a relative 1e-12).
constexpr double kExactTolM = 1e-9;
// EPA on overlapping cores (sphere/capsule/box; measured ~1e-12, the fast path is exact there).
constexpr double kEpaTolM = 1e-6;
// GJK on a cylinder's curved side stops early and over-estimates the distance by up to ~3e-5 m;
// the fast path's sphere/capsule-cylinder distances are checked against an independent reference.
constexpr double kGjkCylinderTolM = 5e-5;

// Reference signed distance from a point (in the cylinder frame) to Bullet's rounded cylinder.
double PointRoundedCylinder(const Eigen::Vector3d& p, double radius, double length) {
  const double r = radius - CollisionWorld::kMarginM, h = 0.5 * length - CollisionWorld::kMarginM;
  const double side = std::sqrt(p.x() * p.x() + p.y() * p.y()) - r, cap = std::abs(p.z()) - h;
  const double outside = std::sqrt(std::pow(std::max(side, 0.0), 2) + std::pow(std::max(cap, 0.0), 2));
  return outside + std::min(std::max(side, cap), 0.0) - CollisionWorld::kMarginM;
}

// Reference distance of a sphere or capsule A to a cylinder B: the point distance minimised along
// A's axis by golden-section search (convex), to ~1e-15.
double ReferenceToCylinder(const CollisionPrimitive& a, const Eigen::Isometry3d& XA,
                           const CollisionPrimitive& b, const Eigen::Isometry3d& XB) {
  const double h = a.kind == Kind::kCapsule ? 0.5 * a.length_m : 0.0;
  const Eigen::Vector3d c = XB.inverse() * XA.translation(), z = XB.linear().transpose() * XA.linear().col(2);
  auto f = [&](double t) { return PointRoundedCylinder(c + t * z, b.radius_m, b.length_m); };
  double lo = -h, hi = h;
  const double g = 0.5 * (std::sqrt(5.0) - 1);
  for (int i = 0; i < 200 && hi - lo > 1e-15; ++i) {
    const double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
    (f(x1) < f(x2) ? hi : lo) = f(x1) < f(x2) ? x2 : x1;
  }
  return std::min({f(lo), f(hi), f(-h), f(h)}) - a.radius_m;
}

TEST(CollisionWorldTest, FastPathMatchesGjkForEveryPrimitivePair) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  auto random_primitive = [&](Kind kind) {
    CollisionPrimitive g;
    g.kind = kind;
    g.radius_m = 0.01 + 0.1 * u(rng);
    g.length_m = 0.02 + 0.3 * u(rng);
    g.size_m = Eigen::Vector3d(0.02 + 0.5 * u(rng), 0.02 + 0.5 * u(rng), 0.02 + 0.5 * u(rng));
    return g;
  };
  auto round = [](Kind k) { return k == Kind::kSphere || k == Kind::kCapsule; };
  const Kind kinds[] = {Kind::kSphere, Kind::kCapsule, Kind::kBox, Kind::kCylinder};
  int exact = 0, epa = 0, cylinder = 0;
  double max_exact = 0, max_epa = 0, max_ref = 0, max_gjk_cyl = 0, max_point = 0;
  for (Kind ka : kinds) {
    for (Kind kb : kinds) {
      for (int i = 0; i < 1500; ++i) {
        const CollisionPrimitive a = random_primitive(ka), b = random_primitive(kb);
        const Eigen::Isometry3d XA = RandomPose(rng, 0.25), XB = RandomPose(rng, 0.25);
        const PairDistance fast = CollisionWorld::PrimitiveDistance(a, XA, b, XB, true);
        const PairDistance gjk = CollisionWorld::PrimitiveDistance(a, XA, b, XB, false);
        const std::string what = std::to_string(static_cast<int>(ka)) + std::to_string(static_cast<int>(kb)) +
                                 " #" + std::to_string(i) + " fast " + std::to_string(fast.distance_m) +
                                 " gjk " + std::to_string(gjk.distance_m);
        const double diff = std::abs(fast.distance_m - gjk.distance_m);
        // The fast path's witnesses are consistent with its distance.
        EXPECT_NEAR((fast.p_WA - (fast.p_WB + fast.normal_W * fast.distance_m)).norm(), 0.0, 1e-12) << what;
        EXPECT_NEAR(fast.normal_W.norm(), 1.0, 1e-12) << what;
        const bool disjoint_cores = fast.distance_m > -(Margin(a) + Margin(b)) + 1e-6;
        const bool with_cylinder = ka == Kind::kCylinder || kb == Kind::kCylinder;
        if (with_cylinder && (round(ka) || round(kb))) {
          // Sphere/capsule against a cylinder: the fast path is exact, GJK over-estimates a little.
          const double ref =
              round(ka) ? ReferenceToCylinder(a, XA, b, XB) : ReferenceToCylinder(b, XB, a, XA);
          if (disjoint_cores || ka == Kind::kSphere || kb == Kind::kSphere) {
            EXPECT_NEAR(fast.distance_m, ref, kExactTolM) << what;
            max_ref = std::max(max_ref, std::abs(fast.distance_m - ref));
          }
          if (disjoint_cores) {
            ++cylinder;
            EXPECT_LE(fast.distance_m, gjk.distance_m + 1e-12) << what;
            EXPECT_LE(diff, kGjkCylinderTolM) << what;
            max_gjk_cyl = std::max(max_gjk_cyl, diff);
          }
        } else if (disjoint_cores) {
          ++exact;
          EXPECT_LE(diff, kExactTolM) << what;
          max_exact = std::max(max_exact, diff);
          if (fast.distance_m > 1e-3 && !with_cylinder) {  // closest points unique in random poses
            const double point_diff = std::max((fast.p_WA - gjk.p_WA).norm(), (fast.p_WB - gjk.p_WB).norm());
            EXPECT_LE(point_diff, 1e-6) << what;
            max_point = std::max(max_point, point_diff);
          }
        } else {
          ++epa;
          EXPECT_LE(diff, kEpaTolM) << what;
          max_epa = std::max(max_epa, diff);
        }
      }
    }
  }
  EXPECT_GT(exact, 10000);
  EXPECT_GT(epa, 1000);
  EXPECT_GT(cylinder, 5000);
  std::cout << "fast vs GJK: " << exact << " disjoint-core pairs, max |diff| " << max_exact
            << " m (closest points " << max_point << " m); " << epa << " overlapping-core pairs, max |diff| "
            << max_epa << " m; " << cylinder << " sphere/capsule-cylinder pairs: fast vs reference "
            << max_ref << " m, GJK over-estimates by up to " << max_gjk_cyl << " m\n";
}

TEST(CollisionWorldTest, SegmentBoxPenetrationIsExact) {
  // A capsule (r 0.05) through a box (half extents 0.3, 0.2, 0.1) with its axis 0.03 m below the
  // top face and parallel to x: the least way out is up, depth 0.03 + 0.05.
  CollisionPrimitive cap = Capsule(0.05, 0.2);
  CollisionPrimitive box;
  box.kind = Kind::kBox;
  box.size_m = Eigen::Vector3d(0.6, 0.4, 0.2);
  Eigen::Isometry3d XA = Eigen::Isometry3d::Identity();
  XA.linear() = Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  XA.translation() = Eigen::Vector3d(0.05, 0.02, 0.07);
  const PairDistance d = CollisionWorld::PrimitiveDistance(cap, XA, box, Eigen::Isometry3d::Identity());
  EXPECT_NEAR(d.distance_m, -0.08, 1e-12);
  EXPECT_NEAR(d.normal_W.z(), 1.0, 1e-12);
  EXPECT_NEAR(d.p_WB.z(), 0.1, 1e-12);
  EXPECT_NEAR(d.p_WA.z(), 0.02, 1e-12);
  EXPECT_NEAR(
      CollisionWorld::PrimitiveDistance(cap, XA, box, Eigen::Isometry3d::Identity(), false).distance_m, -0.08,
      1e-9);
}

TEST(CollisionWorldTest, FastPathMatchesGjkOverRandomConfigurations) {
  RobotModel m = LoadIiwa();
  const Scene scene = LoadSceneFile(orbed::SourceTreePath(kDefaultSceneRelativePath));
  m.SetToolLength(scene.tool_length_m);
  // Every pair reported (so every pair is compared), and the default options (pruned).
  CollisionWorld::Options all;
  all.report_distance_m = 1e9;
  CollisionWorld::Options all_gjk = all, def_gjk;
  all_gjk.fast_path = def_gjk.fast_path = false;
  CollisionWorld fast_all(m, &scene, all), gjk_all(m, &scene, all_gjk);
  CollisionWorld fast(m, &scene), gjk(m, &scene, def_gjk);
  // Per pair: the largest margin sum over its child pairs (disjoint-core test) and whether a
  // sphere/capsule meets a cylinder (where GJK is the inexact side).
  struct PairInfo {
    double margin_sum{0};
    bool round_vs_cylinder{false};
  };
  std::map<std::tuple<int, int, int>, PairInfo> info;
  for (const auto& p : fast.CheckedPairs()) {
    std::vector<CollisionPrimitive> bs =
        p.link_b >= 0 ? fast.LinkPrimitives(p.link_b) : std::vector<CollisionPrimitive>(1);
    if (p.link_b < 0) {
      const SceneObject& o = scene.objects[p.object_b];
      bs[0].kind = o.shape == SceneObject::Shape::kBox        ? Kind::kBox
                   : o.shape == SceneObject::Shape::kCylinder ? Kind::kCylinder
                                                              : Kind::kSphere;
      bs[0].radius_m = o.radius_m;
    }
    PairInfo& pi = info[{p.link_a, p.link_b, p.object_b}];
    for (const auto& ga : fast.LinkPrimitives(p.link_a)) {
      for (const auto& gb : bs) {
        pi.margin_sum = std::max(pi.margin_sum, Margin(ga) + Margin(gb));
        const bool ra = ga.kind == Kind::kSphere || ga.kind == Kind::kCapsule;
        const bool rb = gb.kind == Kind::kSphere || gb.kind == Kind::kCapsule;
        pi.round_vs_cylinder |= (ra && gb.kind == Kind::kCylinder) || (rb && ga.kind == Kind::kCylinder);
      }
    }
  }
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(0, 1);
  int exact = 0, epa = 0, cylinder = 0, fast_gjk_prims = 0, gjk_gjk_prims = 0, clearances = 0,
      clearances_1e9 = 0;
  double max_exact = 0, max_epa = 0, max_cyl = 0, max_clear = 0;
  for (int n = 0; n < 3000; ++n) {
    Eigen::VectorXd q(7);
    for (int i = 0; i < 7; ++i)
      q[i] = m.joints()[i].lower_rad + u(rng) * (m.joints()[i].upper_rad - m.joints()[i].lower_rad);
    // Per pair: fast vs GJK.
    const CollisionResult fa = fast_all.Check(q), ga = gjk_all.Check(q);
    ASSERT_EQ(fa.contacts.size(), ga.contacts.size());
    std::map<std::tuple<int, int, int>, const PairDistance*> gjk_pair;
    for (const auto& c : ga.contacts) gjk_pair[{c.link_a, c.link_b, c.object_b}] = &c;
    for (const auto& c : fa.contacts) {
      const auto key = std::make_tuple(c.link_a, c.link_b, c.object_b);
      ASSERT_EQ(gjk_pair.count(key), 1u);
      const double g = gjk_pair[key]->distance_m, diff = std::abs(c.distance_m - g);
      const PairInfo& pi = info[key];
      if (pi.round_vs_cylinder) {
        ++cylinder;
        max_cyl = std::max(max_cyl, diff);
        EXPECT_LE(diff, kGjkCylinderTolM) << c.body_a << "/" << c.body_b << " q#" << n;
      } else if (c.distance_m > -pi.margin_sum + 1e-6) {
        ++exact;
        max_exact = std::max(max_exact, diff);
        EXPECT_LE(diff, kExactTolM) << c.body_a << "/" << c.body_b << " q#" << n;
      } else {
        ++epa;
        max_epa = std::max(max_epa, diff);
        EXPECT_LE(diff, kEpaTolM) << c.body_a << "/" << c.body_b << " q#" << n;
      }
    }
    // The pruned default query equals the all-pairs one bit for bit (same path, fewer pairs).
    const CollisionResult f = fast.Check(q), g = gjk.Check(q);
    fast_gjk_prims += f.primitive_pairs_gjk;
    gjk_gjk_prims += g.primitive_pairs_gjk;
    EXPECT_EQ(f.min_distance_m, fa.min_distance_m) << "q#" << n;
    EXPECT_EQ(f.closest.body_a + "/" + f.closest.body_b, fa.closest.body_a + "/" + fa.closest.body_b)
        << "q#" << n;
    EXPECT_EQ(f.closest_self.distance_m, fa.closest_self.distance_m) << "q#" << n;
    EXPECT_EQ(f.closest_environment.distance_m, fa.closest_environment.distance_m) << "q#" << n;
    for (int i = 0; i < m.num_links(); ++i)
      EXPECT_EQ(f.link_clearance_m[i], fa.link_clearance_m[i]) << "q#" << n;
    // Fast vs GJK on the query result: the same closest pair (unless the runner-up is within GJK's
    // cylinder error) and the same clearances within the per-pair tolerances.
    EXPECT_EQ(f.in_collision, g.in_collision) << "q#" << n;
    EXPECT_NEAR(f.min_distance_m, g.min_distance_m, kGjkCylinderTolM) << "q#" << n;
    if (fa.contacts.size() < 2 ||
        fa.contacts[1].distance_m - fa.contacts[0].distance_m > 2 * kGjkCylinderTolM) {
      EXPECT_EQ(f.closest.body_a + "/" + f.closest.body_b, g.closest.body_a + "/" + g.closest.body_b)
          << "q#" << n;
    }
    for (int i = 0; i < m.num_links(); ++i) {
      const double gi = g.link_clearance_m[i], fi = f.link_clearance_m[i];
      if (std::isinf(gi)) {
        EXPECT_EQ(fi, gi);
        continue;
      }
      ++clearances;
      const double diff = std::abs(fi - gi);
      clearances_1e9 += diff <= kExactTolM;
      max_clear = std::max(max_clear, diff);
      EXPECT_LE(diff, kGjkCylinderTolM) << m.links()[i].name << " q#" << n;
    }
    EXPECT_EQ(f.contacts.size(), g.contacts.size()) << "q#" << n;
  }
  EXPECT_GT(exact, 100000);
  EXPECT_GT(epa, 100);
  EXPECT_LT(fast_gjk_prims, gjk_gjk_prims / 5);
  std::cout << "3000 configurations, fast vs GJK per pair: " << exact << " exact-both pairs max |diff| "
            << max_exact << " m; " << epa << " overlapping-core (EPA) pairs max " << max_epa << " m; "
            << cylinder << " sphere/capsule-cylinder pairs max " << max_cyl
            << " m (GJK's error). Per-link clearance: " << clearances_1e9 << " of " << clearances
            << " within 1e-9 m, max " << max_clear
            << " m. GJK primitive pairs per query: " << fast_gjk_prims / 3000.0 << " (fast path) vs "
            << gjk_gjk_prims / 3000.0 << " (GJK only)\n";
}

// Several arms: a second iiwa B at X_WB, 0.45 m from A and turned 160 deg, both at random joint
// vectors. Every pair of capsule links of A and B has the hand-computed segment distance minus both
// radii; the closest other-arm pair is the least of them (and of the non-capsule links), pruning
// changes nothing, and an arm whose poses were never set is not checked.
TEST(CollisionWorldTest, OtherArmDistancesMatchSegmentDistances) {
  const RobotModel m = LoadIiwa();
  CollisionWorld::Options all;
  all.report_distance_m = 1e9;
  CollisionWorld world(m, nullptr, all);
  CollisionWorld pruned(m, nullptr);  // default options: report nothing, prune
  EXPECT_EQ(world.num_other_arm_pairs(), 0);
  ASSERT_EQ(world.AddOtherArm("B", m), 0);
  ASSERT_EQ(pruned.AddOtherArm("B", m), 0);
  EXPECT_THROW(world.AddOtherArm("B", m), std::invalid_argument);
  int bodies = 0;
  for (const RobotLink& link : m.links()) bodies += link.collision.empty() ? 0 : 1;
  EXPECT_EQ(world.num_other_arm_pairs(), bodies * bodies);
  // Not posed yet: not checked.
  EXPECT_FALSE(world.Check(Eigen::VectorXd::Zero(7)).closest_other_arm.valid());

  const Eigen::Isometry3d X_WB =
      Eigen::Translation3d(0.45, 0.05, 0) * Eigen::AngleAxisd(160 * kDegToRad, Eigen::Vector3d::UnitZ());
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  auto random_q = [&] {
    Eigen::VectorXd q(7);
    for (int i = 0; i < 7; ++i)
      q[i] = m.joints()[i].lower_rad + u(rng) * (m.joints()[i].upper_rad - m.joints()[i].lower_rad);
    return q;
  };
  int checked = 0, collisions = 0;
  for (int n = 0; n < 500; ++n) {
    const Eigen::VectorXd q_A = random_q(), q_B = random_q();
    std::vector<Eigen::Isometry3d> X_WL_B = m.CalcLinkPoses(q_B);
    for (auto& X : X_WL_B) X = X_WB * X;
    EXPECT_TRUE(world.SetOtherArmLinkPoses(0, X_WL_B));   // moved
    EXPECT_FALSE(world.SetOtherArmLinkPoses(0, X_WL_B));  // the same poses again: nothing changed
    pruned.SetOtherArmLinkPoses(0, X_WL_B);
    const CollisionResult r = world.Check(q_A);
    const auto caps_A = ArmCapsules(m, q_A);
    auto caps_B = ArmCapsules(m, q_B);
    for (auto& c : caps_B) c.a = X_WB * c.a, c.b = X_WB * c.b;
    double least = std::numeric_limits<double>::infinity();
    for (const PairDistance& p : r.contacts) {
      if (p.arm_b >= 0) least = std::min(least, p.distance_m);
    }
    ASSERT_TRUE(r.closest_other_arm.valid());
    EXPECT_EQ(r.closest_other_arm.distance_m, least);
    EXPECT_EQ(r.closest_other_arm.body_b.rfind("B/", 0), 0u) << r.closest_other_arm.body_b;
    for (int i = 1; i <= 6; ++i) {
      for (int j = 1; j <= 6; ++j) {
        const PairDistance* p =
            FindPair(r, "iiwa_link_" + std::to_string(i), "B/iiwa_link_" + std::to_string(j));
        ASSERT_NE(p, nullptr) << i << "," << j;
        EXPECT_FALSE(p->self);
        EXPECT_EQ(p->arm_b, 0);
        EXPECT_LE(r.link_clearance_m[m.FindLink("iiwa_link_" + std::to_string(i))], p->distance_m);
        const double seg = SegmentSegmentDistance(caps_A[i].a, caps_A[i].b, caps_B[j].a, caps_B[j].b);
        if (seg < 1e-3) continue;  // crossing axes: the depth is not seg - r - r
        EXPECT_NEAR(p->distance_m, seg - caps_A[i].r - caps_B[j].r, 1e-6) << i << "," << j;
        ++checked;
        if (p->distance_m < 0) ++collisions;
      }
    }
    // Pruned, the answers are the same.
    const CollisionResult rp = pruned.Check(q_A);
    EXPECT_EQ(rp.closest_other_arm.distance_m, r.closest_other_arm.distance_m);
    EXPECT_EQ(rp.min_distance_m, r.min_distance_m);
    EXPECT_EQ(rp.link_clearance_m, r.link_clearance_m);
  }
  EXPECT_GT(checked, 15000);
  EXPECT_GT(collisions, 0);  // 0.45 m apart, the arms do collide
  EXPECT_THROW(world.SetOtherArmLinkPoses(1, std::vector<Eigen::Isometry3d>(m.num_links())),
               std::invalid_argument);
  EXPECT_THROW(world.SetOtherArmLinkPoses(0, std::vector<Eigen::Isometry3d>(2)), std::invalid_argument);
}

TEST(CollisionWorldTest, UnknownIgnoredLinkIsAnError) {
  const RobotModel m = LoadIiwa();
  Scene scene = FloorScene(0.1);
  scene.objects[0].ignore_links.push_back("iiwa_link_9");
  EXPECT_THROW(CollisionWorld(m, &scene), std::invalid_argument);
}

}  // namespace
}  // namespace orbed::sim
