// libFuzzer: orbed-iiwa-sim's message handlers (IIWA_COMMAND, PLAN_CHECK_REQUEST, ...) in-process.
#include "sim/iiwa_sim.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static orbed::sim::IiwaSim* sim = [] {
    orbed::sim::IiwaSimOptions options;
    options.stale_command_s = 0;  // accept any utime, so inputs reach the motion law
    return new orbed::sim::IiwaSim(orbed::fuzz::FuzzFlags("orbed-iiwa-sim"), options);
  }();
  orbed::fuzz::FeedToProcess(sim->process(), data, size);
  return 0;
}
