/// @file
/// FK + full collision check (self + scene) per query of the iiwa 7 in the shipped trocar scene, in
/// one run: orbed's Bullet CollisionWorld with its closed-form fast path (the default), the same
/// with GJK/EPA for every primitive pair (fast_path = false), both without bound pruning, and FCL
/// answering the same query — the same pairs, the same primitives (capsules, cylinders, spheres,
/// boxes), the minimum signed distance, the closest pair and per-link clearance — every checked pair
/// one after the other (FclChecker), and through FCL's own broadphase (a dynamic AABB tree over every
/// primitive, its distance query pruning by the best distance so far, the same pairs filtered in the
/// callback: FclBroadphaseChecker, the minimum distance only). Then four arms around the table
/// (FourArms): each arm's Bullet world checking itself, the scene and the three others,
/// against one FCL broadphase over the four arms and the scene. The joint vectors are a fixed pool of
/// 1024 seeded random vectors within the limits.
///
/// Counters: `pairs` = exact pair distances computed per query; `gjk_prims` = primitive pairs of
/// those that went to GJK/EPA; `max_diff_vs_bullet_m` = the largest |min distance (FCL) - min
/// distance (Bullet fast path)| over the pool (agreement check).
/// Run: build-*/bench/collision_bench (needs $ORBED_SOURCE_DIR or runs from the source root).
#include <cmath>
#include <cstdlib>
#include <deque>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>

#include "base/source_paths.h"
#include "sim/collision_world.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::sim {
namespace {

struct Fixture {
  RobotModel model = RobotModel::LoadFile(orbed::SourceTreePath(RobotModel::kDefaultUrdfRelativePath));
  Scene scene = LoadSceneFile(orbed::SourceTreePath(kDefaultSceneRelativePath));
  std::vector<Eigen::VectorXd> pool;
  Fixture() {
    model.SetToolLength(scene.tool_length_m);
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> u(0, 1);
    for (int n = 0; n < 1024; ++n) {
      Eigen::VectorXd q(model.num_joints());
      for (int i = 0; i < q.size(); ++i) {
        q[i] = model.joints()[i].lower_rad +
               u(rng) * (model.joints()[i].upper_rad - model.joints()[i].lower_rad);
      }
      pool.push_back(q);
    }
  }
};

Fixture& F() {
  static Fixture f;
  return f;
}

std::shared_ptr<fcl::CollisionGeometryd> ToFcl(const CollisionPrimitive& g) {
  using K = CollisionPrimitive::Kind;
  switch (g.kind) {
    case K::kSphere:
      return std::make_shared<fcl::Sphered>(g.radius_m);
    case K::kCapsule:
      return std::make_shared<fcl::Capsuled>(g.radius_m, g.length_m);
    case K::kCylinder:
      return std::make_shared<fcl::Cylinderd>(g.radius_m, g.length_m);
    case K::kBox:
      return std::make_shared<fcl::Boxd>(g.size_m.x(), g.size_m.y(), g.size_m.z());
  }
  return nullptr;
}

CollisionPrimitive ObjectPrimitive(const SceneObject& o) {
  CollisionPrimitive g;
  switch (o.shape) {
    case SceneObject::Shape::kBox:
      g.kind = CollisionPrimitive::Kind::kBox;
      g.size_m = o.size_m;
      break;
    case SceneObject::Shape::kCylinder:
      g.kind = CollisionPrimitive::Kind::kCylinder;
      g.radius_m = o.radius_m;
      g.length_m = o.length_m;
      break;
    case SceneObject::Shape::kSphere:
      g.kind = CollisionPrimitive::Kind::kSphere;
      g.radius_m = o.radius_m;
      break;
  }
  return g;
}

// The same query on FCL: every checked pair, every primitive pair, signed distance.
class FclChecker {
 public:
  explicit FclChecker(const CollisionWorld& world, const Scene& scene)
      : model_(world.model()), X_WR_(scene.X_WR) {
    links_.resize(model_.num_links());
    for (int l = 0; l < model_.num_links(); ++l) {
      for (const auto& g : world.LinkPrimitives(l)) {
        links_[l].push_back({std::make_unique<fcl::CollisionObjectd>(ToFcl(g)), g.X_LG});
      }
    }
    for (const auto& o : scene.objects) {
      std::vector<Child> v;
      auto obj = std::make_unique<fcl::CollisionObjectd>(ToFcl(ObjectPrimitive(o)));
      obj->setTransform(o.X_WO);
      v.push_back({std::move(obj), Eigen::Isometry3d::Identity()});
      objects_.push_back(std::move(v));
    }
    pairs_ = world.CheckedPairs();
    request_.enable_signed_distance = true;
    request_.enable_nearest_points = true;
    request_.gjk_solver_type = fcl::GST_LIBCCD;
  }

  // Returns the minimum signed distance; fills per-link clearance and the closest pair.
  double Check(const Eigen::VectorXd& q, std::vector<double>* clearance, int* closest_pair) {
    model_.CalcLinkPoses(q, &X_RL_);
    for (int l = 0; l < model_.num_links(); ++l) {
      const Eigen::Isometry3d X_WL = X_WR_ * X_RL_[l];
      for (auto& c : links_[l]) c.object->setTransform(X_WL * c.X_LG);
    }
    clearance->assign(model_.num_links(), std::numeric_limits<double>::infinity());
    double best = std::numeric_limits<double>::infinity();
    for (size_t p = 0; p < pairs_.size(); ++p) {
      const auto& pair = pairs_[p];
      const auto& A = links_[pair.link_a];
      const auto& B = pair.link_b >= 0 ? links_[pair.link_b] : objects_[pair.object_b];
      double d = std::numeric_limits<double>::infinity();
      for (const auto& a : A) {
        for (const auto& b : B) {
          fcl::DistanceResultd result;
          fcl::distance(a.object.get(), b.object.get(), request_, result);
          d = std::min(d, result.min_distance);
        }
      }
      (*clearance)[pair.link_a] = std::min((*clearance)[pair.link_a], d);
      if (pair.link_b >= 0) (*clearance)[pair.link_b] = std::min((*clearance)[pair.link_b], d);
      if (d < best) {
        best = d;
        *closest_pair = static_cast<int>(p);
      }
    }
    return best;
  }

 private:
  struct Child {
    std::unique_ptr<fcl::CollisionObjectd> object;
    Eigen::Isometry3d X_LG;
  };
  const RobotModel& model_;
  Eigen::Isometry3d X_WR_;
  std::vector<std::vector<Child>> links_;
  std::vector<std::vector<Child>> objects_;
  std::vector<CollisionWorld::CheckedPair> pairs_;
  fcl::DistanceRequestd request_;
  std::vector<Eigen::Isometry3d> X_RL_;
};

// The same minimum distance through FCL's broadphase manager: every primitive of every arm's links
// and of the scene in one dynamic AABB tree; the distance callback skips primitive pairs whose
// bodies are not a checked pair (adjacent links, links of one body, scene objects among
// themselves) and hands the best distance back (at least 0: overlapping boxes are always visited,
// for the deepest penetration) so the tree prunes every pair of boxes farther apart. Several arms:
// arm k's world has the others added in index order (AddOtherArm), so its other-arm pairs name them
// by that order; every pair any world checks is checked once here.
class FclBroadphaseChecker {
 public:
  FclBroadphaseChecker(const std::vector<CollisionWorld*>& worlds, const Scene& scene) : worlds_(worlds) {
    const int num_arms = static_cast<int>(worlds.size());
    num_links_ = worlds[0]->model().num_links();
    const int num_objects = static_cast<int>(scene.objects.size());
    // Owner ids: arm k's link l is k * num_links + l; scene object o is num_arms * num_links + o.
    owners_ = num_arms * num_links_ + num_objects;
    checked_.assign(static_cast<size_t>(owners_ * owners_), false);
    for (int k = 0; k < num_arms; ++k) {
      for (const auto& pair : worlds[k]->CheckedPairs()) {
        const int a = k * num_links_ + pair.link_a;
        int b = 0;
        if (pair.link_b >= 0) {
          b = k * num_links_ + pair.link_b;
        } else if (pair.object_b >= 0) {
          b = num_arms * num_links_ + pair.object_b;
        } else {
          const int other = pair.arm_b < k ? pair.arm_b : pair.arm_b + 1;
          b = other * num_links_ + pair.arm_link_b;
        }
        checked_[Index(a, b)] = checked_[Index(b, a)] = true;
      }
      for (int l = 0; l < num_links_; ++l) {
        for (const auto& g : worlds[k]->LinkPrimitives(l)) {
          Add(ToFcl(g), k * num_links_ + l, g.X_LG, Eigen::Isometry3d::Identity());
        }
      }
    }
    for (int o = 0; o < num_objects; ++o) {
      const SceneObject& object = scene.objects[o];
      Add(ToFcl(ObjectPrimitive(object)), num_arms * num_links_ + o, Eigen::Isometry3d::Identity(),
          object.X_WO);
    }
    for (auto& c : children_) manager_.registerObject(c.object.get());
    manager_.setup();
    request_.enable_signed_distance = true;
    request_.gjk_solver_type = fcl::GST_LIBCCD;
    X_RL_.resize(worlds.size());
  }

  // The minimum over every checked pair; `q[k]` is arm k's joint vector.
  double MinDistance(const std::vector<const Eigen::VectorXd*>& q) {
    for (size_t k = 0; k < worlds_.size(); ++k) worlds_[k]->model().CalcLinkPoses(*q[k], &X_RL_[k]);
    const int arm_owners = static_cast<int>(worlds_.size()) * num_links_;
    for (auto& c : children_) {
      if (c.owner >= arm_owners) continue;
      const int k = c.owner / num_links_, l = c.owner % num_links_;
      c.object->setTransform(worlds_[k]->X_WR() * X_RL_[k][l] * c.X_LG);
      c.object->computeAABB();
    }
    manager_.update();
    Query query{this, std::numeric_limits<double>::infinity()};
    manager_.distance(&query, &Callback);
    return query.best;
  }

 private:
  struct Child {
    std::unique_ptr<fcl::CollisionObjectd> object;
    int owner;
    Eigen::Isometry3d X_LG;
  };
  struct Query {
    FclBroadphaseChecker* self;
    double best;
  };
  size_t Index(int a, int b) const { return static_cast<size_t>(a * owners_ + b); }
  void Add(std::shared_ptr<fcl::CollisionGeometryd> shape, int owner, const Eigen::Isometry3d& X_LG,
           const Eigen::Isometry3d& X_WO) {
    auto object = std::make_unique<fcl::CollisionObjectd>(shape);
    object->setTransform(X_WO);
    object->computeAABB();
    children_.push_back({std::move(object), owner, X_LG});
    children_.back().object->setUserData(&children_.back().owner);
  }
  static bool Callback(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data, double& dist) {
    auto* query = static_cast<Query*>(data);
    const int a = *static_cast<int*>(o1->getUserData()), b = *static_cast<int*>(o2->getUserData());
    if (!query->self->checked_[query->self->Index(a, b)]) return false;
    fcl::DistanceResultd result;
    fcl::distance(o1, o2, query->self->request_, result);
    query->best = std::min(query->best, result.min_distance);
    // Prune by the best distance, but never below zero: boxes that overlap may hold a deeper
    // penetration than the best one found so far.
    dist = std::max(query->best, 1e-9);
    return false;
  }

  std::vector<CollisionWorld*> worlds_;
  int num_links_ = 0;
  int owners_ = 0;
  std::vector<bool> checked_;
  std::deque<Child> children_;  // stable addresses: each object's user data points at its owner
  fcl::DynamicAABBTreeCollisionManagerd manager_;
  fcl::DistanceRequestd request_;
  std::vector<std::vector<Eigen::Isometry3d>> X_RL_;
};

// Four arms around the table: sim/models/scenes/four_arms_or.yaml, a0 where the single
// arm stands, a1 and a2 beside it 0.7 m along the table, a3 across it, each on its cart. Each arm's
// world checks its own links, the scene and the three others, as each arm's sim would (so a pair of
// arms is checked from both sides); each arm sits at its own joint vector from the pool.
struct FourArms {
  static constexpr int kArms = 4;
  Scene four = LoadSceneFile(orbed::SourceTreePath("sim/models/scenes/four_arms_or.yaml"));
  std::vector<Scene> scenes;
  std::vector<std::unique_ptr<CollisionWorld>> worlds;
  FourArms() {
    const auto& f = F();
    for (int k = 0; k < kArms; ++k) {
      Scene scene = four;
      scene.X_WR = four.arms.at(k).X_WR;
      scenes.push_back(scene);
    }
    for (int k = 0; k < kArms; ++k) worlds.push_back(std::make_unique<CollisionWorld>(f.model, &scenes[k]));
    for (int k = 0; k < kArms; ++k) {
      for (int j = 0; j < kArms; ++j) {
        if (j != k) worlds[k]->AddOtherArm(four.arms[j].name, f.model);
      }
    }
  }
  // Poses every arm at pool[first + k] and checks every world; returns the least distance.
  double Check(size_t first, int* pairs = nullptr) {
    const auto& f = F();
    for (int k = 0; k < kArms; ++k) {
      f.model.CalcLinkPoses(f.pool[(first + k) & 1023], &X_RL[k]);
      X_WL[k].resize(X_RL[k].size());
      for (size_t l = 0; l < X_RL[k].size(); ++l) X_WL[k][l] = scenes[k].X_WR * X_RL[k][l];
    }
    double least = std::numeric_limits<double>::infinity();
    for (int k = 0; k < kArms; ++k) {
      int other = 0;
      for (int j = 0; j < kArms; ++j) {
        if (j != k) worlds[k]->SetOtherArmLinkPoses(other++, X_WL[j]);
      }
      const CollisionResult r = worlds[k]->CheckPoses(X_RL[k]);
      least = std::min(least, r.min_distance_m);
      if (pairs) *pairs += r.pairs_computed;
    }
    return least;
  }
  std::vector<CollisionWorld*> Raw() const {
    std::vector<CollisionWorld*> raw;
    for (const auto& w : worlds) raw.push_back(w.get());
    return raw;
  }
  std::vector<Eigen::Isometry3d> X_RL[kArms], X_WL[kArms];
};

void BM_Fk(benchmark::State& state) {
  const auto& f = F();
  std::vector<Eigen::Isometry3d> X;
  size_t i = 0;
  for (auto _ : state) {
    f.model.CalcLinkPoses(f.pool[i++ & 1023], &X);
    benchmark::DoNotOptimize(X.data());
  }
}
BENCHMARK(BM_Fk);

void BulletCheck(benchmark::State& state, bool prune, bool fast_path) {
  auto& f = F();
  CollisionWorld::Options options;
  options.prune = prune;
  options.fast_path = fast_path;
  CollisionWorld world(f.model, &f.scene, options);
  size_t i = 0;
  double pairs = 0, gjk = 0;
  for (auto _ : state) {
    const CollisionResult r = world.Check(f.pool[i++ & 1023]);
    pairs += r.pairs_computed;
    gjk += r.primitive_pairs_gjk;
    benchmark::DoNotOptimize(r.min_distance_m);
  }
  state.counters["pairs"] = pairs / static_cast<double>(state.iterations());
  state.counters["gjk_prims"] = gjk / static_cast<double>(state.iterations());
  state.counters["checked_pairs"] = world.num_self_pairs() + world.num_environment_pairs();
}
// Closed forms where exact, GJK/EPA for the rest (the default).
void BM_BulletFkAndCheck(benchmark::State& state) { BulletCheck(state, true, true); }
// GJK/EPA for every primitive pair (the reference path).
void BM_BulletFkAndCheckGjkOnly(benchmark::State& state) { BulletCheck(state, true, false); }
void BM_BulletFkAndCheckNoPruning(benchmark::State& state) { BulletCheck(state, false, true); }
void BM_BulletFkAndCheckGjkOnlyNoPruning(benchmark::State& state) { BulletCheck(state, false, false); }
BENCHMARK(BM_BulletFkAndCheck);
BENCHMARK(BM_BulletFkAndCheckGjkOnly);
BENCHMARK(BM_BulletFkAndCheckNoPruning);
BENCHMARK(BM_BulletFkAndCheckGjkOnlyNoPruning);

void BM_FclFkAndCheck(benchmark::State& state) {
  auto& f = F();
  CollisionWorld world(f.model, &f.scene);
  FclChecker fcl_checker(world, f.scene);
  std::vector<double> clearance;
  int closest = -1;
  double max_diff = 0;
  for (const auto& q : f.pool) {
    max_diff = std::max(max_diff,
                        std::abs(fcl_checker.Check(q, &clearance, &closest) - world.Check(q).min_distance_m));
  }
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(fcl_checker.Check(f.pool[i++ & 1023], &clearance, &closest));
  }
  state.counters["pairs"] = world.num_self_pairs() + world.num_environment_pairs();
  state.counters["max_diff_vs_bullet_m"] = max_diff;
}
BENCHMARK(BM_FclFkAndCheck);

void BM_FclBroadphaseFkAndCheck(benchmark::State& state) {
  auto& f = F();
  CollisionWorld world(f.model, &f.scene);
  FclBroadphaseChecker checker({&world}, f.scene);
  double max_diff = 0;
  for (const auto& q : f.pool) {
    max_diff = std::max(max_diff, std::abs(checker.MinDistance({&q}) - world.Check(q).min_distance_m));
  }
  size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(checker.MinDistance({&f.pool[i++ & 1023]}));
  state.counters["max_diff_vs_bullet_m"] = max_diff;
}
BENCHMARK(BM_FclBroadphaseFkAndCheck);

// Four arms: FK of the four and each arm's check (itself, the scene, the three others).
void BM_Bullet4ArmsFkAndCheck(benchmark::State& state) {
  FourArms arms;
  size_t i = 0;
  double pairs = 0;
  for (auto _ : state) {
    int n = 0;
    benchmark::DoNotOptimize(arms.Check(4 * i++, &n));
    pairs += n;
  }
  int checked = 0;
  for (const auto& w : arms.worlds) {
    checked += w->num_self_pairs() + w->num_environment_pairs() + w->num_other_arm_pairs();
  }
  state.counters["pairs"] = pairs / static_cast<double>(state.iterations());
  state.counters["checked_pairs"] = checked;
  state.counters["inter_arm_pairs"] = arms.worlds[0]->num_other_arm_pairs();
}
BENCHMARK(BM_Bullet4ArmsFkAndCheck);

// The same four arms through one FCL broadphase over all their primitives and the scene (every
// checked pair once: the minimum distance only).
void BM_FclBroadphase4ArmsFkAndCheck(benchmark::State& state) {
  const auto& f = F();
  FourArms arms;
  FclBroadphaseChecker checker(arms.Raw(), arms.four);
  auto q_of = [&](size_t first) {
    std::vector<const Eigen::VectorXd*> q;
    for (int k = 0; k < FourArms::kArms; ++k) q.push_back(&f.pool[(first + k) & 1023]);
    return q;
  };
  double max_diff = 0;
  int colliding = 0;
  for (size_t i = 0; i < 256; ++i) {
    const double bullet = arms.Check(4 * i);
    max_diff = std::max(max_diff, std::abs(checker.MinDistance(q_of(4 * i)) - bullet));
    colliding += bullet <= 0;
  }
  size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(checker.MinDistance(q_of(4 * i++)));
  state.counters["max_diff_vs_bullet_m"] = max_diff;
  state.counters["colliding_of_256"] = colliding;
}
BENCHMARK(BM_FclBroadphase4ArmsFkAndCheck);

}  // namespace
}  // namespace orbed::sim

BENCHMARK_MAIN();
