#pragma once
/// @file
/// A serial robot loaded from URDF (urdfdom): its links, actuated joints with limits, collision
/// primitives, forward kinematics of every link, the flange F and the tool tip T, and the geometric
/// Jacobian. Nothing here knows about Bullet or LCM.
///
/// Frames: R is the robot base (the URDF root link). X_RL is the pose of link frame L in R; X_LG the
/// pose of a collision primitive G in its link frame L; F the flange (link "iiwa_link_ee" by default),
/// T the tool tip (link "tool_tip"), whose +z axis is the tool axis. Units: m, rad, rad/s.
///
/// Threading: a RobotModel is immutable after loading except for SetToolLength(); const methods may
/// be called from any number of threads at once.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace orbed::sim {

/// One collision primitive in its link's frame. Cylinders are along the primitive's own z axis and
/// centred on its origin (URDF convention); boxes take full side lengths in `size_m`. kCapsule never
/// comes from a URDF (urdfdom drops <capsule>): the collision library makes one from a cylinder
/// capped by two spheres; its length_m is the distance between the cap centres, along z.
struct CollisionPrimitive {
  enum class Kind { kSphere, kCylinder, kBox, kCapsule };
  Kind kind{Kind::kSphere};
  std::string name;  ///< the URDF <collision name=...> (may be empty)
  Eigen::Isometry3d X_LG{Eigen::Isometry3d::Identity()};
  double radius_m{0};                               ///< sphere, cylinder, capsule
  double length_m{0};                               ///< cylinder, capsule
  Eigen::Vector3d size_m{Eigen::Vector3d::Zero()};  ///< box, full extents
};

/// A link of the kinematic tree, in topological order (parent before child).
struct RobotLink {
  std::string name;
  int parent{-1};          ///< index into links(), -1 for the root R
  int joint_index{-1};     ///< index into the actuated joints, -1 if rigidly attached
  std::string joint_name;  ///< the URDF joint connecting it to its parent (empty for the root)
  Eigen::Isometry3d X_PJ{Eigen::Isometry3d::Identity()};  ///< joint frame in the parent link frame
  Eigen::Vector3d axis_J{Eigen::Vector3d::UnitZ()};       ///< unit joint axis in the joint frame
  std::vector<CollisionPrimitive> collision;
  /// Index of the rigid body this link belongs to: links joined by fixed joints share one body (e.g.
  /// iiwa_link_7, iiwa_link_ee, iiwa_tool, tool_tip). Two bodies are *adjacent* when one actuated
  /// joint connects them.
  int body{0};
};

/// Limits of one actuated (revolute) joint.
struct JointInfo {
  std::string name;
  int link{-1};  ///< the child link it moves
  double lower_rad{0};
  double upper_rad{0};
  double velocity_rad_per_s{0};
};

class RobotModel {
 public:
  /// Loads a URDF file. Accepts revolute joints with finite limits and fixed joints; a tree may
  /// branch. Throws std::runtime_error naming the file, the element and what was expected (e.g.
  /// "iiwa7.urdf: joint 'j2': <limit velocity> must be > 0").
  /// `flange_link` and `tool_tip_link` name F and T; the tool tip may be absent (then T = F).
  static RobotModel LoadFile(const std::string& path, const std::string& flange_link = "iiwa_link_ee",
                             const std::string& tool_tip_link = "tool_tip");
  /// The model a process's --urdf flag names: `path`, or "" for the shipped one
  /// (kDefaultUrdfRelativePath under the source tree, base/source_paths.h).
  static RobotModel LoadFlag(const std::string& path);
  /// The same from a string; `source_name` is used in error messages.
  static RobotModel LoadString(const std::string& urdf_xml, const std::string& source_name,
                               const std::string& flange_link = "iiwa_link_ee",
                               const std::string& tool_tip_link = "tool_tip");

  /// The path of the model shipped in the source tree, relative to the repository root.
  static constexpr const char* kDefaultUrdfRelativePath = "sim/models/iiwa7.urdf";

  int num_joints() const { return static_cast<int>(joints_.size()); }
  int num_links() const { return static_cast<int>(links_.size()); }
  int num_bodies() const { return num_bodies_; }
  const std::vector<RobotLink>& links() const { return links_; }
  const std::vector<JointInfo>& joints() const { return joints_; }
  const std::string& source_name() const { return source_name_; }
  /// Index of a link by name, or -1.
  int FindLink(const std::string& name) const;
  int flange_link() const { return flange_link_; }
  int tool_tip_link() const { return tool_tip_link_; }
  /// Distance from F to T along the tool axis [m] (0 without a tool tip link).
  double tool_length_m() const { return tool_length_m_; }
  /// The link index that carries the tool's collision geometry (the tool tip's parent), or -1.
  int tool_link() const { return tool_link_; }

  /// Moves the tool tip to `length_m` along F's z axis and makes the tool's collision cylinder that
  /// ended at the old tip end at the new one. Throws std::invalid_argument if the length is not
  /// finite, <= 0, or would make that cylinder shorter than 1 mm.
  void SetToolLength(double length_m);

  /// True when the two bodies are the same or are connected by one joint.
  bool BodiesAdjacent(int body_a, int body_b) const;
  /// Number of actuated joints on the path between two bodies (0 for the same body).
  int BodySeparation(int body_a, int body_b) const;

  Eigen::VectorXd lower_limits_rad() const;
  Eigen::VectorXd upper_limits_rad() const;
  Eigen::VectorXd velocity_limits_rad_per_s() const;

  /// Empty if q has num_joints() finite entries within limits (with `tolerance_rad` slack), else a
  /// one-line reason naming the joint, e.g. "iiwa_joint_2 = 130.000 deg is outside [-120, 120] deg".
  std::string ValidateJointVector(const Eigen::VectorXd& q_rad, double tolerance_rad = 1e-9) const;

  /// Poses X_RL of every link, indexed as links(). Throws std::invalid_argument on a wrong size.
  std::vector<Eigen::Isometry3d> CalcLinkPoses(const Eigen::VectorXd& q_rad) const;
  /// Same without allocation; `X_RL` is resized to num_links().
  void CalcLinkPoses(const Eigen::VectorXd& q_rad, std::vector<Eigen::Isometry3d>* X_RL) const;
  /// X_RL of CalcLinkPoses(q_old) updated to q_rad, where q_rad differs from q_old in `joint` only:
  /// the links that joint moves, up to index `last_link`, are recomputed by the same operations as
  /// CalcLinkPoses (bit for bit its poses of q_rad there); the other links are left as they are. No
  /// allocation: for searches over one joint's angle (the assistant's grid).
  void UpdateLinkPosesForJoint(const Eigen::VectorXd& q_rad, int joint, int last_link,
                               std::vector<Eigen::Isometry3d>* X_RL) const;
  Eigen::Isometry3d CalcFlangePose(const Eigen::VectorXd& q_rad) const;   ///< X_RF
  Eigen::Isometry3d CalcToolTipPose(const Eigen::VectorXd& q_rad) const;  ///< X_RT

  /// Geometric Jacobian of frame `link` (origin point) in R: rows 0-2 angular velocity w_RL, rows 3-5
  /// translational velocity v_RL of L's origin, both expressed in R; 6 x num_joints().
  Eigen::MatrixXd CalcJacobian(const Eigen::VectorXd& q_rad, int link) const;
  /// Same, from precomputed link poses.
  Eigen::MatrixXd CalcJacobian(const std::vector<Eigen::Isometry3d>& X_RL, int link) const;

 private:
  RobotModel() = default;
  std::string source_name_;
  std::vector<RobotLink> links_;
  std::vector<JointInfo> joints_;
  std::vector<std::pair<int, int>> adjacent_bodies_;
  int num_bodies_{0};
  int flange_link_{-1};
  int tool_tip_link_{-1};
  int tool_link_{-1};
  double tool_length_m_{0};
};

/// How close [m] a sphere's centre must be to a cylinder's end-face centre, and its radius to the
/// cylinder's, for FuseCapsules() to take the two as one capsule (a nanometre: round-off of the
/// URDF's origins, not a modelling tolerance).
inline constexpr double kCapsuleFuseToleranceM = 1e-9;

/// The URDF spelling of a capsule is a cylinder with a sphere of the cylinder's radius centred on
/// each end face (urdfdom drops <capsule>); the union of the three is exactly the capsule. Returns
/// `primitives` with every such triple replaced by one kCapsule primitive (the cylinder's name,
/// X_LG, radius and length: the distance between the cap centres, along the primitive's z), first
/// the capsules in the order of their cylinders, then every other primitive in input order. Matches
/// within kCapsuleFuseToleranceM (centre and radius); each sphere caps at most one capsule; a
/// cylinder missing a cap stays a cylinder. The one rule the collision world and the renderer share
/// (collision_world.h, hmd_emulator/scene_geometry.h), so both see the same shapes.
std::vector<CollisionPrimitive> FuseCapsules(const std::vector<CollisionPrimitive>& primitives);

/// Degrees <-> radians, elementwise.
Eigen::VectorXd DegToRad(const Eigen::VectorXd& q_deg);
Eigen::VectorXd RadToDeg(const Eigen::VectorXd& q_rad);

}  // namespace orbed::sim
