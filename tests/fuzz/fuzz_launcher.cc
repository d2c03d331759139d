// libFuzzer: orbed-launch's heartbeat handler (PROCESS_STATUS) and its deputies' reports
// (DEPUTY_STATUS), with the ViRAAl launch file's processes known (none started), the registration
// server and the headset placed on host "hostB" so that a report about them reaches their slots.
#include "base/source_paths.h"
#include "procs/launcher/launch_file.h"
#include "procs/launcher/launcher.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static auto* launcher = [] {
    std::map<std::string, std::string> environment = orbed::launcher::CurrentEnvironment();
    environment["ORBED_LOG_DIR"] = "/tmp";
    environment["ORBED_SOURCE_DIR"] = orbed::SourceDir();
    environment["ORBED_LAUNCH_FILE"] = orbed::SourceTreePath("scripts/launch/viraal.yaml");
    orbed::launcher::LaunchSpec spec =
        orbed::launcher::LoadLaunchFile(orbed::SourceTreePath("scripts/launch/viraal.yaml"), environment);
    for (auto& group : spec.groups) {
      for (auto& process : group.processes) {
        if (process.name == "registration" || process.name == "hmd") process.host = "hostB";
      }
    }
    return new orbed::launcher::Launcher(orbed::fuzz::FuzzFlags("orbed-launch"), spec, "/nonexistent",
                                         "hostA");
  }();
  orbed::fuzz::FeedToProcess(launcher->process(), data, size);
  return 0;
}
