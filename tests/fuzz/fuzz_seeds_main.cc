// orbed-fuzz-seeds LOG DIR [PER_CHANNEL]: turns a real run's event log into the fuzz targets' seed
// corpora (tests/fuzz/corpus is made this way). Messages over kMaxSeedBytes (camera images) are
// left out: libFuzzer sizes its inputs from the seeds, and image bytes are opaque to every handler.
//   DIR/bus/       for the process targets: the channel's index in channels::kAllChannels, then the
//                  message (fuzz_util.h), PER_CHANNEL messages of each channel (default 3);
//   DIR/types/     for fuzz_decode: the type's index in ORBED_FOR_EACH_LCM_TYPE, then the message;
//   DIR/event_log/ for fuzz_event_log: the log's first 100 events under kMaxSeedBytes, as a small
//                  log of their own;
//   DIR/state/     for fuzz_state_files (state_records.h): the first START, the first trial of its
//                  session and the first IIWA_STATUS as a registration journal, a headset state
//                  file, a sim state file and a raw journal;
//   DIR/manifest/  for fuzz_manifest: the manifest.json beside LOG, if there is one, with the
//                  folders taken out of its paths (a corpus in the repository names no machine's
//                  folders).
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <orbed/alignment_trial_t.hpp>
#include <orbed/all_types.hpp>
#include <orbed/session_control_t.hpp>

#include "lcmtypes/bounded_decode.h"
#include "lcmtypes/contract/channels.h"
#include "procs/logger/event_log_reader.h"
#include "procs/logger/event_log_writer.h"
#include "procs/logger/manifest.h"
#include "tests/fuzz/state_records.h"

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

void WriteBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

using Bytes = std::vector<uint8_t>;

// The state-file seeds from the first START, the first trial of its session and an IIWA_STATUS.
void WriteStateSeeds(const fs::path& dir, const Bytes& start, const Bytes& trial, const Bytes& status) {
  namespace fz = orbed::fuzz;
  const std::string session =
      fz::StateRecord(0, start.data(), start.size()) + fz::StateRecord(1, trial.data(), trial.size());
  WriteBytes(dir / "registration", std::string(1, char{fz::kRegistrationJournal}) + session);
  WriteBytes(dir / "hmd", std::string(1, char{fz::kHmdStateFile}) + session);
  WriteBytes(dir / "sim",
             std::string(1, char{fz::kSimStateFile}) + fz::StateRecord(2, status.data(), status.size()));
  WriteBytes(dir / "raw", std::string(1, char{fz::kRawJournal}) +
                              orbed::EncodeJournalRecord("SESSION_CONTROL", start.data(), start.size()) +
                              orbed::EncodeJournalRecord("ALIGNMENT_TRIAL", trial.data(), trial.size()));
}

// `text` with every whitespace-separated word that names a path cut to its last component.
std::string WithoutFolders(const std::string& text) {
  std::string out;
  size_t at = 0;
  while (at < text.size()) {
    const size_t end = std::min(text.find(' ', at), text.size());
    const std::string word = text.substr(at, end - at);
    out += word.find('/') == std::string::npos ? word : fs::path(word).filename().string();
    if (end < text.size()) out += ' ';
    at = end + 1;
  }
  return out;
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
  for (const char* sub : {"bus", "types", "event_log", "state", "manifest"})
    fs::create_directories(dir / sub);
  Bytes start, trial, status;  // the state-file seeds' messages
  std::string start_session;
  std::map<std::string, int> taken;  // seeds written per channel
  orbed::logger::EventLogScanner scanner = log.Scanner();
  orbed::logger::LogEvent event;
  orbed::logger::EventLogWriter head((dir / "event_log" / "first_events.lcmlog").string());
  int head_events = 0;
  int events = 0;
  int seeds = 0;
  while (scanner.Next(&event)) {
    ++events;
    const Bytes bytes(event.data, event.data + event.size);
    if (event.channel == "SESSION_CONTROL" && start.empty()) {
      orbed::session_control_t control;
      if (orbed::DecodeBounded(event.data, event.size, &control).ok() &&
          control.command == orbed::session_control_t::START) {
        start = bytes;
        start_session = control.session_id;
      }
    } else if (event.channel == "ALIGNMENT_TRIAL" && trial.empty() && !start.empty()) {
      orbed::alignment_trial_t message;
      if (orbed::DecodeBounded(event.data, event.size, &message).ok() && message.session_id == start_session)
        trial = bytes;
    } else if (event.channel == "IIWA_STATUS" && status.empty()) {
      status = bytes;
    }
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
  if (!start.empty() && !trial.empty() && !status.empty()) {
    WriteStateSeeds(dir / "state", start, trial, status);
  } else {
    std::fprintf(stderr,
                 "orbed-fuzz-seeds: no START, trial of its session and IIWA_STATUS: no state/ seeds\n");
  }
  const fs::path manifest_path = fs::path(argv[1]).parent_path() / "manifest.json";
  if (fs::exists(manifest_path)) {
    try {
      orbed::logger::Manifest manifest = orbed::logger::ReadManifestFile(manifest_path.string());
      manifest.command_line = WithoutFolders(manifest.command_line);
      for (orbed::logger::HashedFile& file : manifest.files)
        file.path = fs::path(file.path).filename().string();
      WriteBytes(dir / "manifest" / "manifest.json", orbed::logger::ManifestJson(manifest));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "orbed-fuzz-seeds: no manifest/ seed: %s\n", e.what());
    }
  }
  std::printf("orbed-fuzz-seeds: %d seeds from %d events of %zu channels; %d events in event_log/\n", seeds,
              events, taken.size(), head_events);
  return 0;
}
