#pragma once
/// @file
/// Collision checking of a RobotModel in a Scene on Bullet (double precision): each robot link with
/// collision geometry is one btCollisionObject holding a btCompoundShape built from the URDF
/// primitives; each scene object is one btCollisionObject. A query poses the links (from q or from
/// precomputed link poses) and computes, for every checked pair, the exact signed distance over the
/// compound children:
///   - self pairs: robot links on non-adjacent bodies (RobotModel::BodiesAdjacent()),
///   - environment pairs: every robot link vs every scene object, except links the object lists in
///     ignore_links (e.g. the base standing on its cart),
///   - other-arm pairs (several arms, AddOtherArm): every robot link vs every link of each other arm
///     in the OR, whose link poses in W the caller sets before each query (SetOtherArmLinkPoses; an
///     arm whose poses were never set is not checked). The other arm's own self and scene pairs are
///     its own world's business: each arm's world checks itself, the scene and the others.
/// No contact manifold is used or kept, so every result is computed fresh from the current poses.
///
/// Geometry: a URDF cylinder with a sphere of the same radius centred on each end face is exactly a
/// capsule (recognised by FuseCapsules(), sim/robot_model.h, the renderer's rule too) and becomes one
/// btCapsuleShapeZ (an exact segment-with-radius); other cylinders are
/// btCylinderShapeZ (Bullet's btCylinderShape is along y; the Z variant matches URDF), boxes take
/// half extents; box and cylinder margins are kMarginM (their edges are rounded by that much; faces
/// are exact).
///
/// Distances (Options::fast_path): every Bullet convex shape is a core swept by a ball of its margin
/// (point, segment, box, cylinder), and where exact the distance comes from the closed forms of
/// sim/distance_closed_form.h on Bullet's own core dimensions: sphere and capsule against sphere,
/// capsule, box and cylinder (a capsule whose axis reaches a cylinder's core excepted). The rest
/// (box/cylinder against box/cylinder) is btGjkPairDetector + btGjkEpaPenetrationDepthSolver.
/// Agreement with GJK/EPA (collision_world_test, random primitives and 3000 arm configurations):
/// sphere/capsule/box pairs to ~1e-15 m with disjoint cores and ~1e-12 m where EPA takes over; on a
/// cylinder's curved side GJK stops early and over-estimates by up to ~4e-5 m, where the fast path
/// matches an independent reference to 1e-15 m. A pair whose bodies have not moved since the last
/// query (the base link against the scene) reuses its previous result, which the same inputs would
/// reproduce. fast_path = false forces GJK/EPA for every primitive pair (the reference).
///
/// Pruning: each pair has a cheap lower bound on its distance (bounding sphere of the robot primitive
/// vs the exact other shape or bounding sphere). Per link and per group (self, environment) the pair
/// of least bound is computed first; then every other pair is skipped only when its bound proves it
/// can change neither result: not the minimum, not any per-link clearance, not the report list (and
/// within a pair, child pairs whose bound cannot beat the best so far). Results are identical with
/// and without pruning (Options::prune).
///
/// Frames: W is the scene frame, R the robot base (X_WR from the scene; identity without a scene).
/// Points and normals are reported in W; distances in m (negative = penetration depth).
///
/// Threading: not thread-safe (a query writes the object transforms and scratch buffers); use one
/// CollisionWorld per thread. The RobotModel passed in is copied.

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::sim {

/// The closest points of one checked pair.
struct PairDistance {
  std::string body_a;  ///< a robot link name
  std::string body_b;  ///< a robot link name (self) or a scene object name (environment)
  int link_a{-1};      ///< robot link index of body_a
  int link_b{-1};      ///< robot link index of body_b, -1 for a scene object
  int object_b{-1};    ///< scene object index of body_b, -1 for a robot link
  bool self{false};
  int arm_b{-1};       ///< other arm index of body_b (AddOtherArm), -1 otherwise
  int arm_link_b{-1};  ///< that arm's link index, -1 otherwise
  double distance_m{std::numeric_limits<double>::infinity()};  ///< signed; < 0 penetrating
  Eigen::Vector3d p_WA{Eigen::Vector3d::Zero()};               ///< closest (deepest) point on A
  Eigen::Vector3d p_WB{Eigen::Vector3d::Zero()};               ///< closest (deepest) point on B
  Eigen::Vector3d normal_W{Eigen::Vector3d::UnitZ()};          ///< unit, from B toward A
  bool valid() const { return link_a >= 0; }
};

struct CollisionResult {
  bool in_collision{false};  ///< some checked pair has distance <= 0
  double min_distance_m{std::numeric_limits<double>::infinity()};
  PairDistance closest;              ///< the pair with min_distance_m
  PairDistance closest_self;         ///< closest self pair (invalid if none checked)
  PairDistance closest_environment;  ///< closest robot-scene pair (invalid if none checked)
  PairDistance closest_other_arm;    ///< closest pair with another arm (invalid if none checked)
  /// Per robot link (indexed as RobotModel::links()): the smallest distance to anything it is
  /// checked against; +infinity for links without geometry or without checked pairs.
  std::vector<double> link_clearance_m;
  /// Every pair closer than Options::report_distance_m, sorted by distance.
  std::vector<PairDistance> contacts;
  int pairs_computed{0};       ///< pairs whose exact distance was computed (the rest were pruned)
  int primitive_pairs_gjk{0};  ///< primitive pairs of those that went to GJK/EPA (not a closed form)
};

class CollisionWorld {
 public:
  static constexpr double kMarginM = 1e-4;

  struct Options {
    /// Pairs closer than this go into CollisionResult::contacts [m].
    double report_distance_m{0.0};
    /// Skip pairs that provably cannot change the result (see file comment).
    bool prune{true};
    /// Closed-form distances where exact (see file comment); false = GJK/EPA for every pair.
    bool fast_path{true};
    /// Check robot links against each other (non-adjacent bodies only).
    bool check_self{true};
    /// Self pairs are checked only between bodies at least this many joints apart. 2 = every
    /// non-adjacent pair (the default); 3 leaves out links two apart, which the iiwa 7 geometry keeps
    /// from touching anywhere within the limits (robot_model_test) but whose structurally small
    /// gaps would otherwise dominate a clearance objective.
    int min_self_separation{2};  ///< used at construction only
  };

  /// Builds the world. `scene` may be null (self-collision only, W = R). The model's tool length is
  /// taken as is (call RobotModel::SetToolLength(scene.tool_length_m) first if wanted). Throws
  /// std::invalid_argument if an object's ignore_links names an unknown link.
  CollisionWorld(const RobotModel& model, const Scene* scene);
  CollisionWorld(const RobotModel& model, const Scene* scene, const Options& options);
  ~CollisionWorld();
  CollisionWorld(const CollisionWorld&) = delete;
  CollisionWorld& operator=(const CollisionWorld&) = delete;

  const RobotModel& model() const { return model_; }
  const Eigen::Isometry3d& X_WR() const { return X_WR_; }
  const Options& options() const { return options_; }
  void set_options(const Options& options) { options_ = options; }

  /// FK then the full check. Throws std::invalid_argument on a wrong-size or non-finite q (limits are
  /// not enforced here; see RobotModel::ValidateJointVector()).
  CollisionResult Check(const Eigen::VectorXd& q_rad);
  /// The full check with link poses X_RL from RobotModel::CalcLinkPoses().
  CollisionResult CheckPoses(const std::vector<Eigen::Isometry3d>& X_RL);

  /// Number of self, environment and other-arm pairs that are checked.
  int num_self_pairs() const;
  int num_environment_pairs() const;
  int num_other_arm_pairs() const;

  /// Adds another arm of the OR (several arms): `other`'s links with collision geometry, named
  /// "<name>/<link>" in results, checked against every link of this arm once their poses are set.
  /// Returns the arm's index. Throws std::invalid_argument on an empty or repeated name.
  int AddOtherArm(const std::string& name, const RobotModel& other);
  /// The other arm's link poses X_WL in W (one per link of its model, as its
  /// RobotModel::CalcLinkPoses gives X_RL, times its X_WR). Returns whether anything changed for
  /// a query (the first poses, or a link that moved). Throws std::invalid_argument on a wrong arm,
  /// count or a non-finite pose.
  bool SetOtherArmLinkPoses(int arm, const std::vector<Eigen::Isometry3d>& X_WL);
  int num_other_arms() const;

  /// One checked pair: a robot link against a robot link (object_b = -1), a scene object
  /// (link_b = -1) or another arm's link (arm_b >= 0).
  struct CheckedPair {
    int link_a{-1};
    int link_b{-1};
    int object_b{-1};
    int arm_b{-1};       ///< another arm (then link_b = object_b = -1)
    int arm_link_b{-1};  ///< its link
  };
  /// Every pair a query considers (for baselines such as the FCL benchmark).
  std::vector<CheckedPair> CheckedPairs() const;
  /// The convex primitives of a robot link as checked (capsules fused), in the link frame; empty
  /// for links without geometry.
  std::vector<CollisionPrimitive> LinkPrimitives(int link) const;

  /// Exact signed distance between two convex primitives given in W (for tests and tools): same
  /// code path as the pair checks (fast_path as Options::fast_path). Returns the pair with link
  /// indices unset.
  static PairDistance PrimitiveDistance(const CollisionPrimitive& a, const Eigen::Isometry3d& X_WA,
                                        const CollisionPrimitive& b, const Eigen::Isometry3d& X_WB,
                                        bool fast_path = true);

 private:
  struct Impl;
  RobotModel model_;
  Eigen::Isometry3d X_WR_{Eigen::Isometry3d::Identity()};
  Options options_;
  std::unique_ptr<Impl> impl_;
  std::vector<Eigen::Isometry3d> X_RL_scratch_;
};

}  // namespace orbed::sim
