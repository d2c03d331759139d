#pragma once
/// @file
/// The world-frame geometry a camera sees (the headset's, the fixed monitor's) and the headset
/// ray-casts against: the OR scene's objects, the real
/// robot's link collision primitives posed by forward kinematics at X_WR, and the virtual robot's at
/// X_WV. One Body per scene object and per robot link with geometry (so links are told apart in the
/// image and in gaze hits); each body has a name, a kind and a colour. Tessellate() turns the
/// analytic primitives into a triangle Mesh for the renderer; gaze.h uses the primitives directly.
///
/// Frames: W world (floor z = 0, z up), G a primitive's own frame (box centred, full extents
/// size_m along G's axes; cylinder and capsule along G's z, centred; sphere centred), R / V the real /
/// virtual robot base, L a link. X_WG = X_WB · X_BL(q) · X_LG with B = R or V. Units: m, rad.
///
/// Threading: plain data; a SceneGeometry is not synchronised (one writer, or readers only). The
/// RobotModel passed to AddRobot() must outlive the SceneGeometry.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::render {

/// 8-bit colour in OpenCV's channel order (blue, green, red).
struct ColorBgr {
  std::uint8_t b{200}, g{200}, r{200};
};

enum class BodyKind : std::uint8_t { kSceneObject = 0, kRealRobot = 1, kVirtualRobot = 2 };

/// Bit mask of BodyKind values, for filtering what is rendered or ray-cast.
using KindMask = std::uint8_t;
constexpr KindMask KindBit(BodyKind k) { return static_cast<KindMask>(1u << static_cast<int>(k)); }
/// What the headset's spatial map holds: the real environment (scene objects + the real robot).
constexpr KindMask kRealWorld = KindBit(BodyKind::kSceneObject) | KindBit(BodyKind::kRealRobot);
constexpr KindMask kVirtualOnly = KindBit(BodyKind::kVirtualRobot);
constexpr KindMask kAllKinds = kRealWorld | kVirtualOnly;

struct Body {
  std::string name;  ///< scene object name, robot link name; virtual links are "virtual/<link>"
  BodyKind kind{BodyKind::kSceneObject};
  ColorBgr color;
  int robot{-1};  ///< robot handle from AddRobot(), -1 for scene objects
  int link{-1};   ///< link index in the robot model, -1 for scene objects
};

struct Primitive {
  enum class Shape : std::uint8_t { kBox, kCylinder, kSphere, kCapsule };
  Shape shape{Shape::kBox};
  int body{-1};  ///< index into SceneGeometry::bodies()
  Eigen::Isometry3d X_WG{Eigen::Isometry3d::Identity()};
  Eigen::Vector3d size_m{Eigen::Vector3d::Zero()};  ///< box: full extents
  double radius_m{0};                               ///< cylinder, sphere, capsule
  double length_m{0};  ///< cylinder: full length; capsule: distance between the cap centres
};

class SceneGeometry {
 public:
  /// Adds every object of the scene (one body each), coloured from a muted palette; "floor" is grey.
  void AddSceneObjects(const sim::Scene& scene);

  /// Adds one body per link of `robot` that has collision primitives, posed at the zero
  /// configuration with the base at the identity; call PoseRobot() to place it. Real links alternate
  /// KUKA orange and light grey, the tool is dark; virtual links alternate two hologram cyans.
  /// A URDF "capsule" (a cylinder with a sphere of its radius centred on each end face) becomes one
  /// kCapsule primitive: the same solid, without hidden end caps. Primitive sizes are copied now,
  /// so call it after RobotModel::SetToolLength(). Returns the robot handle.
  int AddRobot(const sim::RobotModel& robot, BodyKind kind);

  /// Poses robot `handle` at joint vector q [rad] with base pose X_WB (X_WR or X_WV).
  /// Throws std::invalid_argument on an unknown handle or a q of the wrong size.
  void PoseRobot(int handle, const Eigen::VectorXd& q_rad, const Eigen::Isometry3d& X_WB);

  /// Shorthand: scene + real robot at (q, X_WR), and, when `X_WV` is given, the virtual robot at
  /// (q_virtual or q, X_WV). Handles: real robot 0, virtual robot 1.
  static SceneGeometry MakeOperatingRoom(const sim::Scene& scene, const sim::RobotModel& robot,
                                         const Eigen::VectorXd& q_rad, const Eigen::Isometry3d& X_WR,
                                         const Eigen::Isometry3d* X_WV = nullptr,
                                         const Eigen::VectorXd* q_virtual_rad = nullptr);

  const std::vector<Body>& bodies() const { return bodies_; }
  const std::vector<Primitive>& primitives() const { return primitives_; }
  /// Index of the body with this name, or -1.
  int FindBody(const std::string& name) const;

  /// Adds one primitive on a new body (tests, extra props). Returns the body index.
  int AddBody(const std::string& name, BodyKind kind, ColorBgr color, const Primitive& primitive);

 private:
  struct RobotEntry {
    const sim::RobotModel* model{nullptr};
    BodyKind kind{BodyKind::kRealRobot};
    std::vector<int> primitive_index;     ///< into primitives_
    std::vector<int> primitive_link;      ///< link index of each
    std::vector<Eigen::Isometry3d> X_LG;  ///< primitive pose in its link
    std::vector<Eigen::Isometry3d> X_BL;  ///< scratch for forward kinematics
  };
  std::vector<Body> bodies_;
  std::vector<Primitive> primitives_;
  std::vector<RobotEntry> robots_;
};

/// Triangles of the tessellated primitives, in W, single precision (what the rasteriser eats).
/// Triangles wind counter-clockwise seen from outside; normal_W is the outward unit normal.
struct Mesh {
  struct Triangle {
    std::array<int, 3> v;  ///< vertex indices into p_W
    int body{-1};          ///< index into SceneGeometry::bodies()
    Eigen::Vector3f normal_W;
    ColorBgr color;
  };
  std::vector<Eigen::Vector3f> p_W;
  std::vector<Triangle> triangles;
  void Clear() {
    p_W.clear();
    triangles.clear();
  }
};

struct TessellationOptions {
  int cylinder_segments{24};  ///< around the axis (cylinders, capsules)
  int sphere_segments{20};    ///< around the axis (spheres, capsule caps)
  int sphere_rings{10};       ///< pole to pole (spheres); capsule caps use half each
};

/// Appends the triangles of every primitive whose body kind is in `kinds` to `mesh` (not cleared).
/// Polygonal approximations are inscribed (vertices on the true surface).
void Tessellate(const SceneGeometry& geometry, KindMask kinds, const TessellationOptions& options,
                Mesh* mesh);
/// The same for a single primitive with an explicit body index and colour.
void TessellatePrimitive(const Primitive& primitive, int body, ColorBgr color,
                         const TessellationOptions& options, Mesh* mesh);

}  // namespace orbed::render
