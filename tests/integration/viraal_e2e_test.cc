// The ViRAAl run end to end, as `scripts/orbed run` does it: orbed-launch with
// scripts/launch/viraal.yaml (logger, sim, registration, monitor, orbed-hmd, orbed-scenario) in a
// private network namespace. The scenario ends the run; the launcher must exit 0 and leave a log,
// a complete manifest and a results.json with 2 sessions × 3 trials and 2 means.
//
// The run is seeded (every process's default --seed 1, run id "pinned"), so its results.json is
// fully determined: it must equal, number for number, testdata/viraal_pinned_results.json, which
// was written by the testbed before its redesign into pure cores and shared libraries. A change
// that moves any emulated trial, registration or error shows here.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <lcm/lcm-cpp.hpp>
#include <orbed/iiwa_status_t.hpp>

#include "tests/integration/logged.h"
#include "tests/integration/testbed_util.h"
#include "tests/same_tree.h"

namespace orbed::testing {
namespace {

namespace fs = std::filesystem;

void ExpectErrors(const YAML::Node& node, const std::string& where) {
  for (const char* key : {"translation_error_mm", "rotation_error_deg", "misalignment_mm"}) {
    ASSERT_TRUE(node[key]) << where << " lacks " << key;
    const double value = node[key].as<double>();
    EXPECT_TRUE(std::isfinite(value) && value >= 0) << where << "." << key << " = " << value;
  }
  // An emulated person is not perfect, and not absurd: within a metre and 10 degrees.
  EXPECT_LT(node["translation_error_mm"].as<double>(), 1000.0) << where;
  EXPECT_LT(node["rotation_error_deg"].as<double>(), 10.0) << where;
}

TEST(ViraalRun, LaunchFileRunsTheStudyAndWritesResults) {
  const std::string log_dir = MakeTempDir("viraal_e2e");
  RunningProcess launcher({BinPath("orbed-launch"), SourcePath("scripts/launch/viraal.yaml"), "--duration-s",
                           "240", "--arg", "run_id=pinned"},
                          {{"ORBED_LOG_DIR", log_dir}});
  ASSERT_TRUE(launcher.Wait(240)) << "the run did not finish";
  EXPECT_EQ(launcher.term_signal(), 0);
  ASSERT_EQ(launcher.exit_code(), 0);

  // results.json is JSON, which YAML reads.
  const YAML::Node results = YAML::LoadFile(log_dir + "/results.json");
  EXPECT_EQ(results["status"].as<std::string>(), "ok");
  const YAML::Node sessions = results["sessions"];
  ASSERT_EQ(sessions.size(), 2u);
  std::set<std::string> modes;
  for (const auto& session : sessions) {
    const std::string mode = session["mode"].as<std::string>();
    modes.insert(mode);
    ASSERT_EQ(session["trials"].size(), 3u) << mode;
    for (size_t i = 0; i < 3; ++i) {
      EXPECT_EQ(session["trials"][i]["index"].as<int>(), static_cast<int>(i));
      EXPECT_EQ(session["trials"][i]["q_deg"].size(), 7u);
      ExpectErrors(session["trials"][i], mode + " trial " + std::to_string(i));
    }
    ExpectErrors(session["mean"], mode + " mean");
  }
  EXPECT_EQ(modes, (std::set<std::string>{"ar", "ar_reflective"}));

  // Seeded: the numbers of the run before the redesign, exactly.
  const YAML::Node pinned =
      YAML::LoadFile(SourcePath("tests/integration/testdata/viraal_pinned_results.json"));
  ExpectSameTree(pinned, results, "results", {"started_utime", "duration_s"});

  // The log beside it is whole and holds the study's messages.
  const YAML::Node manifest = YAML::LoadFile(log_dir + "/manifest.json");
  EXPECT_TRUE(manifest["complete"].as<bool>());
  EXPECT_EQ(manifest["drops"].as<int>(), 0);
  for (const char* channel : {"ALIGNMENT_TRIAL", "REGISTRATION", "HMD_POSE", "HMD_CAMERA", "REFLECTIVE_VIEW",
                              "IIWA_STATUS", "SESSION_CONTROL"}) {
    EXPECT_TRUE(manifest["channels"][channel]) << channel << " missing from the log";
  }
  EXPECT_EQ(manifest["channels"]["ALIGNMENT_TRIAL"]["events"].as<int>(), 6);
}

// Faster than real time (--arg sim_rate=8: the sim steps the arm 8 times per tick; every other
// process on its clock, --arg sim_time=1, which it holds until the conductor runs): the arm reaches
// the same configurations, so the run equals the pinned results number for number, and its log is
// whole.
TEST(ViraalRun, FasterThanRealTimeTheRunIsTheSame) {
  const std::string log_dir = MakeTempDir("viraal_fast");
  RunningProcess launcher(
      {BinPath("orbed-launch"), SourcePath("scripts/launch/viraal.yaml"), "--duration-s", "240", "--arg",
       "run_id=pinned", "--arg", "sim_rate=8", "--arg", "sim_time=1", "--arg", "hold_for=scenario"},
      {{"ORBED_LOG_DIR", log_dir}});
  ASSERT_TRUE(launcher.Wait(240)) << "the run did not finish";
  ASSERT_EQ(launcher.exit_code(), 0);
  const YAML::Node pinned =
      YAML::LoadFile(SourcePath("tests/integration/testdata/viraal_pinned_results.json"));
  ExpectSameTree(pinned, YAML::LoadFile(log_dir + "/results.json"), "results",
                 {"started_utime", "duration_s"});
  const YAML::Node manifest = YAML::LoadFile(log_dir + "/manifest.json");
  EXPECT_TRUE(manifest["complete"].as<bool>());
  EXPECT_EQ(manifest["drops"].as<int>(), 0);
  // The sim clock ran 8 times faster: IIWA_STATUS stamps 8 x 5 ms apart (a whole multiple of that
  // after a stall of the loop), where at the wall clock's pace they would be 5 ms apart.
  const std::vector<orbed::iiwa_status_t> status = Logged<orbed::iiwa_status_t>(log_dir, "IIWA_STATUS");
  // The run lasts about 100 of those steps (~4 s of sim time; how many depends on when the logger
  // and the sim start): enough that "most steps are exactly 40 ms" is a real check.
  ASSERT_GE(status.size(), 50u);
  size_t exact = 0;
  for (size_t k = 1; k < status.size(); ++k) {
    const int64_t step_us = status[k].utime - status[k - 1].utime;
    EXPECT_TRUE(step_us > 0 && step_us % 40000 == 0) << "stamp step " << step_us << " us at " << k;
    exact += step_us == 40000;
  }
  EXPECT_GT(exact, status.size() / 2);
}

// The scenario chooses where the display captures (contract change 6): a scenario naming head_end,
// the alignment viewpoint, runs over the bus (sim, registration, headset, conductor) to the same
// results.json as orbed-user-study with that scenario, which differs from the default choice's.
TEST(ViraalRun, TheScenariosCaptureWaypointReachesTheHeadset) {
  const std::string dir = MakeTempDir("viraal_capture");
  std::string text;
  {
    std::ifstream in(SourcePath("experiments/viraal/viraal.yaml"));
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  auto replaced = [](std::string s, const std::string& from, const std::string& to) {
    const size_t at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return at == std::string::npos ? s : s.replace(at, from.size(), to);
  };
  text = replaced(replaced(text, "modes: [ar_reflective, ar]", "modes: [ar_reflective]"), "trials: 3",
                  "trials: 2");
  const std::string chosen = replaced(text, "capture_waypoints: []", "capture_waypoints: [head_end]");
  for (const auto& [name, content] : {std::pair{"default", text}, std::pair{"chosen", chosen}}) {
    std::ofstream(dir + "/" + name + ".yaml") << content;
    RunningProcess study({BinPath("orbed-user-study"), "--scenario", dir + "/" + name + ".yaml", "--run-id",
                          "capture", "--json", dir + "/" + name + ".json", "--quiet"});
    ASSERT_TRUE(study.Wait(60));
    ASSERT_EQ(study.exit_code(), 0) << name;
  }

  RunningProcess sim({BinPath("orbed-iiwa-sim"), "--name", "sim"});
  RunningProcess registration({BinPath("orbed-registration"), "--name", "registration"});
  RunningProcess hmd({BinPath("orbed-hmd"), "--name", "hmd"});
  RunningProcess conductor({BinPath("orbed-scenario"), "--name", "scenario", "--scenario",
                            dir + "/chosen.yaml", "--run-id", "capture", "--results-dir", dir,
                            "--startup-timeout-s", "20"});
  ASSERT_TRUE(conductor.Wait(120)) << "orbed-scenario did not finish";
  ASSERT_EQ(conductor.exit_code(), 0);
  const YAML::Node bus = YAML::LoadFile(dir + "/results.json");
  ExpectSameTree(YAML::LoadFile(dir + "/chosen.json"), bus, "results", {"started_utime", "duration_s"});
  // Captured at head_end instead of foot_end: other frames, so another alignment.
  const YAML::Node by_default = YAML::LoadFile(dir + "/default.json");
  ASSERT_EQ(bus["sessions"][0]["capture_waypoints"].size(), 1u);
  EXPECT_EQ(bus["sessions"][0]["capture_waypoints"][0].as<std::string>(), "head_end");
  EXPECT_FALSE(by_default["sessions"][0]["capture_waypoints"].IsDefined());
  ASSERT_EQ(bus["sessions"][0]["trials"].size(), 2u);
  EXPECT_NE(bus["sessions"][0]["trials"][0]["X_WV"]["position_m"][0].as<double>(),
            by_default["sessions"][0]["trials"][0]["X_WV"]["position_m"][0].as<double>());
}

}  // namespace
}  // namespace orbed::testing
