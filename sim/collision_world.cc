#include "sim/collision_world.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <btBulletCollisionCommon.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkPairDetector.h>
#include <BulletCollision/NarrowPhaseCollision/btPointCollector.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>

namespace orbed::sim {
namespace {

static_assert(sizeof(btScalar) == sizeof(double), "orbed needs Bullet built with BT_USE_DOUBLE_PRECISION");

using Kind = CollisionPrimitive::Kind;
constexpr double kInf = std::numeric_limits<double>::infinity();

btTransform ToBt(const Eigen::Isometry3d& X) {
  const Eigen::Matrix3d& R = X.linear();
  btMatrix3x3 basis(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2));
  return btTransform(basis, btVector3(X.translation().x(), X.translation().y(), X.translation().z()));
}

Eigen::Vector3d ToEigen(const btVector3& v) { return Eigen::Vector3d(v.x(), v.y(), v.z()); }

std::unique_ptr<btConvexShape> MakeShape(const CollisionPrimitive& g) {
  std::unique_ptr<btConvexShape> shape;
  switch (g.kind) {
    case Kind::kSphere:
      shape = std::make_unique<btSphereShape>(g.radius_m);
      break;
    case Kind::kCapsule:
      shape = std::make_unique<btCapsuleShapeZ>(g.radius_m, g.length_m);
      break;
    case Kind::kCylinder:
      shape = std::make_unique<btCylinderShapeZ>(btVector3(g.radius_m, g.radius_m, 0.5 * g.length_m));
      shape->setMargin(CollisionWorld::kMarginM);
      break;
    case Kind::kBox:
      shape = std::make_unique<btBoxShape>(btVector3(0.5 * g.size_m.x(), 0.5 * g.size_m.y(), 0.5 * g.size_m.z()));
      shape->setMargin(CollisionWorld::kMarginM);
      break;
  }
  return shape;
}

// Radius of the sphere about the primitive's origin that contains it.
double BoundingRadius(const CollisionPrimitive& g) {
  switch (g.kind) {
    case Kind::kSphere: return g.radius_m;
    case Kind::kCapsule: return 0.5 * g.length_m + g.radius_m;
    case Kind::kCylinder: return std::hypot(0.5 * g.length_m, g.radius_m);
    case Kind::kBox: return 0.5 * g.size_m.norm();
  }
  return kInf;
}

// Signed distance from a point (in the primitive's frame) to the primitive; a lower bound is enough
// but these are exact.
double PointDistance(const CollisionPrimitive& g, const Eigen::Vector3d& p) {
  switch (g.kind) {
    case Kind::kSphere: return p.norm() - g.radius_m;
    case Kind::kCapsule: {
      const double h = 0.5 * g.length_m;
      const Eigen::Vector3d c(0, 0, std::clamp(p.z(), -h, h));
      return (p - c).norm() - g.radius_m;
    }
    case Kind::kCylinder: {
      const Eigen::Vector2d q(std::hypot(p.x(), p.y()) - g.radius_m, std::abs(p.z()) - 0.5 * g.length_m);
      return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
    }
    case Kind::kBox: {
      const Eigen::Vector3d q = p.cwiseAbs() - 0.5 * g.size_m;
      return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
    }
  }
  return -kInf;
}

// Replaces each cylinder capped by two spheres of its radius at its end-face centres with a capsule.
std::vector<CollisionPrimitive> FuseCapsules(const std::vector<CollisionPrimitive>& in) {
  std::vector<bool> used(in.size(), false);
  std::vector<CollisionPrimitive> out;
  for (size_t i = 0; i < in.size(); ++i) {
    if (in[i].kind != Kind::kCylinder) continue;
    const CollisionPrimitive& c = in[i];
    const Eigen::Vector3d axis = c.X_LG.linear().col(2);
    const Eigen::Vector3d ends[2] = {c.X_LG.translation() + 0.5 * c.length_m * axis,
                                     c.X_LG.translation() - 0.5 * c.length_m * axis};
    int caps[2] = {-1, -1};
    for (int e = 0; e < 2; ++e) {
      for (size_t j = 0; j < in.size(); ++j) {
        if (used[j] || j == i || in[j].kind != Kind::kSphere) continue;
        if (std::abs(in[j].radius_m - c.radius_m) < 1e-12 && (in[j].X_LG.translation() - ends[e]).norm() < 1e-9 &&
            static_cast<int>(j) != caps[0]) {
          caps[e] = static_cast<int>(j);
          break;
        }
      }
    }
    if (caps[0] >= 0 && caps[1] >= 0) {
      used[i] = used[caps[0]] = used[caps[1]] = true;
      CollisionPrimitive cap = c;
      cap.kind = Kind::kCapsule;
      out.push_back(cap);
    }
  }
  for (size_t i = 0; i < in.size(); ++i) {
    if (!used[i]) out.push_back(in[i]);
  }
  return out;
}

struct Child {
  CollisionPrimitive prim;
  std::unique_ptr<btConvexShape> shape;
  double bound_radius_m{0};
  Eigen::Isometry3d X_WC{Eigen::Isometry3d::Identity()};  // updated every query
  Eigen::Isometry3d X_CW{Eigen::Isometry3d::Identity()};  // inverse, kept for static (scene) children
  btTransform bt_X_WC;
};

struct Body {
  std::string name;
  int link{-1};
  int object{-1};
  std::vector<Child> children;
  std::unique_ptr<btCompoundShape> compound;
  std::unique_ptr<btCollisionObject> object_bt;
};

struct Pair {
  int a;  // body index (a robot link)
  int b;  // body index
  bool self;
};

// One exact signed distance between two posed convex shapes.
void GjkDistance(const btConvexShape* a, const btTransform& X_WA, const btConvexShape* b, const btTransform& X_WB,
                 PairDistance* out) {
  btVoronoiSimplexSolver simplex;
  btGjkEpaPenetrationDepthSolver epa;
  btGjkPairDetector gjk(a, b, &simplex, &epa);
  btDiscreteCollisionDetectorInterface::ClosestPointInput input;
  input.m_transformA = X_WA;
  input.m_transformB = X_WB;
  input.m_maximumDistanceSquared = BT_LARGE_FLOAT;
  btPointCollector result;
  gjk.getClosestPoints(input, result, nullptr);
  if (!result.m_hasResult) {
    // GJK and EPA both gave up: only possible for degenerate deep overlaps. Report a penetration
    // of unknown depth rather than a false clearance.
    out->distance_m = -0.0;
    out->p_WA = out->p_WB = ToEigen(X_WA.getOrigin());
    return;
  }
  out->distance_m = result.m_distance;
  out->p_WB = ToEigen(result.m_pointInWorld);
  out->normal_W = ToEigen(result.m_normalOnBInWorld);
  out->p_WA = out->p_WB + out->normal_W * result.m_distance;
}

}  // namespace

struct CollisionWorld::Impl {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btCollisionWorld world{&dispatcher, &broadphase, &config};
  std::vector<Body> bodies;
  std::vector<int> body_of_link;  // robot link -> body index or -1
  std::vector<std::string> object_names;
  std::vector<Pair> pairs;
  // Scratch for queries.
  std::vector<double> lower_bound;
  std::vector<int> order;

  ~Impl() {
    for (auto& b : bodies) world.removeCollisionObject(b.object_bt.get());
  }

  void AddBody(Body body, const Eigen::Isometry3d& X_WB) {
    body.compound = std::make_unique<btCompoundShape>(/*enableDynamicAabbTree=*/false);
    for (auto& c : body.children) {
      c.shape = MakeShape(c.prim);
      c.bound_radius_m = BoundingRadius(c.prim);
      body.compound->addChildShape(ToBt(c.prim.X_LG), c.shape.get());
      c.X_WC = X_WB * c.prim.X_LG;
      c.X_CW = c.X_WC.inverse();
      c.bt_X_WC = ToBt(c.X_WC);
    }
    body.object_bt = std::make_unique<btCollisionObject>();
    body.object_bt->setCollisionShape(body.compound.get());
    body.object_bt->setWorldTransform(ToBt(X_WB));
    world.addCollisionObject(body.object_bt.get());
    bodies.push_back(std::move(body));
  }
};

CollisionWorld::CollisionWorld(const RobotModel& model, const Scene* scene)
    : CollisionWorld(model, scene, Options{}) {}

CollisionWorld::CollisionWorld(const RobotModel& model, const Scene* scene, const Options& options)
    : model_(model), options_(options), impl_(std::make_unique<Impl>()) {
  if (scene) X_WR_ = scene->X_WR;
  Impl& im = *impl_;
  im.body_of_link.assign(model_.num_links(), -1);
  const auto X_RL = model_.CalcLinkPoses(Eigen::VectorXd::Zero(model_.num_joints()));
  for (int i = 0; i < model_.num_links(); ++i) {
    const RobotLink& link = model_.links()[i];
    if (link.collision.empty()) continue;
    Body body;
    body.name = link.name;
    body.link = i;
    for (const auto& prim : FuseCapsules(link.collision)) {
      Child c;
      c.prim = prim;
      body.children.push_back(std::move(c));
    }
    im.body_of_link[i] = static_cast<int>(im.bodies.size());
    im.AddBody(std::move(body), X_WR_ * X_RL[i]);
  }
  const int num_robot_bodies = static_cast<int>(im.bodies.size());
  if (scene) {
    for (size_t k = 0; k < scene->objects.size(); ++k) {
      const SceneObject& o = scene->objects[k];
      Body body;
      body.name = o.name;
      body.object = static_cast<int>(k);
      Child c;
      switch (o.shape) {
        case SceneObject::Shape::kBox:
          c.prim.kind = Kind::kBox;
          c.prim.size_m = o.size_m;
          break;
        case SceneObject::Shape::kCylinder:
          c.prim.kind = Kind::kCylinder;
          c.prim.radius_m = o.radius_m;
          c.prim.length_m = o.length_m;
          break;
        case SceneObject::Shape::kSphere:
          c.prim.kind = Kind::kSphere;
          c.prim.radius_m = o.radius_m;
          break;
      }
      c.prim.name = o.name;
      body.children.push_back(std::move(c));
      im.object_names.push_back(o.name);
      im.AddBody(std::move(body), o.X_WO);
    }
  }
  // Pairs.
  for (int a = 0; a < num_robot_bodies; ++a) {
    const int link_a = im.bodies[a].link;
    for (int b = a + 1; b < num_robot_bodies; ++b) {
      const int link_b = im.bodies[b].link;
      const int separation = model_.BodySeparation(model_.links()[link_a].body, model_.links()[link_b].body);
      if (separation < std::max(2, options_.min_self_separation)) continue;
      im.pairs.push_back({a, b, true});
    }
  }
  if (scene) {
    for (int b = num_robot_bodies; b < static_cast<int>(im.bodies.size()); ++b) {
      const SceneObject& o = scene->objects[im.bodies[b].object];
      for (const auto& name : o.ignore_links) {
        if (model_.FindLink(name) < 0) {
          throw std::invalid_argument(scene->source + ": object '" + o.name + "' ignore_links names '" + name +
                                      "', which is not a link of " + model_.source_name());
        }
      }
      for (int a = 0; a < num_robot_bodies; ++a) {
        const std::string& link_name = im.bodies[a].name;
        if (std::find(o.ignore_links.begin(), o.ignore_links.end(), link_name) != o.ignore_links.end()) continue;
        im.pairs.push_back({a, b, false});
      }
    }
  }
}

CollisionWorld::~CollisionWorld() = default;

int CollisionWorld::num_self_pairs() const {
  return static_cast<int>(std::count_if(impl_->pairs.begin(), impl_->pairs.end(), [](const Pair& p) { return p.self; }));
}

int CollisionWorld::num_environment_pairs() const {
  return static_cast<int>(impl_->pairs.size()) - num_self_pairs();
}

CollisionResult CollisionWorld::Check(const Eigen::VectorXd& q_rad) {
  if (q_rad.size() != model_.num_joints() || !q_rad.allFinite()) {
    throw std::invalid_argument("CollisionWorld::Check: expected " + std::to_string(model_.num_joints()) +
                                " finite joint values, got " + std::to_string(q_rad.size()));
  }
  model_.CalcLinkPoses(q_rad, &X_RL_scratch_);
  return CheckPoses(X_RL_scratch_);
}

CollisionResult CollisionWorld::CheckPoses(const std::vector<Eigen::Isometry3d>& X_RL) {
  if (static_cast<int>(X_RL.size()) != model_.num_links()) {
    throw std::invalid_argument("CollisionWorld::CheckPoses: expected " + std::to_string(model_.num_links()) +
                                " link poses, got " + std::to_string(X_RL.size()));
  }
  Impl& im = *impl_;
  // Pose the robot bodies (scene bodies are static).
  for (auto& body : im.bodies) {
    if (body.link < 0) continue;
    const Eigen::Isometry3d X_WL = X_WR_ * X_RL[body.link];
    body.object_bt->setWorldTransform(ToBt(X_WL));
    for (auto& c : body.children) {
      c.X_WC = X_WL * c.prim.X_LG;
      c.bt_X_WC = ToBt(c.X_WC);
    }
  }

  CollisionResult result;
  result.link_clearance_m.assign(model_.num_links(), kInf);
  const size_t n = im.pairs.size();
  im.lower_bound.resize(n);
  im.order.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const Pair& p = im.pairs[i];
    const Body& A = im.bodies[p.a];
    const Body& B = im.bodies[p.b];
    double lb = kInf;
    for (const Child& ca : A.children) {
      for (const Child& cb : B.children) {
        double d;
        if (p.self) {
          d = (ca.X_WC.translation() - cb.X_WC.translation()).norm() - ca.bound_radius_m - cb.bound_radius_m;
        } else {
          d = PointDistance(cb.prim, cb.X_CW * ca.X_WC.translation()) - ca.bound_radius_m;
        }
        lb = std::min(lb, d);
      }
    }
    im.lower_bound[i] = lb;
    im.order[i] = static_cast<int>(i);
  }
  if (options_.prune) {
    std::sort(im.order.begin(), im.order.end(),
              [&](int x, int y) { return im.lower_bound[x] < im.lower_bound[y]; });
  }

  for (int idx : im.order) {
    const Pair& p = im.pairs[idx];
    if (p.self && !options_.check_self) continue;
    const Body& A = im.bodies[p.a];
    const Body& B = im.bodies[p.b];
    const double lb = im.lower_bound[idx];
    if (options_.prune) {
      // Skip only what cannot lower link A's or B's clearance, its group's closest pair (and so the
      // overall minimum) or enter the report list.
      const double clear_b = p.self ? result.link_clearance_m[B.link] : -kInf;
      const double group_min = p.self ? result.closest_self.distance_m : result.closest_environment.distance_m;
      if (lb >= result.link_clearance_m[A.link] && lb >= clear_b && lb >= group_min &&
          lb >= options_.report_distance_m) {
        continue;
      }
    }
    PairDistance best;
    for (const Child& ca : A.children) {
      for (const Child& cb : B.children) {
        PairDistance d;
        GjkDistance(ca.shape.get(), ca.bt_X_WC, cb.shape.get(), cb.bt_X_WC, &d);
        if (d.distance_m < best.distance_m) best = d;
      }
    }
    ++result.pairs_computed;
    best.link_a = A.link;
    best.link_b = B.link;
    best.object_b = B.object;
    best.self = p.self;
    double& ca = result.link_clearance_m[A.link];
    ca = std::min(ca, best.distance_m);
    if (p.self) {
      double& cb = result.link_clearance_m[B.link];
      cb = std::min(cb, best.distance_m);
    }
    PairDistance& group = p.self ? result.closest_self : result.closest_environment;
    if (best.distance_m < group.distance_m) group = best;
    if (best.distance_m < result.min_distance_m) {
      result.min_distance_m = best.distance_m;
      result.closest = best;
    }
    if (best.distance_m < options_.report_distance_m) result.contacts.push_back(best);
  }
  std::sort(result.contacts.begin(), result.contacts.end(),
            [](const PairDistance& x, const PairDistance& y) { return x.distance_m < y.distance_m; });
  // Names only for what is returned (string copies are most of a query's cost otherwise).
  auto name = [&](PairDistance& d) {
    if (!d.valid()) return;
    d.body_a = im.bodies[im.body_of_link[d.link_a]].name;
    d.body_b = d.link_b >= 0 ? im.bodies[im.body_of_link[d.link_b]].name : im.object_names[d.object_b];
  };
  name(result.closest);
  name(result.closest_self);
  name(result.closest_environment);
  for (auto& c : result.contacts) name(c);
  result.in_collision = result.min_distance_m <= 0.0;
  return result;
}

std::vector<CollisionWorld::CheckedPair> CollisionWorld::CheckedPairs() const {
  std::vector<CheckedPair> out;
  for (const Pair& p : impl_->pairs) {
    const Body& A = impl_->bodies[p.a];
    const Body& B = impl_->bodies[p.b];
    out.push_back({A.link, B.link, B.object});
  }
  return out;
}

std::vector<CollisionPrimitive> CollisionWorld::LinkPrimitives(int link) const {
  std::vector<CollisionPrimitive> out;
  if (link < 0 || link >= static_cast<int>(impl_->body_of_link.size()) || impl_->body_of_link[link] < 0) return out;
  for (const Child& c : impl_->bodies[impl_->body_of_link[link]].children) out.push_back(c.prim);
  return out;
}

PairDistance CollisionWorld::PrimitiveDistance(const CollisionPrimitive& a, const Eigen::Isometry3d& X_WA,
                                               const CollisionPrimitive& b, const Eigen::Isometry3d& X_WB) {
  const auto sa = MakeShape(a);
  const auto sb = MakeShape(b);
  PairDistance d;
  GjkDistance(sa.get(), ToBt(X_WA), sb.get(), ToBt(X_WB), &d);
  return d;
}

}  // namespace orbed::sim
