// libFuzzer: orbed-monitor's handlers (PROCESS_STATUS, LOGGER_STATUS) and its table.
#include "lcmtypes/contract/conversions.h"
#include "procs/monitor/monitor.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static auto* monitor = [] {
    orbed::monitor::MonitorOptions options;
    options.out = nullptr;
    return new orbed::monitor::Monitor(orbed::fuzz::FuzzFlags("orbed-monitor"), options);
  }();
  orbed::fuzz::FeedToProcess(monitor->process(), data, size);
  (void)monitor->Table(orbed::NowMicros());
  return 0;
}
