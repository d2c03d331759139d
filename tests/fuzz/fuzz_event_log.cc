// libFuzzer: the event-log reader (resync on the sync word) and DecodeBounded on what it finds.
// Every event returned lies inside the input; the damage ranges and events tile it in order.
// Then orbed-log export --mcap's core on the same bytes (the shipped robot, no scene): every
// message it makes is JSON on a channel it announced before, whose schema it announced before.
#include <cstdlib>
#include <set>

#include <nlohmann/json.hpp>
#include <orbed/process_status_t.hpp>

#include "lcmtypes/bounded_decode.h"
#include "procs/logger/event_log_reader.h"
#include "procs/logger/mcap_export.h"

namespace {

class CheckingSink : public orbed::logger::RecordSink {
 public:
  bool Add(const orbed::logger::McapSchemaRecord& r) override {
    if (!nlohmann::json::accept(r.data)) std::abort();
    schemas_.insert(r.id);
    return true;
  }
  bool Add(const orbed::logger::McapChannelRecord& r) override {
    if (!schemas_.count(r.schema_id)) std::abort();
    channels_.insert(r.id);
    return true;
  }
  bool Add(const orbed::logger::McapMessageRecord& r) override {
    if (!channels_.count(r.channel_id) || !nlohmann::json::accept(r.data)) std::abort();
    return true;
  }
  bool Add(const orbed::logger::McapMetadataRecord&) override { return true; }

 private:
  std::set<uint16_t> schemas_, channels_;
};

}  // namespace

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

  static const orbed::sim::RobotModel model = orbed::sim::RobotModel::LoadFlag("");
  CheckingSink sink;
  const orbed::logger::McapExportOptions options;
  (void)orbed::logger::WriteMcapRecords(data, size, options, model, nullptr, &sink);
  return 0;
}
