#pragma once
/// @file
/// The operating-room scene around the robot, loaded from YAML (sim/models/scenes/*.yaml): the robot
/// base pose X_WR, the tool length, the trocar (docking point and insertion direction) and the
/// obstacles (table, patient mannequin, carts, other arms...) as boxes, cylinders and spheres.
///
/// Frames: W is the OR world frame (floor at z = 0, z up). Each object O has its pose X_WO; a box is
/// centred on O with full side lengths size_m along O's axes; a cylinder is centred on O with its
/// axis along O's z; a sphere is centred on O. Orientations in the file are URDF-style fixed-axis
/// roll-pitch-yaw in degrees: R = Rz(yaw) Ry(pitch) Rx(roll). Units: m, deg in the file.
///
/// File format (read with base/yaml_fields.h: every key is checked, unknown keys are errors, so
/// typos are caught), here with values of the shipped sim/models/scenes/trocar_or.yaml:
/// @code{.yaml}
/// name: trocar_or                    # optional (default: none; a file names itself)
/// robot:                             # required
///   base_pose: {position_m: [0.25, -0.55, 0.75], rpy_deg: [0, 0, 90]}   # required: X_WR
///   tool_length_m: 0.25              # required: flange F to tool tip T [m], > 0
/// arms:                              # optional, several arms (scenes/four_arms_or.yaml): 1..16
///   - name: a0                       # a-z, 0-9, _ (1..32); unique; `orbed-iiwa-sim --arm a0`
///     base_pose: {position_m: [0.25, -0.55, 0.75], rpy_deg: [0, 0, 90]}   # that arm's X_WR
/// trocar:                            # required
///   position_m: [0.11294, 0.0, 1.06830]                # p_WT*, where the tip docks onto the cannula
///   insertion_direction: [-0.258819, 0.0, -0.965926]   # unit vector in W (normalised if within 1 %)
/// objects:                           # optional (default: none)
///   - name: robot_cart               # required, unique
///     shape: box                     # required: box | cylinder | sphere
///     size_m: [0.5, 0.5, 0.75]       # box: full side lengths [m], > 0
///     pose: {position_m: [0.25, -0.55, 0.375], rpy_deg: [0, 0, 0]}   # required: X_WO; rpy_deg optional (0)
///     ignore_links: [iiwa_link_0, iiwa_link_1]   # optional: robot links never checked against it (a mount)
///   - name: second_arm_column
///     shape: cylinder
///     radius_m: 0.12                 # cylinder, sphere [m], > 0
///     length_m: 1.9                  # cylinder [m], > 0
///     pose: {position_m: [0.55, 0.7, 0.95]}
/// @endcode
/// Scene's tool_length_m is the URDF's tool (0.25 m, sim/models/iiwa7.urdf), the length the shipped
/// scene sets too (scene_test.cc checks that they agree).
///
/// Threading: plain data; the loaders are reentrant.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "sim/robot_model.h"

namespace orbed::sim {

struct SceneObject {
  enum class Shape { kBox, kCylinder, kSphere };
  std::string name;
  Shape shape{Shape::kBox};
  Eigen::Isometry3d X_WO{Eigen::Isometry3d::Identity()};
  Eigen::Vector3d size_m{Eigen::Vector3d::Zero()};  ///< box: full side lengths
  double radius_m{0};                               ///< cylinder, sphere
  double length_m{0};                               ///< cylinder
  std::vector<std::string> ignore_links;
};

struct Trocar {
  Eigen::Vector3d p_WT{Eigen::Vector3d::Zero()};                     ///< docking point [m]
  Eigen::Vector3d insertion_direction_W{-Eigen::Vector3d::UnitZ()};  ///< unit vector
};

/// One of several arms in the OR (the scene file's `arms:` list): its name (1..32 characters of
/// a-z, 0-9, _; it suffixes the arm's channels, channels::ForArm) and its base X_WR.
struct ArmPlacement {
  std::string name;
  Eigen::Isometry3d X_WR{Eigen::Isometry3d::Identity()};
};
inline constexpr size_t kMaxSceneArms = 16;

struct Scene {
  std::string name;
  std::string source;  ///< file name or the name passed to the loader
  /// The single arm's base (robot.base_pose); an arm of `arms` has its own.
  Eigen::Isometry3d X_WR{Eigen::Isometry3d::Identity()};
  double tool_length_m{0.25};  ///< [m]: the URDF's tool
  Trocar trocar;
  std::vector<SceneObject> objects;
  /// Several arms (`arms:`): empty for a single-arm scene.
  std::vector<ArmPlacement> arms;
  /// The arm of that name, or nullptr.
  const ArmPlacement* FindArm(const std::string& arm_name) const;
  /// Makes the arm `arm_name` of `arms` the scene's arm (X_WR = its base), as a process that is
  /// that arm or looks at it does (--arm NAME); "" keeps the single arm. std::invalid_argument
  /// naming the scene's arms when it has no such arm.
  void StandAt(const std::string& arm_name);
};

/// Loads a scene file. Throws std::runtime_error naming the file, the line, the key and what was
/// expected, e.g. "or.yaml:12: objects[1].size_m: expected a list of 3 numbers > 0".
Scene LoadSceneFile(const std::string& path);
/// The same from YAML text; `source_name` is used in error messages.
Scene LoadSceneString(const std::string& yaml_text, const std::string& source_name);

/// The robot as it stands in `scene`: RobotModel::LoadFile(urdf_path) with the scene's tool length
/// applied (SetToolLength), so that FK, collision geometry and everything copied from it see the
/// scene's tool. Every process and tool that loads the robot for a scene goes through this. Throws
/// std::runtime_error naming the URDF (as LoadFile) or naming scene.source and tool_length_m when
/// the model cannot take that tool length.
RobotModel LoadRobotForScene(const std::string& urdf_path, const Scene& scene);

/// R = Rz(yaw) Ry(pitch) Rx(roll), angles in degrees.
Eigen::Matrix3d RotationFromRpyDeg(const Eigen::Vector3d& rpy_deg);

/// The scene shipped in the source tree for the trocar-placement experiment, relative to the root.
inline constexpr const char* kDefaultSceneRelativePath = "sim/models/scenes/trocar_or.yaml";

/// The scene a tool's --scene flag names: `path`; "" the shipped one (under the source tree,
/// base/source_paths.h); "none" no scene (the robot alone). Throws as LoadSceneFile.
std::optional<Scene> LoadSceneFlag(const std::string& path);

}  // namespace orbed::sim
