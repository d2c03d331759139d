#include "hmd_emulator/hmd_config.h"

#include <cstdlib>
#include <limits>
#include <stdexcept>

#include "base/source_paths.h"
#include "base/yaml_fields.h"

namespace orbed::hmd {
namespace {

std::string Text(const YamlFields& f, const YAML::Node& map, const std::string& name, const std::string& key,
                 const std::string& fallback) {
  const YAML::Node node = map[name];
  if (!node.IsDefined() || node.IsNull()) return fallback;
  if (!node.IsScalar()) f.Fail(node, key + "." + name, "expected a string");
  return node.as<std::string>();
}

}  // namespace

std::string HmdSourcePath(const std::string& relative) { return orbed::SourceTreePath(relative); }

std::vector<std::string> DefaultHmdConfigRelativePaths() {
  return {kDefaultSlamConfigRelativePath, kDefaultUserConfigRelativePath,
          "hmd_emulator/config/viraal_walk.yaml", "hmd_emulator/config/hmd.yaml"};
}

HmdConfig ParseHmdConfig(const YAML::Node& node, const std::string& source, const std::string& key,
                         const HmdConfig& base) {
  const YamlFields f(source);
  f.CheckKeys(
      node, key,
      {"name", "gaze_hz", "reflective_hz", "ar_view_hz", "align_waypoint", "settle_s", "max_wait_s",
       "max_repeats", "recapture_period_s", "gaze_fallback_distance_m", "max_gaze_distance_m", "displays",
       "annotation_landmarks", "annotation_pointing_std_deg", "annotation_dwell_s",
       "annotation_view_angle_deg", "annotation_walk_speed_m_per_s", "session_start_m", "collaborator"});
  HmdConfig c = base;
  c.name = Text(f, node, "name", key, c.name);
  c.gaze_hz = f.NumberOr(node, "gaze_hz", key, c.gaze_hz, 0.1, 1000, "Hz");
  c.reflective_hz = f.NumberOr(node, "reflective_hz", key, c.reflective_hz, 0.1, 1000, "Hz");
  c.ar_view_hz = f.NumberOr(node, "ar_view_hz", key, c.ar_view_hz, 0.1, 1000, "Hz");
  c.align_waypoint = Text(f, node, "align_waypoint", key, c.align_waypoint);
  c.settle_s = f.NumberOr(node, "settle_s", key, c.settle_s, 0, 600, "s");
  c.max_wait_s = f.NumberOr(node, "max_wait_s", key, c.max_wait_s, 0, 3600, "s");
  c.max_repeats = static_cast<int>(f.IntegerOr(node, "max_repeats", key, c.max_repeats, 0, 100));
  c.recapture_period_s = f.NumberOr(node, "recapture_period_s", key, c.recapture_period_s, 0, 3600, "s");
  c.gaze_fallback_distance_m =
      f.NumberOr(node, "gaze_fallback_distance_m", key, c.gaze_fallback_distance_m, 0.05, 100, "m");
  c.max_gaze_distance_m = f.NumberOr(node, "max_gaze_distance_m", key, c.max_gaze_distance_m, 0.1, 1000, "m");
  const YAML::Node landmarks = node["annotation_landmarks"];
  if (landmarks.IsDefined() && !landmarks.IsNull()) {
    if (!landmarks.IsSequence() || landmarks.size() > kMaxAnnotationLandmarks) {
      f.Fail(landmarks, key + ".annotation_landmarks",
             "expected a list of at most " + std::to_string(kMaxAnnotationLandmarks) + " link names");
    }
    c.annotation_landmarks.clear();  // [] = no annotation
    if (landmarks.size() > 0) c.annotation_landmarks = f.Strings(landmarks, key + ".annotation_landmarks");
  }
  c.annotation_pointing_std_deg =
      f.NumberOr(node, "annotation_pointing_std_deg", key, c.annotation_pointing_std_deg, 0, 10, "deg");
  c.annotation_dwell_s = f.NumberOr(node, "annotation_dwell_s", key, c.annotation_dwell_s, 0.01, 60, "s");
  c.annotation_view_angle_deg =
      f.NumberOr(node, "annotation_view_angle_deg", key, c.annotation_view_angle_deg, 5, 150, "deg");
  c.annotation_walk_speed_m_per_s =
      f.NumberOr(node, "annotation_walk_speed_m_per_s", key, c.annotation_walk_speed_m_per_s, 0.05, 5, "m/s");
  if (node["session_start_m"]) {
    c.session_start_m = f.Vector3(node["session_start_m"], key + ".session_start_m", "m");
    if (c.session_start_m.norm() > 100)
      f.Fail(node["session_start_m"], key + ".session_start_m", "more than 100 m from W");
  }
  const YAML::Node collaborator = node["collaborator"];
  if (collaborator.IsDefined() && !collaborator.IsNull()) {
    const std::string k = key + ".collaborator";
    f.CheckKeys(collaborator, k,
                {"waypoint", "colocalization_translation_mm", "colocalization_rotation_deg"});
    c.collaborator.waypoint = Text(f, collaborator, "waypoint", k, "");
    if (c.collaborator.waypoint.empty()) f.Fail(collaborator, k + ".waypoint", "missing (a waypoint name)");
    c.collaborator.colocalization_translation_mm =
        f.NumberOr(collaborator, "colocalization_translation_mm", k, 0.0, 0, 1000, "mm");
    c.collaborator.colocalization_rotation_deg =
        f.NumberOr(collaborator, "colocalization_rotation_deg", k, 0.0, 0, 45, "deg");
  }
  const YAML::Node displays = node["displays"];
  if (displays.IsDefined() && !displays.IsNull()) {
    if (!displays.IsSequence() || displays.size() == 0 || displays.size() > 16) {
      f.Fail(displays, key + ".displays", "expected a list of 1 to 16 {capture_waypoint: NAME}");
    }
    c.displays.clear();  // a list is replaced as a whole
    for (std::size_t i = 0; i < displays.size(); ++i) {
      const std::string k = key + ".displays[" + std::to_string(i) + "]";
      f.CheckKeys(displays[i], k, {"capture_waypoint"});
      DisplayPlacement d;
      d.capture_waypoint = Text(f, displays[i], "capture_waypoint", k, "");
      if (d.capture_waypoint.empty())
        f.Fail(displays[i], k + ".capture_waypoint", "missing (a waypoint name)");
      c.displays.push_back(d);
    }
  }
  return c;
}

HmdConfigSet LoadHmdConfigs(const std::vector<std::string>& paths) {
  HmdConfigSet set;
  std::string walk_source, align_source = "(defaults)", displays_source = "(defaults)",
                           collaborator_source = "(defaults)";
  for (const std::string& path : paths) {
    const YAML::Node root = YamlFields::LoadFile(path);
    const YamlFields f(path);
    if (root.IsNull()) continue;  // an empty file sets nothing
    f.CheckKeys(root, "", {"slam", "user", "head_trajectory", "hmd"});
    // Each section over what the earlier files set (key by key).
    if (root["slam"]) set.slam = ParseSlamConfig(root["slam"], path, "slam", set.slam);
    if (root["user"]) set.user = ParseUserConfig(root["user"], path, "user", set.user);
    if (root["head_trajectory"]) {
      set.walk = ParseHeadTrajectory(root["head_trajectory"], path);
      walk_source = path;
    }
    if (root["hmd"]) {
      set.hmd = ParseHmdConfig(root["hmd"], path, "hmd", set.hmd);
      if (root["hmd"]["align_waypoint"]) align_source = path;
      if (root["hmd"]["displays"]) displays_source = path;
      if (root["hmd"]["collaborator"]) collaborator_source = path;
    }
    set.sources.push_back(path);
  }
  if (set.walk.waypoints.empty()) {
    throw std::runtime_error(
        "no head_trajectory: none of the config files (" + std::to_string(paths.size()) +
        ") has a `head_trajectory:` mapping; add one (see hmd_emulator/config/viraal_walk.yaml)");
  }
  HeadTrajectory walk(set.walk);  // validates the walk
  auto check = [&](const std::string& name, const std::string& what, const std::string& source) {
    if (walk.FindWaypoint(name) < 0) {
      std::string names;
      for (const auto& w : set.walk.waypoints) names += (names.empty() ? "" : ", ") + w.name;
      throw std::runtime_error(source + ": " + what + ": the walk (" + walk_source + ") has no waypoint '" +
                               name + "'; it has: " + names);
    }
  };
  if (set.hmd.displays.empty()) set.hmd.displays.push_back({set.walk.waypoints.front().name});
  if (set.hmd.align_waypoint.empty()) set.hmd.align_waypoint = set.walk.waypoints.back().name;
  check(set.hmd.align_waypoint, "hmd.align_waypoint", align_source);
  for (std::size_t i = 0; i < set.hmd.displays.size(); ++i) {
    check(set.hmd.displays[i].capture_waypoint, "hmd.displays[" + std::to_string(i) + "].capture_waypoint",
          displays_source);
  }
  if (!set.hmd.collaborator.waypoint.empty())
    check(set.hmd.collaborator.waypoint, "hmd.collaborator.waypoint", collaborator_source);
  return set;
}

HmdConfigSet MovedBy(const Eigen::Isometry3d& X, HmdConfigSet config) {
  config.walk.p_W_look_at = X * config.walk.p_W_look_at;
  for (HeadWaypoint& w : config.walk.waypoints) {
    w.p_WH = X * w.p_WH;
    if (w.p_W_look_at) w.p_W_look_at = X * *w.p_W_look_at;
  }
  config.hmd.session_start_m = X * config.hmd.session_start_m;
  return config;
}

}  // namespace orbed::hmd
