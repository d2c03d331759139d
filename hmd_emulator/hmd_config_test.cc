// orbed-hmd's `hmd:` mapping: the defaults documented in hmd_config.h, HmdConfig's member
// initializers and the shipped config/hmd.yaml agree, and the two keys the shipped file sets apart
// from the defaults (the walk's waypoint names) are what the defaults resolve to with the shipped walk.
#include "hmd_emulator/hmd_config.h"

#include <fstream>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "base/source_paths.h"
#include "base/yaml_fields.h"

namespace orbed::hmd {
namespace {

void ExpectSame(const HmdConfig& a, const HmdConfig& b, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.gaze_hz, b.gaze_hz);
  EXPECT_EQ(a.reflective_hz, b.reflective_hz);
  EXPECT_EQ(a.ar_view_hz, b.ar_view_hz);
  EXPECT_EQ(a.align_waypoint, b.align_waypoint);
  EXPECT_EQ(a.settle_s, b.settle_s);
  EXPECT_EQ(a.max_wait_s, b.max_wait_s);
  EXPECT_EQ(a.max_repeats, b.max_repeats);
  EXPECT_EQ(a.recapture_period_s, b.recapture_period_s);
  EXPECT_EQ(a.gaze_fallback_distance_m, b.gaze_fallback_distance_m);
  EXPECT_EQ(a.max_gaze_distance_m, b.max_gaze_distance_m);
  EXPECT_EQ(a.annotation_landmarks, b.annotation_landmarks);
  EXPECT_EQ(a.annotation_pointing_std_deg, b.annotation_pointing_std_deg);
  EXPECT_EQ(a.annotation_dwell_s, b.annotation_dwell_s);
  EXPECT_EQ(a.annotation_view_angle_deg, b.annotation_view_angle_deg);
  EXPECT_EQ(a.annotation_walk_speed_m_per_s, b.annotation_walk_speed_m_per_s);
  EXPECT_EQ(a.session_start_m, b.session_start_m);
  ASSERT_EQ(a.displays.size(), b.displays.size());
  for (std::size_t i = 0; i < a.displays.size(); ++i) {
    EXPECT_EQ(a.displays[i].capture_waypoint, b.displays[i].capture_waypoint) << i;
  }
}

TEST(HmdConfig, HeaderStructAndShippedFileAgree) {
  const std::string header = orbed::SourceTreePath("hmd_emulator/hmd_config.h");
  const std::string file = orbed::SourceTreePath("hmd_emulator/config/hmd.yaml");
  const YAML::Node doc = YamlFields::LoadDocBlock(header);
  const std::set<std::string> documented = YamlFields::KeyPaths(doc);
  for (const std::string& k : YamlFields::KeyPaths(YamlFields::LoadFile(file))) {
    if (k == "hmd.displays") continue;  // a list of waypoint names, documented in prose
    EXPECT_TRUE(documented.count(k)) << k << ": set in " << file << ", not documented in " << header;
  }
  ExpectSame(ParseHmdConfig(doc["hmd"], header), HmdConfig{}, "header vs HmdConfig");

  // The shipped file differs from the defaults only where hmd_config.h says: it names the shipped
  // walk's waypoints.
  HmdConfig expected;
  expected.align_waypoint = "head_end";
  expected.displays = {{"foot_end"}, {"head_end"}};
  ExpectSame(ParseHmdConfig(YamlFields::LoadFile(file)["hmd"], file), expected, "config/hmd.yaml");

  // With the shipped walk, the defaults resolve to the same alignment waypoint (the walk's last)
  // and the same first display (at the walk's first waypoint).
  std::vector<std::string> without_hmd;
  for (const std::string& rel : DefaultHmdConfigRelativePaths()) {
    if (rel != "hmd_emulator/config/hmd.yaml") without_hmd.push_back(HmdSourcePath(rel));
  }
  ASSERT_EQ(without_hmd.size(), 3u);
  const HmdConfigSet defaults = LoadHmdConfigs(without_hmd);
  EXPECT_EQ(defaults.hmd.align_waypoint, expected.align_waypoint);
  ASSERT_EQ(defaults.hmd.displays.size(), 1u);
  EXPECT_EQ(defaults.hmd.displays[0].capture_waypoint, expected.displays[0].capture_waypoint);
}

// hmd.collaborator (viraal_trial.h's CollaboratorDisplay): absent by default; read and checked
// like the other waypoint names, against the loaded walk.
TEST(HmdConfig, TheCollaboratorNamesAWaypointOfTheWalk) {
  std::vector<std::string> paths;
  for (const std::string& rel : DefaultHmdConfigRelativePaths()) paths.push_back(HmdSourcePath(rel));
  EXPECT_TRUE(LoadHmdConfigs(paths).hmd.collaborator.waypoint.empty());
  auto with = [&](const std::string& yaml) {
    const std::string path = ::testing::TempDir() + "collaborator.yaml";
    std::ofstream(path) << yaml;
    std::vector<std::string> all = paths;
    all.push_back(path);
    return LoadHmdConfigs(all);
  };
  const HmdConfigSet set = with(
      "hmd:\n  collaborator: {waypoint: foot_end, colocalization_translation_mm: 12, "
      "colocalization_rotation_deg: 0.4}\n");
  EXPECT_EQ(set.hmd.collaborator.waypoint, "foot_end");
  EXPECT_EQ(set.hmd.collaborator.colocalization_translation_mm, 12);
  EXPECT_EQ(set.hmd.collaborator.colocalization_rotation_deg, 0.4);
  auto error = [&](const std::string& yaml) {
    try {
      with(yaml);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  EXPECT_NE(error("hmd:\n  collaborator: {waypoint: the_door}\n").find("hmd.collaborator.waypoint"),
            std::string::npos);
  EXPECT_NE(error("hmd:\n  collaborator: {waypoint: foot_end, colocalization_translation_mm: -1}\n")
                .find("colocalization_translation_mm"),
            std::string::npos);
  EXPECT_NE(error("hmd:\n  collaborator: {waypoint: foot_end, wall: 1}\n").find("wall"), std::string::npos);
}

}  // namespace
}  // namespace orbed::hmd
