#include "procs/launcher/launcher_cli.h"

#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>

#include <CLI/CLI.hpp>

#include "procs/common/flags.h"
#include "procs/common/log.h"
#include "procs/launcher/deputy.h"
#include "procs/launcher/launch_file.h"
#include "procs/launcher/launcher.h"

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
  std::string host = ThisHostName();
  app.add_option("--host", host,
                 "This host's name: processes with this `host:` (or none) start here, the others through "
                 "their host's deputy (default: $ORBED_HOST, else the hostname)")
      ->capture_default_str();
  DeputyOptions deputy;
  auto* deputy_option = app.add_option("--deputy", deputy.name,
                                       "Be the deputy NAME: run what launchers place on host NAME (no launch "
                                       "file)");
  deputy_option->excludes(file_option)->excludes("--dry-run");
  app.add_option("--orphan-timeout-s", deputy.orphan_timeout_s,
                 "Deputy: stop what a launcher started when it has been silent this long")
      ->needs(deputy_option)
      ->check(CLI::PositiveNumber)
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
  LaunchSpec spec;
  try {
    spec = LoadLaunchFile(launch_file, environment);
  } catch (const LaunchFileError& e) {
    err << "orbed-launch: " << e.what() << "\n";
    return 2;
  }
  if (dry_run) {
    PrintPlan(spec, out);
    return 0;
  }
  try {
    Launcher launcher(common, std::move(spec), bin_dir, host);
    return launcher.Run();
  } catch (const std::exception& e) {
    err << "orbed-launch: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace orbed::launcher
