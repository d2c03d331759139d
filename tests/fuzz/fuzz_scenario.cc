// libFuzzer: orbed-scenario's handlers (ROBOT_STATE, PLAN_CHECK_REPLY, ALIGNMENT_TRIAL,
// REGISTRATION, MISALIGNMENT, ...) on a conductor that has started its run.
#include "experiments/viraal/protocol.h"
#include "procs/scenario/scenario_process.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static auto* scenario = [] {
    orbed::scenario::ScenarioOptions options;
    options.conductor.config = orbed::viraal::LoadScenarioFile(
        orbed::scenario::ScenarioSourcePath(orbed::viraal::kDefaultScenarioRelativePath));
    options.conductor.run_id = "fuzz";
    options.results_dir = "/tmp";
    return new orbed::scenario::ViraalScenario(orbed::fuzz::FuzzFlags("orbed-scenario"), options);
  }();
  orbed::fuzz::FeedToProcess(scenario->process(), data, size);
  return 0;
}
