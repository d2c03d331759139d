#include "sim/scene.h"

#include <cmath>
#include <set>
#include <stdexcept>

#include "base/source_paths.h"
#include "base/units.h"
#include "base/yaml_fields.h"
#include "lcmtypes/contract/channels.h"

namespace orbed::sim {
namespace {

Eigen::Isometry3d Pose(const YamlFields& f, const YAML::Node& node, const std::string& key) {
  f.CheckKeys(node, key, {"position_m", "rpy_deg"});
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = f.Vector3(f.Required(node, "position_m", key + ".position_m", "[x, y, z] in m"),
                              key + ".position_m", "m");
  if (node["rpy_deg"]) X.linear() = RotationFromRpyDeg(f.Vector3(node["rpy_deg"], key + ".rpy_deg", "deg"));
  return X;
}

Scene LoadScene(const YAML::Node& root, const std::string& source) {
  const YamlFields f(source);
  if (!root.IsMap()) f.Fail(root, "(top level)", "expected a mapping with keys robot, trocar, objects");
  Scene scene;
  scene.source = source;
  f.CheckKeys(root, "", {"name", "robot", "arms", "trocar", "objects"});
  scene.name = f.StringOr(root, "name", "", scene.name);

  const YAML::Node robot = f.Required(root, "robot", "robot", "a mapping with base_pose and tool_length_m");
  f.CheckKeys(robot, "robot", {"base_pose", "tool_length_m"});
  scene.X_WR = Pose(
      f, f.Required(robot, "base_pose", "robot.base_pose", "{position_m: [x, y, z], rpy_deg: [r, p, y]}"),
      "robot.base_pose");
  scene.tool_length_m =
      f.Positive(f.Required(robot, "tool_length_m", "robot.tool_length_m", "a length > 0 [m]"),
                 "robot.tool_length_m", "m");

  // Several arms: each one's name and base; the robot's base_pose stays the single arm's.
  if (const YAML::Node arms = root["arms"]) {
    if (!arms.IsSequence() || arms.size() == 0 || arms.size() > kMaxSceneArms) {
      f.Fail(arms, "arms", "expected a list of 1.." + std::to_string(kMaxSceneArms) + " {name, base_pose}");
    }
    for (size_t i = 0; i < arms.size(); ++i) {
      const std::string key = "arms[" + std::to_string(i) + "]";
      f.CheckKeys(arms[i], key, {"name", "base_pose"});
      ArmPlacement arm;
      arm.name = f.String(f.Required(arms[i], "name", key + ".name", "a name"), key + ".name");
      if (!channels::IsInstanceName(arm.name)) {
        f.Fail(arms[i]["name"], key + ".name",
               std::string("expected ") + channels::kInstanceNameRule + " (it names channels), got '" +
                   arm.name + "'");
      }
      if (scene.FindArm(arm.name) != nullptr) {
        f.Fail(arms[i]["name"], key + ".name",
               "expected a name not used by another arm, got '" + arm.name + "'");
      }
      arm.X_WR = Pose(
          f,
          f.Required(arms[i], "base_pose", key + ".base_pose", "{position_m: [x, y, z], rpy_deg: [r, p, y]}"),
          key + ".base_pose");
      scene.arms.push_back(arm);
    }
  }

  const YAML::Node trocar =
      f.Required(root, "trocar", "trocar", "a mapping with position_m and insertion_direction");
  f.CheckKeys(trocar, "trocar", {"position_m", "insertion_direction"});
  scene.trocar.p_WT = f.Vector3(f.Required(trocar, "position_m", "trocar.position_m", "[x, y, z] in m"),
                                "trocar.position_m", "m");
  const YAML::Node dir_node =
      f.Required(trocar, "insertion_direction", "trocar.insertion_direction", "a unit vector [x, y, z]");
  const Eigen::Vector3d dir = f.Vector3(dir_node, "trocar.insertion_direction", "");
  if (std::abs(dir.norm() - 1.0) > 0.01) {
    f.Fail(dir_node, "trocar.insertion_direction",
           "expected a unit vector (norm within 1 % of 1), got norm " + std::to_string(dir.norm()));
  }
  scene.trocar.insertion_direction_W = dir.normalized();

  const YAML::Node objects = root["objects"];
  if (!objects) return scene;
  if (!objects.IsSequence()) f.Fail(objects, "objects", "expected a list of objects");
  std::set<std::string> names;
  for (size_t i = 0; i < objects.size(); ++i) {
    const YAML::Node o = objects[i];
    const std::string key = "objects[" + std::to_string(i) + "]";
    f.CheckKeys(o, key, {"name", "shape", "size_m", "radius_m", "length_m", "pose", "ignore_links"});
    SceneObject obj;
    const YAML::Node name = f.Required(o, "name", key + ".name", "a unique name");
    obj.name = f.String(name, key + ".name");
    if (obj.name.empty() || !names.insert(obj.name).second) {
      f.Fail(name, key + ".name",
             "expected a non-empty name not used by another object ('" + obj.name + "')");
    }
    const std::string shape = f.OneOf(f.Required(o, "shape", key + ".shape", "box, cylinder or sphere"),
                                      key + ".shape", {"box", "cylinder", "sphere"});
    if (shape == "box") {
      obj.shape = SceneObject::Shape::kBox;
      obj.size_m =
          f.PositiveVector3(f.Required(o, "size_m", key + ".size_m", "[lx, ly, lz] full side lengths in m"),
                            key + ".size_m", "m");
    } else if (shape == "cylinder") {
      obj.shape = SceneObject::Shape::kCylinder;
      obj.radius_m = f.Positive(f.Required(o, "radius_m", key + ".radius_m", "a radius > 0 [m]"),
                                key + ".radius_m", "m");
      obj.length_m = f.Positive(f.Required(o, "length_m", key + ".length_m", "a length > 0 [m]"),
                                key + ".length_m", "m");
    } else {
      obj.shape = SceneObject::Shape::kSphere;
      obj.radius_m = f.Positive(f.Required(o, "radius_m", key + ".radius_m", "a radius > 0 [m]"),
                                key + ".radius_m", "m");
    }
    for (const char* k : {"size_m", "radius_m", "length_m"}) {
      const bool wanted = (shape == "box" && std::string(k) == "size_m") ||
                          (shape == "cylinder" && std::string(k) != "size_m") ||
                          (shape == "sphere" && std::string(k) == "radius_m");
      if (o[k] && !wanted) f.Fail(o[k], key + "." + k, "not used by a " + shape + "; remove it");
    }
    obj.X_WO = Pose(f, f.Required(o, "pose", key + ".pose", "{position_m: [x, y, z], rpy_deg: [r, p, y]}"),
                    key + ".pose");
    if (const YAML::Node il = o["ignore_links"]) {
      if (!il.IsSequence()) f.Fail(il, key + ".ignore_links", "expected a list of robot link names");
      for (size_t j = 0; j < il.size(); ++j) {
        obj.ignore_links.push_back(f.String(il[j], key + ".ignore_links[" + std::to_string(j) + "]"));
      }
    }
    scene.objects.push_back(obj);
  }
  return scene;
}

}  // namespace

Eigen::Matrix3d RotationFromRpyDeg(const Eigen::Vector3d& rpy_deg) {
  const Eigen::Vector3d r = rpy_deg * kDegToRad;
  return (Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

const ArmPlacement* Scene::FindArm(const std::string& arm_name) const {
  for (const ArmPlacement& arm : arms) {
    if (arm.name == arm_name) return &arm;
  }
  return nullptr;
}

void Scene::StandAt(const std::string& arm_name) {
  if (arm_name.empty()) return;
  const ArmPlacement* placement = FindArm(arm_name);
  if (placement == nullptr) {
    std::string names;
    for (const ArmPlacement& a : arms) names += (names.empty() ? "" : ", ") + a.name;
    throw std::invalid_argument("--arm " + arm_name + ": the scene " + source + " has " +
                                (names.empty() ? "no arms: list" : "the arms " + names));
  }
  X_WR = placement->X_WR;
}

Scene LoadSceneFile(const std::string& path) { return LoadScene(YamlFields::LoadFile(path), path); }

RobotModel LoadRobotForScene(const std::string& urdf_path, const Scene& scene) {
  RobotModel model = RobotModel::LoadFile(urdf_path);
  try {
    model.SetToolLength(scene.tool_length_m);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(scene.source + ": robot.tool_length_m does not fit " + urdf_path + ": " +
                             e.what());
  }
  return model;
}

Scene LoadSceneString(const std::string& yaml_text, const std::string& source_name) {
  return LoadScene(YamlFields::LoadString(yaml_text, source_name), source_name);
}

std::optional<Scene> LoadSceneFlag(const std::string& path) {
  if (path == "none") return std::nullopt;
  return LoadSceneFile(path.empty() ? SourceTreePath(kDefaultSceneRelativePath) : path);
}

}  // namespace orbed::sim
