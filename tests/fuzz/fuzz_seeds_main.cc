// orbed-fuzz-seeds LOG DIR [PER_CHANNEL]: turns a real run's event log into the fuzz targets' seed
// corpora (tests/fuzz/corpus is made this way). Messages over kMaxSeedBytes (camera images) are
// left out: libFuzzer sizes its inputs from the seeds, and image bytes are opaque to every handler.
//   DIR/bus/       for the process targets: the channel's index in channels::kAllChannels, then the
//                  message (fuzz_util.h), PER_CHANNEL messages of each channel (default 3);
//   DIR/types/     for fuzz_decode: the type's index in ORBED_FOR_EACH_LCM_TYPE, then the message;
//   DIR/event_log/ for fuzz_event_log: the log's first 100 events under kMaxSeedBytes, as a small
//                  log of their own.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include <orbed/all_types.hpp>

#include "lcmtypes/bounded_decode.h"
#include "procs/common/channels.h"
#include "procs/logger/event_log_reader.h"
#include "procs/logger/event_log_writer.h"

namespace {

namespace fs = std::filesystem;

constexpr size_t kMaxSeedBytes = 16384;

// Index of the type whose fingerprint the message carries, or -1.
int TypeIndex(const uint8_t* data, size_t size) {
  int index = 0;
  int found = -1;
#define ORBED_SEED_TYPE(type)                                            \
  if (orbed::CheckEncoding<orbed::type>(data, size).ok()) found = index; \
  ++index;
  ORBED_FOR_EACH_LCM_TYPE(ORBED_SEED_TYPE)
#undef ORBED_SEED_TYPE
  return found;
}

void WriteSeed(const fs::path& path, uint8_t first, const uint8_t* data, size_t size) {
  std::ofstream out(path, std::ios::binary);
  out.put(static_cast<char>(first));
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3 || std::strcmp(argv[1], "--help") == 0) {
    std::fprintf(stderr, "usage: orbed-fuzz-seeds LOG DIR [PER_CHANNEL]\n");
    return argc < 3 ? 2 : 0;
  }
  const int per_channel = argc > 3 ? std::atoi(argv[3]) : 3;
  orbed::logger::MappedLog log(argv[1]);
  if (!log.ok()) {
    std::fprintf(stderr, "orbed-fuzz-seeds: %s\n", log.error().c_str());
    return 1;
  }
  const fs::path dir(argv[2]);
  for (const char* sub : {"bus", "types", "event_log"}) fs::create_directories(dir / sub);
  std::map<std::string, int> taken;  // seeds written per channel
  orbed::logger::EventLogScanner scanner = log.Scanner();
  orbed::logger::LogEvent event;
  orbed::logger::EventLogWriter head((dir / "event_log" / "first_events.lcmlog").string());
  int head_events = 0;
  int events = 0;
  int seeds = 0;
  while (scanner.Next(&event)) {
    ++events;
    if (head_events < 100 && event.size <= kMaxSeedBytes) {
      head.Write(event.timestamp_us, event.channel, event.data, event.size);
      ++head_events;
    }
    if (taken[event.channel] >= per_channel || event.size > kMaxSeedBytes) continue;
    const auto& all = orbed::channels::kAllChannels;
    const auto found =
        std::find_if(std::begin(all), std::end(all), [&](const char* c) { return event.channel == c; });
    const int type_index = TypeIndex(event.data, event.size);
    if (found == std::end(all) || type_index < 0) continue;
    const int n = taken[event.channel]++;
    const std::string stem = event.channel + "_" + std::to_string(n);
    WriteSeed(dir / "bus" / stem, static_cast<uint8_t>(found - std::begin(all)), event.data, event.size);
    WriteSeed(dir / "types" / stem, static_cast<uint8_t>(type_index), event.data, event.size);
    ++seeds;
  }
  head.Close();
  std::printf("orbed-fuzz-seeds: %d seeds from %d events of %zu channels; %d events in event_log/\n", seeds,
              events, taken.size(), head_events);
  return 0;
}
