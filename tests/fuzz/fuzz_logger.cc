// libFuzzer: orbed-logger's raw handler (every channel) with a small queue: nothing it receives
// may cost more than the queue's bounds.
#include <cstdlib>
#include <string>

#include "procs/logger/logger.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static auto* logger = [] {
    char dir[] = "/tmp/orbed_fuzz_loggerXXXXXX";
    if (mkdtemp(dir) == nullptr) std::abort();
    orbed::logger::LoggerOptions options;
    options.file = std::string(dir) + "/fuzz.lcmlog";
    options.queue_capacity_events = 1000;
    options.queue_capacity_bytes = 1 << 20;
    return new orbed::logger::Logger(orbed::fuzz::FuzzFlags("orbed-logger"), options);
  }();
  orbed::fuzz::FeedToProcess(logger->process(), data, size);
  return 0;
}
