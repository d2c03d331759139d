// libFuzzer: the event-log reader (resync on the sync word) and DecodeBounded on what it finds.
// Every event returned lies inside the input; the damage ranges and events tile it in order.
#include <cstdlib>

#include <orbed/process_status_t.hpp>

#include "lcmtypes/bounded_decode.h"
#include "procs/logger/event_log_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  orbed::logger::EventLogScanner scanner(data, size);
  orbed::logger::LogEvent event;
  uint64_t covered = 0;
  while (scanner.Next(&event)) {
    if (event.data < data || event.data + event.size > data + size) std::abort();
    covered += 28 + event.channel.size() + event.size;
    orbed::process_status_t status;
    (void)orbed::DecodeBounded(event.data, event.size, &status);
  }
  if (covered + scanner.damaged_bytes() != size) std::abort();
  return 0;
}
