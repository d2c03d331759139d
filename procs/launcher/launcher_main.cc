/// @file
/// orbed-launch: starts, watches, restarts and stops the testbed from a YAML launch file.
/// Subscribes: PROCESS_STATUS (readiness). Publishes: PROCESS_STATUS (its own heartbeat).
#include <unistd.h>

#include <filesystem>
#include <iostream>

#include "procs/common/log.h"
#include "procs/launcher/launcher.h"

int main(int argc, char** argv) {
  CLI::App app{
      "orbed-launch: start the processes of a YAML launch file group by group (each group waits\n"
      "for its processes' first heartbeat), prefix their output with their names, restart them\n"
      "when asked, and stop everything in reverse order on SIGINT/SIGTERM or after --duration-sec."};
  orbed::CommonFlags common("orbed-launch");
  orbed::AddCommonFlags(&app, &common);
  std::string launch_file;
  app.add_option("launch_file", launch_file, "YAML launch file (see scripts/launch/)")
      ->required()
      ->check(CLI::ExistingFile);
  bool dry_run = false;
  app.add_flag("--dry-run", dry_run, "Parse the file, print the plan and exit");
  CLI11_PARSE(app, argc, argv);
  orbed::ApplyCommonFlags(common);

  // Commands without '/' are looked up beside this executable first.
  std::error_code ec;
  const std::string bin_dir = std::filesystem::read_symlink("/proc/self/exe", ec).parent_path().string();
  auto environment = orbed::launcher::CurrentEnvironment();
  environment.emplace("ORBED_BIN_DIR", bin_dir);
  orbed::launcher::LaunchSpec spec;
  try {
    spec = orbed::launcher::LoadLaunchFile(launch_file, environment);
  } catch (const orbed::launcher::LaunchFileError& e) {
    std::cerr << "orbed-launch: " << e.what() << "\n";
    return 2;
  }
  if (dry_run) {
    for (const auto& group : spec.groups) {
      std::cout << "group " << group.name << ":\n";
      for (const auto& p : group.processes) {
        std::cout << "  " << p.name << ": " << p.command;
        for (const auto& a : p.args) std::cout << " " << a;
        std::cout << (p.respawn ? "  [respawn]" : "") << (p.required ? "  [required]" : "") << "\n";
      }
    }
    return 0;
  }
  try {
    orbed::launcher::Launcher launcher(common, std::move(spec), bin_dir);
    return launcher.Run();
  } catch (const std::exception& e) {
    std::cerr << "orbed-launch: " << e.what() << "\n";
    return 1;
  }
}
