// The orbed-scenario command line, run in-process: --help, bad flags, and the run id's sources
// (--run-id, else viraal-<UTC time>; never the environment) seen in results.json of a run on memq:// that
// fails fast for want of a robot.
#include "procs/scenario/scenario_cli.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/source_paths.h"

namespace orbed::scenario {
namespace {

struct CliRun {
  int code;
  std::string out, err;
};

CliRun Cli(std::vector<std::string> args) {
  args.insert(args.begin(), "orbed-scenario");
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  const int code = RunScenario(static_cast<int>(argv.size()), argv.data(), out, err);
  return {code, out.str(), err.str()};
}

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(ScenarioCli, HelpPrintsTheUsageOnOut) {
  const CliRun r = Cli({"--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_TRUE(Contains(r.out, "orbed-scenario: conducts the ViRAAl experiment")) << r.out;
  for (const char* flag : {"--scenario", "--trials", "--modes", "--q-deg", "--run-id", "--results-dir",
                           "--urdf", "--tolerance-deg", "--startup-timeout-s", "--request-deadline-s",
                           "--move-timeout-s", "--retry-initial-s", "--retry-max-s", "--robot-state-channel",
                           "--misalignment-channel", "--lcm-url", "--seed", "--duration-s", "--chaos"}) {
    EXPECT_TRUE(Contains(r.out, flag)) << flag;
  }
  EXPECT_FALSE(Contains(r.out, "ORBED_RUN_ID"));
  EXPECT_EQ(r.err, "");
}

TEST(ScenarioCli, BadFlagsExitNonZeroWithTheMessageOnErr) {
  CliRun r = Cli({"--no-such-flag-xyz"});
  EXPECT_NE(r.code, 0);
  EXPECT_TRUE(Contains(r.err, "--no-such-flag-xyz")) << r.err;
  EXPECT_EQ(r.out, "");
  r = Cli({"--trials", "0"});
  EXPECT_NE(r.code, 0);
  EXPECT_TRUE(Contains(r.err, "--trials")) << r.err;
  r = Cli({"--request-deadline-s", "-1"});
  EXPECT_NE(r.code, 0);
  EXPECT_TRUE(Contains(r.err, "--request-deadline-s")) << r.err;
  for (const char* not_finite : {"nan", "inf", "-nan"}) {  // no comparison stops a NaN deadline
    r = Cli({"--request-deadline-s", not_finite});
    EXPECT_NE(r.code, 0) << not_finite;
    EXPECT_TRUE(Contains(r.err, "expected a finite number")) << r.err;
  }
  r = Cli({"--retry-initial-s", "1", "--retry-max-s", "0.5", "--lcm-url", "memq://"});
  EXPECT_NE(r.code, 0);
  EXPECT_TRUE(Contains(r.err, "--retry-max-s must be >= --retry-initial-s")) << r.err;
  r = Cli({"--chaos", "drop=0.1,lose=1"});
  EXPECT_NE(r.code, 0);
  EXPECT_TRUE(Contains(r.err, "--chaos")) << r.err;
  r = Cli({"--log-level", "loud"});
  EXPECT_NE(r.code, 0);
  EXPECT_TRUE(Contains(r.err, "loud")) << r.err;
}

TEST(ScenarioCli, AScenarioThatCannotBeBuiltExitsOneWithTheReasonOnErr) {
  const CliRun r = Cli({"--lcm-url", "memq://", "--q-deg", "0,130,0,0,0,0,0"});
  EXPECT_EQ(r.code, 1);
  EXPECT_TRUE(Contains(r.err, "orbed-scenario: configuration 0: ")) << r.err;
}

// Runs on memq:// with no robot: the run fails after 50 ms and writes results.json.
std::string RunIdOfAFailedRun(const std::vector<std::string>& extra, CliRun* run) {
  const std::string dir = std::filesystem::temp_directory_path() / "orbed_scenario_cli_test";
  std::filesystem::remove_all(dir);
  std::vector<std::string> args = {"--lcm-url", "memq://",       "--startup-timeout-s",
                                   "0.05",      "--results-dir", dir};
  args.insert(args.end(), extra.begin(), extra.end());
  *run = Cli(args);
  const std::string json = ReadFile(dir + "/results.json");
  const std::string key = "\"run_id\": \"";
  const size_t begin = json.find(key);
  if (begin == std::string::npos) return "<no run_id in results.json>";
  const size_t end = json.find('"', begin + key.size());
  return json.substr(begin + key.size(), end - begin - key.size());
}

// The run id is a setting of the run: the flag, or the clock; never the environment (a stray
// variable must not change a run).
TEST(ScenarioCli, TheRunIdComesFromTheFlagThenTheClock) {
  CliRun run;
  EXPECT_EQ(RunIdOfAFailedRun({"--run-id", "from-flag"}, &run), "from-flag");
  EXPECT_EQ(run.code, 1);
  EXPECT_TRUE(Contains(run.out, "ViRAAl run from-flag: waiting for the robot (ROBOT_STATE)")) << run.out;
  EXPECT_TRUE(Contains(run.out, "FAILED: no valid ROBOT_STATE on ROBOT_STATE within 0.1 s")) << run.out;
  EXPECT_EQ(RunIdOfAFailedRun({"--run-id", ""}, &run).rfind("viraal-", 0), 0u);
  ::setenv("ORBED_RUN_ID", "from-env", 1);
  const std::string id = RunIdOfAFailedRun({}, &run);
  ::unsetenv("ORBED_RUN_ID");
  EXPECT_EQ(id.rfind("viraal-", 0), 0u) << id;
  EXPECT_EQ(id.size(), std::string("viraal-20250101T000000Z").size()) << id;
}

// --print: the pinned run's table (its Table 1 rows as docs/studies.md's pinned block shows them), exit
// 0; the same run marked partial, exit 3 with the trials done; a missing file, exit 1 naming it.
TEST(ScenarioCli, PrintsAFinishedRunsTable) {
  const std::string pinned = SourceTreePath("tests/integration/testdata/viraal_pinned_results.json");
  CliRun r = Cli({"--print", pinned});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(Contains(r.out, "ViRAAl run pinned: ok")) << r.out;
  EXPECT_TRUE(Contains(r.out, "Table 1 (3 trials): ")) << r.out;
  EXPECT_TRUE(Contains(r.out, "(paper: 30.2 +/- 23.9 mm)")) << r.out;

  std::string text = ReadFile(pinned);
  const std::string ok = "\"status\": \"ok\"";
  ASSERT_NE(text.find(ok), std::string::npos);
  text.replace(text.find(ok), ok.size(), "\"status\": \"partial\"");
  const std::string partial = ::testing::TempDir() + "partial_results.json";
  std::ofstream(partial) << text;
  r = Cli({"--print", partial});
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_TRUE(Contains(r.out, "ViRAAl run pinned: partial")) << r.out;
  EXPECT_TRUE(Contains(r.out, "the run stopped before it finished (6 trial(s) done)")) << r.out;

  r = Cli({"--print", "/nonexistent/results.json"});
  EXPECT_EQ(r.code, 1);
  EXPECT_TRUE(Contains(r.err, "/nonexistent/results.json")) << r.err;
}

}  // namespace
}  // namespace orbed::scenario
