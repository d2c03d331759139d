// libFuzzer: orbed-logger's raw handler (every channel) and its writer. Each input's event is
// queued by the handler and written at once (Logger::WriteQueued) to /dev/null, so nothing stays
// allocated from one input to the next (libFuzzer would otherwise run a leak check after every
// input that keeps memory, which made this target run at about 13 inputs/s).
#include <cstdlib>
#include <string>

#include "procs/logger/logger.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static auto* logger = [] {
    char dir[] = "/tmp/orbed_fuzz_loggerXXXXXX";
    if (mkdtemp(dir) == nullptr) std::abort();
    orbed::logger::LoggerOptions options;
    options.file = "/dev/null";
    options.manifest = std::string(dir) + "/manifest.json";
    options.queue_capacity_events = 1000;
    options.queue_capacity_bytes = 1 << 20;
    return new orbed::logger::Logger(orbed::fuzz::FuzzFlags("orbed-logger"), options);
  }();
  orbed::fuzz::FeedToProcess(logger->process(), data, size);
  logger->WriteQueued();
  return 0;
}
