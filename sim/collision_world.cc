#include "sim/collision_world.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkPairDetector.h>
#include <BulletCollision/NarrowPhaseCollision/btPointCollector.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>
#include <btBulletCollisionCommon.h>

#include "sim/distance_closed_form.h"

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
      shape =
          std::make_unique<btBoxShape>(btVector3(0.5 * g.size_m.x(), 0.5 * g.size_m.y(), 0.5 * g.size_m.z()));
      shape->setMargin(CollisionWorld::kMarginM);
      break;
  }
  return shape;
}

// Radius of the sphere about the primitive's origin that contains it.
double BoundingRadius(const CollisionPrimitive& g) {
  switch (g.kind) {
    case Kind::kSphere:
      return g.radius_m;
    case Kind::kCapsule:
      return 0.5 * g.length_m + g.radius_m;
    case Kind::kCylinder:
      return std::hypot(0.5 * g.length_m, g.radius_m);
    case Kind::kBox:
      return 0.5 * g.size_m.norm();
  }
  return kInf;
}

// Signed distance from a point (in the primitive's frame) to the primitive; a lower bound is enough
// but these are exact.
double PointDistance(const CollisionPrimitive& g, const Eigen::Vector3d& p) {
  switch (g.kind) {
    case Kind::kSphere:
      return p.norm() - g.radius_m;
    case Kind::kCapsule: {
      const double h = 0.5 * g.length_m;
      const Eigen::Vector3d c(0, 0, std::clamp(p.z(), -h, h));
      return (p - c).norm() - g.radius_m;
    }
    case Kind::kCylinder: {
      const Eigen::Vector2d q(std::sqrt(p.x() * p.x() + p.y() * p.y()) - g.radius_m,
                              std::abs(p.z()) - 0.5 * g.length_m);
      return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
    }
    case Kind::kBox: {
      const Eigen::Vector3d q = p.cwiseAbs() - 0.5 * g.size_m;
      return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
    }
  }
  return -kInf;
}

// The fast path's view of a Bullet shape: its core and margin as Bullet itself stores them.
CoreShape CoreOf(const CollisionPrimitive& g, const btConvexShape& shape) {
  CoreShape c;
  c.margin_m = shape.getMargin();
  switch (g.kind) {
    case Kind::kSphere:
      c.kind = CoreShape::Kind::kPoint;
      break;
    case Kind::kCapsule:
      c.kind = CoreShape::Kind::kSegment;
      c.half_length_m = static_cast<const btCapsuleShape&>(shape).getHalfHeight();
      break;
    case Kind::kBox: {
      c.kind = CoreShape::Kind::kBox;
      const btVector3& e = static_cast<const btBoxShape&>(shape).getHalfExtentsWithoutMargin();
      c.half_extents_m = Eigen::Vector3d(e.x(), e.y(), e.z());
      break;
    }
    case Kind::kCylinder: {
      c.kind = CoreShape::Kind::kCylinder;
      const btVector3& e = static_cast<const btCylinderShape&>(shape).getHalfExtentsWithoutMargin();
      c.half_extents_m = Eigen::Vector3d(e.x(), e.x(), e.z());  // btCylinderShapeZ: radius x, half height z
      break;
    }
  }
  return c;
}

struct Child {
  CollisionPrimitive prim;
  std::unique_ptr<btConvexShape> shape;
  CoreShape core;
  double bound_radius_m{0};
  Eigen::Isometry3d X_WC{Eigen::Isometry3d::Identity()};  // updated every query
  Eigen::Isometry3d X_CW{Eigen::Isometry3d::Identity()};  // inverse, kept for static (scene) children
};

struct Body {
  std::string name;
  int link{-1};
  int object{-1};
  int arm{-1};       // another arm's index (AddOtherArm), -1 for this arm's links and the scene
  int arm_link{-1};  // that arm's link index
  std::vector<Child> children;
  std::unique_ptr<btCompoundShape> compound;
  std::unique_ptr<btCollisionObject> object_bt;
  // Pose bookkeeping for the pair cache: `epoch` changes whenever X_WL differs (bitwise) from the
  // previous query's; scene bodies never change.
  Eigen::Isometry3d X_WL{Eigen::Isometry3d::Identity()};
  long epoch{0};
};

enum class Group { kSelf = 0, kEnvironment = 1, kOtherArm = 2 };

struct Pair {
  int a;  // body index (a robot link)
  int b;  // body index
  Group group;
  bool self() const { return group == Group::kSelf; }
  // Both bodies move (self and other-arm pairs): bounding spheres on both sides.
  bool moving() const { return group != Group::kEnvironment; }
};

// The last exact result of a pair and the body epochs (and path) it was computed at: when neither
// body moved, the same inputs give the same output, so it is reused (the base link and the scene).
struct PairCache {
  long epoch_a{-1};
  long epoch_b{-1};
  bool fast_path{false};
  SignedDistance distance;
};

// One exact signed distance between two posed convex shapes by GJK (EPA when the cores overlap).
void GjkDistance(const btConvexShape* a, const btTransform& X_WA, const btConvexShape* b,
                 const btTransform& X_WB, SignedDistance* out) {
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
    out->normal_W = Eigen::Vector3d::UnitZ();
    return;
  }
  out->distance_m = result.m_distance;
  out->p_WB = ToEigen(result.m_pointInWorld);
  out->normal_W = ToEigen(result.m_normalOnBInWorld);
  out->p_WA = out->p_WB + out->normal_W * result.m_distance;
}

// The signed distance of one primitive pair: the closed forms where they apply (fast_path), else
// Bullet's GJK/EPA. Returns true if GJK/EPA was used.
bool ChildDistance(const Child& a, const Child& b, bool fast_path, SignedDistance* out) {
  if (fast_path && ClosedFormDistance(a.core, a.X_WC, b.core, b.X_WC, out)) return false;
  GjkDistance(a.shape.get(), ToBt(a.X_WC), b.shape.get(), ToBt(b.X_WC), out);
  return true;
}

// Lower bound on the distance of two children: bounding spheres when both move (self and
// other-arm pairs), the exact scene shape against the robot child's bounding sphere otherwise.
double ChildLowerBound(const Child& ca, const Child& cb, bool moving) {
  if (moving)
    return (ca.X_WC.translation() - cb.X_WC.translation()).norm() - ca.bound_radius_m - cb.bound_radius_m;
  return PointDistance(cb.prim, cb.X_CW * ca.X_WC.translation()) - ca.bound_radius_m;
}

}  // namespace

struct CollisionWorld::Impl {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btCollisionWorld world{&dispatcher, &broadphase, &config};
  std::vector<Body> bodies;
  std::vector<int> body_of_link;  // robot link -> body index or -1
  int num_robot_bodies{0};        // bodies [0, num_robot_bodies) are this arm's links
  // Other arms: their names, whether their poses were set, and their link -> body index (or -1).
  std::vector<std::string> arm_names;
  std::vector<char> arm_posed;
  std::vector<std::vector<int>> body_of_arm_link;
  std::vector<std::string> object_names;
  std::vector<Pair> pairs;
  // Scratch for queries (sized once, reused).
  std::vector<double> lower_bound;
  std::vector<char> done;
  std::vector<int>
      seed;  // per link, then the self, environment and other-arm groups: the pair of least bound
  std::vector<PairCache> cache;  // per pair

  ~Impl() {
    for (auto& b : bodies) world.removeCollisionObject(b.object_bt.get());
  }

  void AddBody(Body body, const Eigen::Isometry3d& X_WB) {
    body.compound = std::make_unique<btCompoundShape>(/*enableDynamicAabbTree=*/false);
    for (auto& c : body.children) {
      c.shape = MakeShape(c.prim);
      c.core = CoreOf(c.prim, *c.shape);
      c.bound_radius_m = BoundingRadius(c.prim);
      body.compound->addChildShape(ToBt(c.prim.X_LG), c.shape.get());
      c.X_WC = X_WB * c.prim.X_LG;
      c.X_CW = c.X_WC.inverse();
    }
    body.object_bt = std::make_unique<btCollisionObject>();
    body.object_bt->setCollisionShape(body.compound.get());
    body.object_bt->setWorldTransform(ToBt(X_WB));
    body.X_WL = X_WB;
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
  im.num_robot_bodies = num_robot_bodies;
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
      im.pairs.push_back({a, b, Group::kSelf});
    }
  }
  if (scene) {
    for (int b = num_robot_bodies; b < static_cast<int>(im.bodies.size()); ++b) {
      const SceneObject& o = scene->objects[im.bodies[b].object];
      for (const auto& name : o.ignore_links) {
        if (model_.FindLink(name) < 0) {
          throw std::invalid_argument(scene->source + ": object '" + o.name + "' ignore_links names '" +
                                      name + "', which is not a link of " + model_.source_name());
        }
      }
      for (int a = 0; a < num_robot_bodies; ++a) {
        const std::string& link_name = im.bodies[a].name;
        if (std::find(o.ignore_links.begin(), o.ignore_links.end(), link_name) != o.ignore_links.end())
          continue;
        im.pairs.push_back({a, b, Group::kEnvironment});
      }
    }
  }
}

CollisionWorld::~CollisionWorld() = default;

int CollisionWorld::num_self_pairs() const {
  return static_cast<int>(
      std::count_if(impl_->pairs.begin(), impl_->pairs.end(), [](const Pair& p) { return p.self(); }));
}

int CollisionWorld::num_environment_pairs() const {
  return static_cast<int>(std::count_if(impl_->pairs.begin(), impl_->pairs.end(),
                                        [](const Pair& p) { return p.group == Group::kEnvironment; }));
}

int CollisionWorld::num_other_arm_pairs() const {
  return static_cast<int>(impl_->pairs.size()) - num_self_pairs() - num_environment_pairs();
}

int CollisionWorld::AddOtherArm(const std::string& name, const RobotModel& other) {
  Impl& im = *impl_;
  if (name.empty() || std::find(im.arm_names.begin(), im.arm_names.end(), name) != im.arm_names.end()) {
    throw std::invalid_argument("CollisionWorld::AddOtherArm: expected a new non-empty arm name, got '" +
                                name + "'");
  }
  const int arm = static_cast<int>(im.arm_names.size());
  im.arm_names.push_back(name);
  im.arm_posed.push_back(0);
  im.body_of_arm_link.emplace_back(other.num_links(), -1);
  for (int i = 0; i < other.num_links(); ++i) {
    const RobotLink& link = other.links()[i];
    if (link.collision.empty()) continue;
    Body body;
    body.name = name + "/" + link.name;
    body.arm = arm;
    body.arm_link = i;
    for (const auto& prim : FuseCapsules(link.collision)) {
      Child c;
      c.prim = prim;
      body.children.push_back(std::move(c));
    }
    const int b = static_cast<int>(im.bodies.size());
    im.body_of_arm_link[arm][i] = b;
    im.AddBody(std::move(body), Eigen::Isometry3d::Identity());
    for (int a = 0; a < im.num_robot_bodies; ++a) im.pairs.push_back({a, b, Group::kOtherArm});
  }
  im.cache.clear();
  return arm;
}

bool CollisionWorld::SetOtherArmLinkPoses(int arm, const std::vector<Eigen::Isometry3d>& X_WL) {
  Impl& im = *impl_;
  if (arm < 0 || arm >= static_cast<int>(im.arm_names.size()) ||
      X_WL.size() != im.body_of_arm_link[arm].size()) {
    throw std::invalid_argument("CollisionWorld::SetOtherArmLinkPoses: no arm " + std::to_string(arm) +
                                " with " + std::to_string(X_WL.size()) + " links");
  }
  for (const Eigen::Isometry3d& X : X_WL) {
    if (!X.matrix().allFinite()) {
      throw std::invalid_argument("CollisionWorld::SetOtherArmLinkPoses: a non-finite pose of arm '" +
                                  im.arm_names[arm] + "'");
    }
  }
  bool changed = !im.arm_posed[arm];
  for (size_t i = 0; i < X_WL.size(); ++i) {
    const int b = im.body_of_arm_link[arm][i];
    if (b < 0) continue;
    Body& body = im.bodies[b];
    if (X_WL[i].matrix() == body.X_WL.matrix()) continue;
    changed = true;
    ++body.epoch;
    body.X_WL = X_WL[i];
    body.object_bt->setWorldTransform(ToBt(X_WL[i]));
    for (auto& c : body.children) c.X_WC = X_WL[i] * c.prim.X_LG;
  }
  im.arm_posed[arm] = 1;
  return changed;
}

int CollisionWorld::num_other_arms() const { return static_cast<int>(impl_->arm_names.size()); }

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
    if (X_WL.matrix() == body.X_WL.matrix()) continue;  // unmoved (e.g. the base): children as they are
    ++body.epoch;
    body.X_WL = X_WL;
    body.object_bt->setWorldTransform(ToBt(X_WL));
    for (auto& c : body.children) c.X_WC = X_WL * c.prim.X_LG;
  }
  if (im.cache.size() != im.pairs.size()) im.cache.assign(im.pairs.size(), PairCache{});

  CollisionResult result;
  result.link_clearance_m.assign(model_.num_links(), kInf);
  const bool prune = options_.prune, fast = options_.fast_path;
  const double report = options_.report_distance_m;

  // Pairs not checked: self pairs when check_self is off, pairs with an arm whose poses are unknown.
  auto Skipped = [&](const Pair& p) {
    if (p.self()) return !options_.check_self;
    return p.group == Group::kOtherArm && !im.arm_posed[im.bodies[p.b].arm];
  };
  auto GroupClosest = [](Group g, CollisionResult* r) -> PairDistance& {
    return g == Group::kSelf          ? r->closest_self
           : g == Group::kEnvironment ? r->closest_environment
                                      : r->closest_other_arm;
  };
  // The exact distance of pair i, folded into the result.
  auto compute = [&](int i) {
    const Pair& p = im.pairs[i];
    const Body& A = im.bodies[p.a];
    const Body& B = im.bodies[p.b];
    PairCache& cache = im.cache[i];
    SignedDistance& best = cache.distance;
    if (cache.epoch_a != A.epoch || cache.epoch_b != B.epoch || cache.fast_path != fast) {
      best.distance_m = kInf;
      const bool single = A.children.size() == 1 && B.children.size() == 1;
      for (const Child& ca : A.children) {
        for (const Child& cb : B.children) {
          // Within a pair only the least distance is kept: a child pair whose bound is not below the
          // best so far cannot replace it (ties keep the earlier one either way).
          if (prune && !single && ChildLowerBound(ca, cb, p.moving()) >= best.distance_m) continue;
          SignedDistance d;
          result.primitive_pairs_gjk += ChildDistance(ca, cb, fast, &d);
          if (d.distance_m < best.distance_m) best = d;
        }
      }
      cache.epoch_a = A.epoch;
      cache.epoch_b = B.epoch;
      cache.fast_path = fast;
    }
    ++result.pairs_computed;
    const double dist = best.distance_m;
    double& clear_a = result.link_clearance_m[A.link];
    clear_a = std::min(clear_a, dist);
    if (p.self()) {
      double& clear_b = result.link_clearance_m[B.link];
      clear_b = std::min(clear_b, dist);
    }
    PairDistance& group = GroupClosest(p.group, &result);
    const bool closer_in_group = dist < group.distance_m, closest = dist < result.min_distance_m;
    if (!closer_in_group && !closest && !(dist < report)) return;
    PairDistance pd;
    pd.link_a = A.link;
    pd.link_b = B.link;
    pd.object_b = B.object;
    pd.self = p.self();
    pd.arm_b = B.arm;
    pd.arm_link_b = B.arm_link;
    pd.distance_m = dist;
    pd.p_WA = best.p_WA;
    pd.p_WB = best.p_WB;
    pd.normal_W = best.normal_W;
    if (closer_in_group) group = pd;
    if (closest) {
      result.min_distance_m = dist;
      result.closest = pd;
    }
    if (dist < report) result.contacts.push_back(pd);
  };

  const int n = static_cast<int>(im.pairs.size());
  if (!prune) {
    for (int i = 0; i < n; ++i) {
      if (Skipped(im.pairs[i])) continue;
      compute(i);
    }
  } else {
    // Bounds, and per link and per group the pair of least bound: computed first, these make the
    // clearances tight early (they are usually the final ones), so the pass in pair order that
    // follows skips nearly everything else without sorting.
    const int num_links = model_.num_links();
    im.lower_bound.resize(n);
    im.done.assign(n, 0);
    im.seed.assign(num_links + 3, -1);
    auto offer = [&](int slot, int i, double lb) {
      int& s = im.seed[slot];
      if (s < 0 || lb < im.lower_bound[s]) s = i;
    };
    for (int i = 0; i < n; ++i) {
      const Pair& p = im.pairs[i];
      if (Skipped(p)) {
        im.done[i] = 1;
        continue;
      }
      const Body& A = im.bodies[p.a];
      const Body& B = im.bodies[p.b];
      double lb = kInf;
      for (const Child& ca : A.children) {
        for (const Child& cb : B.children) lb = std::min(lb, ChildLowerBound(ca, cb, p.moving()));
      }
      im.lower_bound[i] = lb;
      offer(A.link, i, lb);
      if (p.self()) offer(B.link, i, lb);
      offer(num_links + static_cast<int>(p.group), i, lb);
    }
    for (int i : im.seed) {
      if (i < 0 || im.done[i]) continue;
      im.done[i] = 1;
      compute(i);
    }
    for (int i = 0; i < n; ++i) {
      if (im.done[i]) continue;
      const Pair& p = im.pairs[i];
      const double lb = im.lower_bound[i];
      // Skip only what cannot lower link A's or B's clearance, its group's closest pair (and so the
      // overall minimum) or enter the report list.
      const double clear_b = p.self() ? result.link_clearance_m[im.bodies[p.b].link] : -kInf;
      const double group_min = GroupClosest(p.group, &result).distance_m;
      if (lb >= result.link_clearance_m[im.bodies[p.a].link] && lb >= clear_b && lb >= group_min &&
          lb >= report) {
        continue;
      }
      compute(i);
    }
  }
  std::sort(result.contacts.begin(), result.contacts.end(),
            [](const PairDistance& x, const PairDistance& y) { return x.distance_m < y.distance_m; });
  // Names only for what is returned (string copies are most of a query's cost otherwise).
  auto name = [&](PairDistance& d) {
    if (!d.valid()) return;
    d.body_a = im.bodies[im.body_of_link[d.link_a]].name;
    if (d.arm_b >= 0) {
      d.body_b = im.bodies[im.body_of_arm_link[d.arm_b][d.arm_link_b]].name;
    } else {
      d.body_b = d.link_b >= 0 ? im.bodies[im.body_of_link[d.link_b]].name : im.object_names[d.object_b];
    }
  };
  name(result.closest);
  name(result.closest_self);
  name(result.closest_environment);
  name(result.closest_other_arm);
  for (auto& c : result.contacts) name(c);
  result.in_collision = result.min_distance_m <= 0.0;
  return result;
}

std::vector<CollisionWorld::CheckedPair> CollisionWorld::CheckedPairs() const {
  std::vector<CheckedPair> out;
  for (const Pair& p : impl_->pairs) {
    const Body& A = impl_->bodies[p.a];
    const Body& B = impl_->bodies[p.b];
    out.push_back({A.link, B.link, B.object, B.arm, B.arm_link});
  }
  return out;
}

std::vector<CollisionPrimitive> CollisionWorld::LinkPrimitives(int link) const {
  std::vector<CollisionPrimitive> out;
  if (link < 0 || link >= static_cast<int>(impl_->body_of_link.size()) || impl_->body_of_link[link] < 0)
    return out;
  for (const Child& c : impl_->bodies[impl_->body_of_link[link]].children) out.push_back(c.prim);
  return out;
}

PairDistance CollisionWorld::PrimitiveDistance(const CollisionPrimitive& a, const Eigen::Isometry3d& X_WA,
                                               const CollisionPrimitive& b, const Eigen::Isometry3d& X_WB,
                                               bool fast_path) {
  Child ca, cb;
  ca.prim = a;
  cb.prim = b;
  ca.shape = MakeShape(a);
  cb.shape = MakeShape(b);
  ca.core = CoreOf(a, *ca.shape);
  cb.core = CoreOf(b, *cb.shape);
  ca.X_WC = X_WA;
  cb.X_WC = X_WB;
  SignedDistance d;
  ChildDistance(ca, cb, fast_path, &d);
  PairDistance out;
  out.distance_m = d.distance_m;
  out.p_WA = d.p_WA;
  out.p_WB = d.p_WB;
  out.normal_W = d.normal_W;
  return out;
}

}  // namespace orbed::sim
