#include "sim/scene.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

namespace orbed::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Reads typed values out of YAML nodes; every failure names the source, line, key and expectation.
class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void Fail(const YAML::Node& node, const std::string& key, const std::string& expected) const {
    std::string where = source_;
    if (node && node.Mark().line >= 0) where += ":" + std::to_string(node.Mark().line + 1);
    throw std::runtime_error(where + ": " + key + ": " + expected);
  }

  YAML::Node Required(const YAML::Node& map, const std::string& name, const std::string& key,
                      const std::string& expected) const {
    YAML::Node v = map[name];
    if (!v) Fail(map, key, "missing; expected " + expected);
    return v;
  }

  void OnlyKeys(const YAML::Node& map, const std::string& key, const std::set<std::string>& allowed) const {
    if (!map.IsMap()) Fail(map, key, "expected a mapping");
    for (const auto& kv : map) {
      const std::string k = kv.first.as<std::string>();
      if (!allowed.count(k)) {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        Fail(kv.first, key.empty() ? k : key + "." + k, "unknown key; expected one of: " + list);
      }
    }
  }

  double Number(const YAML::Node& node, const std::string& key, const std::string& expected) const {
    if (!node.IsScalar()) Fail(node, key, "expected " + expected);
    double v;
    try {
      v = node.as<double>();
    } catch (const YAML::Exception&) {
      Fail(node, key, "expected " + expected + ", got '" + node.Scalar() + "'");
    }
    if (!std::isfinite(v)) Fail(node, key, "expected " + expected + ", got a non-finite value");
    return v;
  }

  double Positive(const YAML::Node& node, const std::string& key) const {
    const double v = Number(node, key, "a number > 0 [m]");
    if (v <= 0) Fail(node, key, "expected a number > 0 [m], got " + node.Scalar());
    return v;
  }

  Eigen::Vector3d Vector3(const YAML::Node& node, const std::string& key, const std::string& expected) const {
    if (!node.IsSequence() || node.size() != 3) Fail(node, key, "expected " + expected);
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v[i] = Number(node[i], key + "[" + std::to_string(i) + "]", expected);
    return v;
  }

  Eigen::Isometry3d Pose(const YAML::Node& node, const std::string& key) const {
    OnlyKeys(node, key, {"position_m", "rpy_deg"});
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.translation() = Vector3(Required(node, "position_m", key + ".position_m", "[x, y, z] in m"),
                              key + ".position_m", "a list of 3 numbers [m]");
    if (node["rpy_deg"]) {
      X.linear() = RotationFromRpyDeg(Vector3(node["rpy_deg"], key + ".rpy_deg", "a list of 3 angles [deg]"));
    }
    return X;
  }

 private:
  std::string source_;
};

}  // namespace

Eigen::Matrix3d RotationFromRpyDeg(const Eigen::Vector3d& rpy_deg) {
  const Eigen::Vector3d r = rpy_deg * (kPi / 180.0);
  return (Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Scene LoadSceneFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the scene file");
  std::stringstream ss;
  ss << in.rdbuf();
  return LoadSceneString(ss.str(), path);
}

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
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(source_name + ":" + std::to_string(e.mark.line + 1) +
                             ": not valid YAML: " + e.msg);
  }
  const Reader r(source_name);
  if (!root || !root.IsMap()) {
    throw std::runtime_error(source_name + ": expected a YAML mapping with keys robot, trocar, objects");
  }
  Scene scene;
  scene.source = source_name;
  r.OnlyKeys(root, "", {"name", "robot", "trocar", "objects"});
  if (root["name"]) scene.name = root["name"].as<std::string>();

  const YAML::Node robot = r.Required(root, "robot", "robot", "a mapping with base_pose and tool_length_m");
  r.OnlyKeys(robot, "robot", {"base_pose", "tool_length_m"});
  scene.X_WR =
      r.Pose(r.Required(robot, "base_pose", "robot.base_pose", "{position_m: [x, y, z], rpy_deg: [r, p, y]}"),
             "robot.base_pose");
  scene.tool_length_m = r.Positive(
      r.Required(robot, "tool_length_m", "robot.tool_length_m", "a length > 0 [m]"), "robot.tool_length_m");

  const YAML::Node trocar =
      r.Required(root, "trocar", "trocar", "a mapping with position_m and insertion_direction");
  r.OnlyKeys(trocar, "trocar", {"position_m", "insertion_direction"});
  scene.trocar.p_WT = r.Vector3(r.Required(trocar, "position_m", "trocar.position_m", "[x, y, z] in m"),
                                "trocar.position_m", "a list of 3 numbers [m]");
  const YAML::Node dir_node =
      r.Required(trocar, "insertion_direction", "trocar.insertion_direction", "a unit vector [x, y, z]");
  const Eigen::Vector3d dir = r.Vector3(dir_node, "trocar.insertion_direction", "a unit vector [x, y, z]");
  if (std::abs(dir.norm() - 1.0) > 0.01) {
    r.Fail(dir_node, "trocar.insertion_direction",
           "expected a unit vector (norm within 1 % of 1), got norm " + std::to_string(dir.norm()));
  }
  scene.trocar.insertion_direction_W = dir.normalized();

  const YAML::Node objects = root["objects"];
  if (objects) {
    if (!objects.IsSequence()) r.Fail(objects, "objects", "expected a list of objects");
    std::set<std::string> names;
    for (size_t i = 0; i < objects.size(); ++i) {
      const YAML::Node o = objects[i];
      const std::string key = "objects[" + std::to_string(i) + "]";
      r.OnlyKeys(o, key, {"name", "shape", "size_m", "radius_m", "length_m", "pose", "ignore_links"});
      SceneObject obj;
      const YAML::Node name = r.Required(o, "name", key + ".name", "a unique name");
      obj.name = name.as<std::string>();
      if (obj.name.empty() || !names.insert(obj.name).second) {
        r.Fail(name, key + ".name",
               "expected a non-empty name not used by another object ('" + obj.name + "')");
      }
      const std::string shape =
          r.Required(o, "shape", key + ".shape", "box, cylinder or sphere").as<std::string>();
      if (shape == "box") {
        obj.shape = SceneObject::Shape::kBox;
        const YAML::Node s = r.Required(o, "size_m", key + ".size_m", "[lx, ly, lz] full side lengths in m");
        obj.size_m = r.Vector3(s, key + ".size_m", "a list of 3 numbers > 0 [m]");
        if ((obj.size_m.array() <= 0).any())
          r.Fail(s, key + ".size_m", "expected a list of 3 numbers > 0 [m]");
      } else if (shape == "cylinder") {
        obj.shape = SceneObject::Shape::kCylinder;
        obj.radius_m =
            r.Positive(r.Required(o, "radius_m", key + ".radius_m", "a radius > 0 [m]"), key + ".radius_m");
        obj.length_m =
            r.Positive(r.Required(o, "length_m", key + ".length_m", "a length > 0 [m]"), key + ".length_m");
      } else if (shape == "sphere") {
        obj.shape = SceneObject::Shape::kSphere;
        obj.radius_m =
            r.Positive(r.Required(o, "radius_m", key + ".radius_m", "a radius > 0 [m]"), key + ".radius_m");
      } else {
        r.Fail(o["shape"], key + ".shape", "expected box, cylinder or sphere, got '" + shape + "'");
      }
      for (const char* k : {"size_m", "radius_m", "length_m"}) {
        const bool wanted = (shape == "box" && std::string(k) == "size_m") ||
                            (shape == "cylinder" && std::string(k) != "size_m") ||
                            (shape == "sphere" && std::string(k) == "radius_m");
        if (o[k] && !wanted) r.Fail(o[k], key + "." + k, "not used by a " + shape + "; remove it");
      }
      obj.X_WO = r.Pose(r.Required(o, "pose", key + ".pose", "{position_m: [x, y, z], rpy_deg: [r, p, y]}"),
                        key + ".pose");
      if (o["ignore_links"]) {
        const YAML::Node il = o["ignore_links"];
        if (!il.IsSequence()) r.Fail(il, key + ".ignore_links", "expected a list of robot link names");
        for (const auto& n : il) obj.ignore_links.push_back(n.as<std::string>());
      }
      scene.objects.push_back(obj);
    }
  }
  return scene;
}

}  // namespace orbed::sim
