// The ViRAAl scenario file: the defaults documented in protocol.h, ScenarioConfig's member
// initializers and the shipped experiments/viraal/viraal.yaml agree, and an absent key takes the struct's
// default.
#include "experiments/viraal/protocol.h"

#include <set>
#include <string>

#include <gtest/gtest.h>

#include "base/source_paths.h"
#include "base/yaml_fields.h"

namespace orbed::viraal {
namespace {

void ExpectSameDefaults(const ScenarioConfig& a, const ScenarioConfig& b, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(a.trials, b.trials);
  EXPECT_EQ(a.method, b.method);
  EXPECT_EQ(a.capture_waypoints, b.capture_waypoints);
  ASSERT_EQ(a.modes.size(), b.modes.size());
  for (std::size_t i = 0; i < a.modes.size(); ++i) {
    EXPECT_EQ(a.modes[i].name, b.modes[i].name) << i;
    EXPECT_EQ(a.modes[i].display_mode, b.modes[i].display_mode) << i;
    EXPECT_EQ(a.modes[i].num_mirrors, b.modes[i].num_mirrors) << i;
  }
}

TEST(ScenarioConfig, HeaderStructAndShippedFileAgree) {
  const std::string header = orbed::SourceTreePath("experiments/viraal/protocol.h");
  const std::string file = orbed::SourceTreePath(kDefaultScenarioRelativePath);
  const YAML::Node doc = YamlFields::LoadDocBlock(header);
  const YAML::Node shipped_yaml = YamlFields::LoadFile(file);
  const std::set<std::string> documented = YamlFields::KeyPaths(doc);
  for (const std::string& k : YamlFields::KeyPaths(shipped_yaml)) {
    EXPECT_TRUE(documented.count(k)) << k << ": set in " << file << ", not documented in " << header;
  }
  const ScenarioConfig d;
  ExpectSameDefaults(LoadScenarioString(YAML::Dump(doc), header), d, "header vs ScenarioConfig");
  ExpectSameDefaults(LoadScenarioFile(file), d, "viraal.yaml vs ScenarioConfig");
  EXPECT_EQ(doc["reflective_mirrors"].as<int>(), kDefaultReflectiveMirrors);
  EXPECT_EQ(shipped_yaml["reflective_mirrors"].as<int>(), kDefaultReflectiveMirrors);

  // Only the required keys: everything else is ScenarioConfig's default.
  const ScenarioConfig bare = LoadScenarioString(
      "configurations_deg: [[0, 30, 0, -60, 0, 45, 0]]\nlandmarks: [iiwa_link_4]\n", "bare.yaml");
  ExpectSameDefaults(bare, d, "absent keys");
  // reflective_mirrors applies to the default modes too.
  const ScenarioConfig two = LoadScenarioString(
      "reflective_mirrors: 2\nconfigurations_deg: [[0, 30, 0, -60, 0, 45, 0]]\nlandmarks: [iiwa_link_4]\n",
      "two.yaml");
  ASSERT_EQ(two.modes.size(), 2u);
  EXPECT_EQ(two.modes[0].num_mirrors, 2);
  EXPECT_EQ(two.modes[1].num_mirrors, 0);
}

}  // namespace
}  // namespace orbed::viraal
