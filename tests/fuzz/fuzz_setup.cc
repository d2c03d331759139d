// libFuzzer: orbed-setup's handlers (ROBOT_STATE, COLLISION_STATUS, PLAN_CHECK_REPLY, ALIGNMENT_TRIAL,
// REGISTRATION, MISALIGNMENT, SETUP_RESULT) into its conductor, started once with the shipped plan and
// protocol.
#include <filesystem>

#include "base/source_paths.h"
#include "experiments/viraal/protocol.h"
#include "procs/setup/setup_process.h"
#include "sim/guidance_messages.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static auto* setup = [] {
    orbed::setup::SetupOptions options;
    options.modes = {0, 1, 2};
    options.start_deg = {0, 20, 0, -60, 0, 40, 0};
    options.targets_deg = {{0, 30, 0, -60, 0, 45, 0}};
    options.alignment =
        orbed::viraal::LoadScenarioFile(orbed::SourceTreePath(orbed::viraal::kDefaultScenarioRelativePath));
    const std::string dir = (std::filesystem::temp_directory_path() / "fuzz_setup").string();
    auto* process = new orbed::setup::SetupProcess(
        orbed::fuzz::FuzzFlags("orbed-setup"), options,
        orbed::SourceTreePath(orbed::sim::RobotModel::kDefaultUrdfRelativePath), dir, nullptr);
    process->Start();
    return process;
  }();
  orbed::fuzz::FeedToProcess(setup->process(), data, size);
  return 0;
}
