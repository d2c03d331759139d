// Unit tests of orbed-launch's launch-file parser and child handling (no LCM needed). The
// multi-process behaviour (readiness, respawn, ordered stop) is in tests/integration.
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>

#include "base/test_command.h"
#include "procs/launcher/child.h"
#include "procs/launcher/launch_file.h"
#include "procs/launcher/launcher.h"
#include "procs/launcher/launcher_cli.h"

namespace orbed::launcher {
namespace {

const std::map<std::string, std::string> kEnv = {{"LOGS", "/tmp/logs"}, {"BIN", "/opt/b"}};

std::string ErrorOf(const std::string& yaml) {
  try {
    ParseLaunchYaml(yaml, "test.yaml", kEnv);
  } catch (const LaunchFileError& e) {
    return e.what();
  }
  return "";
}

std::string ErrorOfFile(const std::string& path) {
  try {
    LoadLaunchFile(path, kEnv);
  } catch (const LaunchFileError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(LaunchFile, ParsesGroupsProcessesDefaultsAndVariables) {
  const LaunchSpec spec = ParseLaunchYaml(R"(
name: bed
groups:
  - name: first
    processes:
      - name: logger
        command: orbed-logger
        args: [--log-dir, "${LOGS}/x"]
  - name: second
    processes:
      - name: tool
        command: ${BIN}/tool
        env: {A: "1", B: "${LOGS}"}
        respawn: true
        required: false
        stop_signal: SIGTERM
        stop_timeout_s: 2.5
        ready: none
        exit_stops_all: true
)",
                                          "test.yaml", kEnv);
  EXPECT_EQ(spec.name, "bed");
  ASSERT_EQ(spec.groups.size(), 2u);
  const ProcessSpec& logger = spec.groups[0].processes.at(0);
  EXPECT_EQ(logger.command, "orbed-logger");
  EXPECT_EQ(logger.args, (std::vector<std::string>{"--log-dir", "/tmp/logs/x"}));
  EXPECT_TRUE(logger.required);
  EXPECT_FALSE(logger.respawn);
  EXPECT_EQ(logger.stop_signal, SIGINT);
  EXPECT_EQ(logger.stop_timeout_s, 5.0);
  EXPECT_EQ(logger.ready, ReadyCheck::kHeartbeat);
  const ProcessSpec& tool = spec.groups[1].processes.at(0);
  EXPECT_EQ(tool.command, "/opt/b/tool");
  EXPECT_EQ(tool.env.at("B"), "/tmp/logs");
  EXPECT_TRUE(tool.respawn);
  EXPECT_FALSE(tool.required);
  EXPECT_EQ(tool.stop_signal, SIGTERM);
  EXPECT_EQ(tool.stop_timeout_s, 2.5);
  EXPECT_EQ(tool.ready, ReadyCheck::kNone);
  EXPECT_TRUE(tool.exit_stops_all);
}

TEST(LaunchFile, ErrorsNameFileLineKeyAndFix) {
  EXPECT_EQ(ErrorOf("groups: []"), "test.yaml:1: groups: expected a non-empty list of {name, processes}");
  const std::string typo = ErrorOf(
      "groups:\n  - name: g\n    processes:\n      - name: a\n        command: x\n        "
      "respawm: true\n");
  EXPECT_NE(typo.find("test.yaml:6: groups[0].processes[0].respawm: unknown key"), std::string::npos) << typo;
  EXPECT_NE(typo.find("respawn"), std::string::npos);
  EXPECT_NE(ErrorOf("groups:\n  - name: g\n    processes:\n      - name: a\n")
                .find("test.yaml:4: groups[0].processes[0].command: missing; expected a string"),
            std::string::npos);
  EXPECT_NE(
      ErrorOf("groups:\n  - name: g\n    processes:\n      - {name: a, command: x, "
              "stop_signal: SIGFOO}\n")
          .find("test.yaml:4: groups[0].processes[0].stop_signal: expected SIGINT, SIGTERM, SIGHUP, SIGQUIT, "
                "SIGUSR1, SIGUSR2 or SIGKILL, got 'SIGFOO'"),
      std::string::npos);
  EXPECT_NE(ErrorOf("groups:\n  - name: g\n    processes:\n      - {name: a, command: x}\n"
                    "      - {name: a, command: y}\n")
                .find("test.yaml:5: groups[0].processes[1].name: expected a name not used by another "
                      "process, got 'a'"),
            std::string::npos);
  EXPECT_NE(ErrorOf("groups:\n  - name: g\n    processes:\n      - {name: a, command: "
                    "\"${NOPE}/x\"}\n")
                .find("test.yaml:4: groups[0].processes[0].command: variable ${NOPE} is not set"),
            std::string::npos);
  EXPECT_NE(ErrorOf("groups:\n  - name: g\n    processes:\n      - {name: a, command: x, "
                    "respawn: maybe}\n")
                .find("test.yaml:4: groups[0].processes[0].respawn: expected true or false, got 'maybe'"),
            std::string::npos);
  EXPECT_NE(ErrorOf("groups: [\n").find("test.yaml:2: not valid YAML"), std::string::npos);
  // Hostile structure: maps and lists where words belong.
  EXPECT_NE(ErrorOf("groups:\n  - name: g\n    processes:\n      - {name: a, command: x, [1, 2]: 3}\n")
                .find("test.yaml:4: groups[0].processes[0]: expected plain words as keys"),
            std::string::npos);
  EXPECT_NE(ErrorOf("groups:\n  - name: g\n    processes:\n      - {name: a, command: x, env: {[1]: b}}\n")
                .find("test.yaml:4: groups[0].processes[0].env: expected plain words as variable names"),
            std::string::npos);
  EXPECT_NE(ErrorOf("groups:\n  - name: [g]\n    processes: []\n"), "");
  EXPECT_NE(ErrorOf("{[a]: 1}"), "");
}

TEST(LaunchFile, MissingFileIsNamed) {
  try {
    LoadLaunchFile("/no/such/launch.yaml", kEnv);
    FAIL();
  } catch (const LaunchFileError& e) {
    EXPECT_NE(std::string(e.what()).find("/no/such/launch.yaml"), std::string::npos);
  }
}

// Includes: the included groups come first, in order, and nest; paths are relative to the
// including file; names stay unique across files; a cycle, a missing file and too deep a nesting
// are refused with the file and line of the include.
TEST(LaunchFile, IncludesReadTheirGroupsFirst) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "launch_include";
  std::filesystem::create_directories(dir / "sub");
  auto write = [&](const std::string& name, const std::string& text) { std::ofstream(dir / name) << text; };
  write("sub/base.yaml",
        "name: base\ngroups:\n  - name: robot\n    processes:\n      - {name: sim, command: s}\n");
  write("sub/more.yaml",
        "include: [base.yaml]\ngroups:\n  - name: health\n    processes:\n      - {name: mon, command: m}\n");
  write("top.yaml",
        "name: top\ninclude: [sub/more.yaml]\ngroups:\n  - name: run\n    processes:\n"
        "      - {name: conductor, command: c, args: [\"${LOGS}\"]}\n");
  const LaunchSpec spec = LoadLaunchFile((dir / "top.yaml").string(), kEnv);
  EXPECT_EQ(spec.name, "top");
  ASSERT_EQ(spec.groups.size(), 3u);
  EXPECT_EQ(spec.groups[0].name, "robot");
  EXPECT_EQ(spec.groups[1].name, "health");
  EXPECT_EQ(spec.groups[2].name, "run");
  EXPECT_EQ(spec.groups[2].processes[0].args[0], "/tmp/logs");
  write("only.yaml", "include: [sub/base.yaml]\n");  // groups may come only from includes
  EXPECT_EQ(LoadLaunchFile((dir / "only.yaml").string(), kEnv).groups.size(), 1u);

  auto error = [&](const std::string& name) -> std::string {
    try {
      LoadLaunchFile((dir / name).string(), kEnv);
    } catch (const LaunchFileError& e) {
      return e.what();
    }
    return "(accepted)";
  };
  write(
      "twice.yaml",
      "include: [sub/base.yaml]\ngroups:\n  - name: robot\n    processes:\n      - {name: x, command: x}\n");
  EXPECT_NE(
      error("twice.yaml").find("twice.yaml:3: groups[0].name: expected a name not used by another group"),
      std::string::npos)
      << error("twice.yaml");
  write("same_process.yaml",
        "include: [sub/base.yaml]\ngroups:\n  - name: g\n    processes:\n      - {name: sim, command: x}\n");
  EXPECT_NE(error("same_process.yaml").find("used twice"), std::string::npos) << error("same_process.yaml");
  write("a.yaml", "include: [b.yaml]\n");
  write("b.yaml", "include: [a.yaml]\n");
  EXPECT_NE(error("a.yaml").find("b.yaml:1: include[0]: expected a file not being read already"),
            std::string::npos)
      << error("a.yaml");
  write("missing.yaml", "include: [nowhere.yaml]\n");
  EXPECT_NE(error("missing.yaml").find("nowhere.yaml: cannot read the launch file (included by"),
            std::string::npos)
      << error("missing.yaml");
  write("unset.yaml", "include: [\"${NOPE}.yaml\"]\n");
  EXPECT_NE(error("unset.yaml").find("${NOPE}"), std::string::npos) << error("unset.yaml");
  // A chain of 10 files, each including the next: deeper than 8.
  for (int i = 0; i < 10; ++i) {
    write("deep" + std::to_string(i) + ".yaml", "include: [deep" + std::to_string(i + 1) + ".yaml]\n");
  }
  write("deep10.yaml", "groups:\n  - name: g\n    processes:\n      - {name: x, command: x}\n");
  EXPECT_NE(error("deep0.yaml").find("nested includes"), std::string::npos) << error("deep0.yaml");
}

// Arguments: declared in any file of the chain (here after their use, in an included file),
// given or defaulted, $(arg NAME) expanded and {if: NAME, args: [...]} kept only when NAME is set.
TEST(LaunchFile, ArgumentsAreDeclaredGivenDefaultedAndConditional) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "launch_arguments";
  std::filesystem::create_directories(dir);
  auto write = [&](const std::string& name, const std::string& text) { std::ofstream(dir / name) << text; };
  write("base.yaml",
        "arguments:\n"
        "  seed: {default: '', help: the person}\n"
        "  rate: {default: '1'}\n"
        "groups:\n  - name: robot\n    processes:\n"
        "      - {name: sim, command: s, args: [--rate, '$(arg rate)', {if: seed, args: [--seed, '$(arg "
        "seed)']}]}\n");
  write("top.yaml",
        "include: [base.yaml]\n"
        "arguments:\n  trials: {default: '10'}\n"
        "groups:\n  - name: run\n    processes:\n"
        "      - {name: c, command: c, args: ['${LOGS}/$(arg trials)', {if: seed, args: [--s, x$(arg "
        "seed)y]}]}\n");
  const std::string top = (dir / "top.yaml").string();
  LaunchSpec spec = LoadLaunchFile(top, kEnv);
  EXPECT_EQ(spec.groups[0].processes[0].args, (std::vector<std::string>{"--rate", "1"}));
  EXPECT_EQ(spec.groups[1].processes[0].args, (std::vector<std::string>{"/tmp/logs/10"}));
  ASSERT_EQ(spec.arguments.size(), 3u);
  EXPECT_EQ(spec.arguments[0].name, "seed");  // the included file's first
  EXPECT_EQ(spec.arguments[0].help, "the person");
  EXPECT_FALSE(spec.arguments[0].given);
  EXPECT_EQ(spec.arguments[2].name, "trials");

  spec = LoadLaunchFile(top, kEnv, {{"seed", "7"}, {"trials", "3"}});
  EXPECT_EQ(spec.groups[0].processes[0].args, (std::vector<std::string>{"--rate", "1", "--seed", "7"}));
  EXPECT_EQ(spec.groups[1].processes[0].args, (std::vector<std::string>{"/tmp/logs/3", "--s", "x7y"}));
  EXPECT_TRUE(spec.arguments[0].given);
  EXPECT_EQ(spec.arguments[0].value, "7");
  EXPECT_EQ(spec.arguments[1].value, "1");

  auto error = [&](const std::map<std::string, std::string>& given) -> std::string {
    try {
      LoadLaunchFile(top, kEnv, given);
    } catch (const LaunchFileError& e) {
      return e.what();
    }
    return "(accepted)";
  };
  EXPECT_EQ(error({{"sed", "1"}}),
            top + ": --arg sed: the launch declares no argument 'sed' (it has: seed, rate, trials)");
  write("undeclared.yaml",
        "groups:\n  - name: g\n    processes:\n      - {name: a, command: a, args: ['$(arg nope)']}\n");
  const std::string undeclared = ErrorOfFile((dir / "undeclared.yaml").string());
  EXPECT_NE(
      undeclared.find("undeclared.yaml:4: groups[0].processes[0].args[0]: argument 'nope' is not declared"),
      std::string::npos)
      << undeclared;
  write("twice.yaml", "include: [base.yaml]\narguments:\n  seed: {default: '2'}\n");
  EXPECT_NE(ErrorOfFile((dir / "twice.yaml").string())
                .find("twice.yaml:3: arguments.seed: expected an argument declared once"),
            std::string::npos)
      << ErrorOfFile((dir / "twice.yaml").string());
  write("bad_if.yaml",
        "groups:\n  - name: g\n    processes:\n      - {name: a, command: a, args: [{if: x, args: [-v]}]}\n");
  EXPECT_NE(
      ErrorOfFile((dir / "bad_if.yaml").string()).find("args[0].if: expected a declared argument, got 'x'"),
      std::string::npos);
  write("bad_key.yaml",
        "arguments:\n  a: {default: '', typo: 1}\ngroups:\n  - name: g\n    processes:\n"
        "      - {name: a, command: a}\n");
  EXPECT_NE(ErrorOfFile((dir / "bad_key.yaml").string()).find("bad_key.yaml:2: arguments.a"),
            std::string::npos)
      << ErrorOfFile((dir / "bad_key.yaml").string());
}

// A study's user's run folder is named after the study too, so that deputies, which make it under
// their own logs folder, never give two studies' users one folder.
TEST(Launcher, RunFolderNamesAreAsUniqueOnADeputyAsHere) {
  const std::filesystem::path logs = std::filesystem::path(::testing::TempDir()) / "run_folder_names";
  std::filesystem::create_directories(logs / "study-A" / "setup-u1");
  std::filesystem::create_directories(logs / "20261204T000000Z-abc");
  std::ofstream(logs / "study-A" / "provenance.json") << "{}";
  EXPECT_EQ(RunFolderName((logs / "20261204T000000Z-abc").string()), "20261204T000000Z-abc");
  EXPECT_EQ(RunFolderName((logs / "20261204T000000Z-abc").string() + "/"), "20261204T000000Z-abc");
  EXPECT_EQ(RunFolderName((logs / "study-A" / "setup-u1").string()), "study-A.setup-u1");
  EXPECT_EQ(RunFolderName((logs / "study-A").string()), "study-A");
  EXPECT_EQ(RunFolderName(""), "");
}

TEST(LaunchFile, ArgumentAssignments) {
  EXPECT_EQ(ParseArgumentAssignment("user_seed=3"), (std::pair<std::string, std::string>{"user_seed", "3"}));
  EXPECT_EQ(ParseArgumentAssignment("a=b=c"), (std::pair<std::string, std::string>{"a", "b=c"}));
  EXPECT_EQ(ParseArgumentAssignment("empty="), (std::pair<std::string, std::string>{"empty", ""}));
  EXPECT_THROW(ParseArgumentAssignment("novalue"), std::invalid_argument);
  EXPECT_THROW(ParseArgumentAssignment("=3"), std::invalid_argument);
  EXPECT_THROW(ParseArgumentAssignment("a-b=3"), std::invalid_argument);
  EXPECT_EQ(ExpandArguments("x$(arg a)y$(arg b)", {{"a", "1"}, {"b", ""}}), "x1y");
  EXPECT_THROW(ExpandArguments("$(arg a", {{"a", "1"}}), std::invalid_argument);
  EXPECT_THROW(ExpandArguments("$(arg c)", {{"a", "1"}}), std::invalid_argument);
}

TEST(LaunchFile, ExpandVariables) {
  EXPECT_EQ(ExpandVariables("a${LOGS}b${BIN}", kEnv), "a/tmp/logsb/opt/b");
  EXPECT_EQ(ExpandVariables("plain $LOGS", kEnv), "plain $LOGS");
  EXPECT_THROW(ExpandVariables("${LOGS", kEnv), std::invalid_argument);
}

bool WaitForExit(Child* child, double seconds) {
  for (int i = 0; i < seconds * 100; ++i) {
    if (child->Poll()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return child->Poll();
}

TEST(Child, ReportsExitCodeAndEnvironment) {
  Child child;
  std::string error;
  ASSERT_TRUE(
      child.Start({"sh", "-c", "test \"$ORBED_X\" = 42 && exit 3; exit 9"}, {{"ORBED_X", "42"}}, "", &error))
      << error;
  ASSERT_TRUE(WaitForExit(&child, 5));
  EXPECT_EQ(child.exit_code(), 3);
  EXPECT_EQ(child.DescribeExit(), "exited with code 3");
}

TEST(Child, SignalReachesTheProcessGroup) {
  Child child;
  std::string error;
  // The shell's child (sleep) is in the same group and must die too, or the pipe stays open.
  ASSERT_TRUE(child.Start({"sh", "-c", "sleep 30 & wait"}, {}, "", &error)) << error;
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_TRUE(child.running());
  child.Signal(SIGTERM);
  ASSERT_TRUE(WaitForExit(&child, 5));
  EXPECT_EQ(child.term_signal(), SIGTERM);
}

TEST(Child, MissingExecutableFailsBeforeFork) {
  Child child;
  std::string error;
  EXPECT_FALSE(child.Start({"orbed-no-such-program"}, {}, "/nonexistent", &error));
  EXPECT_NE(error.find("cannot find executable 'orbed-no-such-program'"), std::string::npos);
  EXPECT_NE(ResolveExecutable("sh", ""), "");
}

// The command line, in-process (--dry-run: nothing is started).

// `text` in a fresh file under the temporary folder; its path.
std::string WriteTempFile(const std::string& name, const std::string& text) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("orbed_launcher_test_" + std::to_string(::getpid()) + name);
  std::ofstream(path) << text;
  return path.string();
}

TEST(LauncherCli, HelpGoesToOutAndExitsZero) {
  const test::CommandRun r = test::RunCommand(RunLauncher, "orbed-launch", {"--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("--dry-run"), std::string::npos) << r.out;
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST(LauncherCli, RefusesAnUnknownFlagAMissingFileAndABadFile) {
  test::CommandRun r = test::RunCommand(RunLauncher, "orbed-launch", {"--no-such-flag"});
  EXPECT_NE(r.code, 0);
  EXPECT_FALSE(r.err.empty());
  r = test::RunCommand(RunLauncher, "orbed-launch", {"--dry-run", "/no/such/launch.yaml"});
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("launch_file"), std::string::npos) << r.err;
  const std::string bad = WriteTempFile("_bad.yaml", "groups: []\n");
  r = test::RunCommand(RunLauncher, "orbed-launch", {"--dry-run", bad});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(bad + ":1: groups: expected a non-empty list"), std::string::npos) << r.err;
  std::filesystem::remove(bad);
}

TEST(LauncherCli, DryRunPrintsThePlan) {
  const std::string good = WriteTempFile(
      "_good.yaml",
      "groups:\n  - name: g\n    processes:\n      - {name: a, command: x, args: [-v], respawn: true}\n");
  const test::CommandRun r = test::RunCommand(RunLauncher, "orbed-launch", {"--dry-run", good});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, "group g:\n  a: x -v  [respawn]  [required]\n");
  std::filesystem::remove(good);
}

TEST(LauncherCli, ShowArgsListsTheArgumentsAndRefusesAnUndeclaredOne) {
  const std::string file = WriteTempFile(
      "_args.yaml",
      "arguments:\n  seed: {default: '1', help: the person}\n"
      "groups:\n  - name: g\n    processes:\n      - {name: a, command: x, args: ['$(arg seed)']}\n");
  test::CommandRun r =
      test::RunCommand(RunLauncher, "orbed-launch", {file, "--show-args", "--json", "--arg", "seed=4"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out,
            "{\n  \"seed\": {\n    \"value\": \"4\",\n    \"default\": \"1\",\n    \"given\": true,\n"
            "    \"help\": \"the person\"\n  }\n}\n");
  r = test::RunCommand(RunLauncher, "orbed-launch", {file, "--dry-run", "--arg", "seed=9"});
  EXPECT_EQ(r.out, "group g:\n  a: x 9  [required]\n");
  r = test::RunCommand(RunLauncher, "orbed-launch", {file, "--dry-run", "--arg", "sead=9"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--arg sead: the launch declares no argument 'sead' (it has: seed)"),
            std::string::npos)
      << r.err;
  r = test::RunCommand(RunLauncher, "orbed-launch",
                       {file, "--dry-run", "--arg", "seed=1", "--arg", "seed=2"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--arg seed given twice"), std::string::npos) << r.err;
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace orbed::launcher
