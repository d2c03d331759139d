#include "procs/launcher/launcher_cli.h"

#include <cstdlib>
#include <exception>
#include <filesystem>
#include <map>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "base/json.h"
#include "base/log.h"
#include "procs/launcher/deputy.h"
#include "procs/launcher/deputy_protocol.h"
#include "procs/launcher/launch_file.h"
#include "procs/launcher/launcher.h"
#include "runtime/flags.h"

namespace orbed::launcher {
namespace {

void PrintPlan(const LaunchSpec& spec, std::ostream& out) {
  for (const auto& group : spec.groups) {
    out << "group " << group.name << ":\n";
    for (const auto& p : group.processes) {
      out << "  " << p.name << (p.host.empty() ? "" : " @" + p.host) << ": " << p.command;
      for (const auto& a : p.args) out << " " << a;
      out << (p.respawn ? "  [respawn]" : "") << (p.required ? "  [required]" : "") << "\n";
    }
  }
}

// The launch's arguments: a table for people, or JSON for scripts (scripts/provenance.py records
// it as the run's effective settings).
void PrintArguments(const LaunchSpec& spec, bool json, std::ostream& out) {
  if (json) {
    JsonWriter w(2);
    w.BeginObject();
    for (const ArgumentSpec& a : spec.arguments) {
      w.Key(a.name).BeginObject();
      w.Key("value").String(a.value);
      w.Key("default").String(a.default_value);
      w.Key("given").Bool(a.given);
      w.Key("help").String(a.help);
      w.EndObject();
    }
    w.EndObject();
    out << w.str() << "\n";
    return;
  }
  if (spec.arguments.empty()) {
    out << spec.path << " declares no arguments\n";
    return;
  }
  out << "arguments of " << spec.path << " (give them as --arg NAME=VALUE):\n";
  for (const ArgumentSpec& a : spec.arguments) {
    out << "  " << a.name << " = \"" << a.value << "\"" << (a.given ? "" : " (default)") << "\n";
    if (!a.help.empty()) out << "      " << a.help << "\n";
  }
}

}  // namespace

int RunLauncher(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-launch: start the processes of a YAML launch file group by group (each group waits\n"
      "for its processes' first heartbeat), prefix their output with their names, restart them\n"
      "when asked, and stop everything in reverse order on SIGINT/SIGTERM or after --duration-s."};
  CommonFlags common("orbed-launch");
  AddCommonFlags(&app, &common);
  std::string launch_file;
  auto* file_option = app.add_option("launch_file", launch_file, "YAML launch file (see scripts/launch/)")
                          ->check(CLI::ExistingFile);
  bool dry_run = false;
  app.add_flag("--dry-run", dry_run, "Parse the file, print the plan and exit");
  std::vector<std::string> assignments;
  app.add_option("--arg", assignments,
                 "NAME=VALUE: the launch file's argument NAME (repeatable; --show-args lists them)");
  bool show_args = false, json = false;
  app.add_flag("--show-args", show_args,
               "Print the launch's arguments with their values and help, then exit");
  app.add_flag("--json", json, "With --show-args: as JSON {name: {value, default, given, help}}");
  std::string host = ThisHostName();
  app.add_option("--host", host,
                 "This host's name: processes with this `host:` (or none) start here, the others through "
                 "their host's deputy (default: $ORBED_HOST, else the hostname)")
      ->capture_default_str();
  DeputyOptions deputy;
  auto* deputy_option = app.add_option("--deputy", deputy.name,
                                       "Be the deputy NAME: run what launchers place on host NAME (no launch "
                                       "file)");
  deputy_option->excludes(file_option)->excludes("--dry-run")->excludes("--arg")->excludes("--show-args");
  app.add_option("--log-root", deputy.log_root,
                 "Deputy: this host's logs folder, where it makes each run's folder for the processes' "
                 "${ORBED_LOG_DIR}")
      ->needs(deputy_option)
      ->capture_default_str();
  app.add_option("--orphan-timeout-s", deputy.orphan_timeout_s,
                 "Deputy: stop what a launcher started when it has been silent this long")
      ->needs(deputy_option)
      ->check(orbed::PositiveNumber())
      ->capture_default_str();
  if (const auto code = ParseCommandLine(&app, common, argc, argv, out, err)) return *code;

  // Commands without '/' are looked up beside this executable first.
  std::error_code ec;
  const std::string bin_dir = std::filesystem::read_symlink("/proc/self/exe", ec).parent_path().string();
  if (!deputy.name.empty()) {
    deputy.bin_dir = bin_dir;
    // Its own heartbeat names its host as its children's do.
    setenv("ORBED_HOST", deputy.name.c_str(), 1);
    if (common.name == "orbed-launch") {
      common.name = "deputy-" + deputy.name;
      SetLogName(common.name);
    }
    try {
      Deputy running(common, deputy);
      return running.Run();
    } catch (const std::exception& e) {
      err << "orbed-launch: " << e.what() << "\n";
      return 1;
    }
  }
  if (launch_file.empty()) {
    err << "orbed-launch: a LAUNCH_FILE is required (or --deputy NAME)\n";
    return 106;  // CLI11's RequiredError code
  }
  auto environment = CurrentEnvironment();
  environment.emplace("ORBED_BIN_DIR", bin_dir);
  environment["ORBED_LAUNCH_FILE"] = std::filesystem::absolute(launch_file, ec).lexically_normal().string();
  std::map<std::string, std::string> arguments;
  for (const std::string& assignment : assignments) {
    try {
      const auto [name, value] = ParseArgumentAssignment(assignment);
      if (!arguments.emplace(name, value).second) {
        err << "orbed-launch: --arg " << name << " given twice\n";
        return 2;
      }
    } catch (const std::invalid_argument& e) {
      err << "orbed-launch: --arg: " << e.what() << "\n";
      return 2;
    }
  }
  // ${ORBED_LOG_DIR} is expanded where each process runs (launcher.h): left in the spec here.
  std::string log_dir;
  if (const auto it = environment.find("ORBED_LOG_DIR"); it != environment.end()) {
    log_dir = it->second;
    it->second = kLogDirVariable;
  }
  LaunchSpec spec;
  try {
    spec = LoadLaunchFile(launch_file, environment, arguments);
  } catch (const LaunchFileError& e) {
    err << "orbed-launch: " << e.what() << "\n";
    return 2;
  }
  if (show_args) {
    PrintArguments(spec, json, out);
    return 0;
  }
  if (dry_run) {
    PrintPlan(spec, out);
    return 0;
  }
  try {
    Launcher launcher(common, std::move(spec), bin_dir, host, log_dir);
    return launcher.Run();
  } catch (const std::exception& e) {
    err << "orbed-launch: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace orbed::launcher
