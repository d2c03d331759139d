#include "procs/logger/recording.h"

#include <lcm/lcm.h>

#include <algorithm>
#include <optional>
#include <stdexcept>

#include "base/format.h"
#include "base/sha256.h"
#include "procs/logger/event_log_reader.h"
#include "procs/logger/event_log_writer.h"

namespace orbed::logger {
namespace {

namespace fs = std::filesystem;

std::string NewLogPath(const LoggerOptions& options, int64_t start_utime) {
  if (!options.file.empty()) return options.file;
  const std::string stem = "orbed-" + FormatUtc(start_utime, "%Y%m%dT%H%M%SZ");
  fs::path path = fs::path(options.log_dir) / (stem + ".lcmlog");
  for (int i = 1; fs::exists(path); ++i) {
    path = fs::path(options.log_dir) / (stem + "-" + std::to_string(i) + ".lcmlog");
  }
  return path.string();
}

// The unfinished recording at `manifest_path` that this logger continues, if any.
std::optional<Manifest> RecordingToContinue(const std::string& manifest_path, const LoggerOptions& options) {
  std::error_code ec;
  if (!fs::exists(manifest_path, ec)) return std::nullopt;
  Manifest previous;
  try {
    previous = ReadManifestFile(manifest_path);
  } catch (const JsonReadError& e) {
    throw std::runtime_error(std::string("cannot continue the recording: ") + e.what() +
                             " (move the manifest away to start a new recording)");
  }
  if (previous.complete) return std::nullopt;
  if (!options.file.empty() && previous.parts.front().file != fs::path(options.file).filename().string()) {
    return std::nullopt;
  }
  return previous;
}

}  // namespace

fs::path LogFolder(const LoggerOptions& options) {
  return options.file.empty() ? fs::path(options.log_dir) : fs::path(options.file).parent_path();
}

std::string ManifestPath(const LoggerOptions& options) {
  if (!options.manifest.empty()) return options.manifest;
  return (LogFolder(options) / "manifest.json").string();
}

void RecountPart(const fs::path& path, ManifestPart* part) {
  const MappedLog log(path.string());
  if (!log.ok()) throw std::runtime_error(log.error());
  EventLogScanner scanner = log.Scanner();
  ManifestPart recounted;
  recounted.file = part->file;
  recounted.start_utime = part->start_utime;
  recounted.drops = part->drops;
  LogEvent event;
  while (scanner.Next(&event)) {
    ++recounted.events;
    recounted.bytes += static_cast<int64_t>(EventLogWriter::kHeaderBytes + event.channel.size() + event.size);
    ChannelStats one{1, static_cast<int64_t>(event.size), event.timestamp_us, event.timestamp_us};
    Accumulate(one, &recounted.channels[event.channel]);
    recounted.stop_utime = std::max(recounted.stop_utime.value_or(part->start_utime), event.timestamp_us);
  }
  recounted.damaged_bytes = static_cast<int64_t>(scanner.damaged_bytes());
  if (!recounted.stop_utime) recounted.stop_utime = part->start_utime;
  *part = recounted;
}

RecordingStart StartRecording(const LoggerOptions& options, const std::string& lcm_url, int64_t start_utime) {
  RecordingStart start;
  Manifest& manifest = start.manifest;
  const fs::path folder = LogFolder(options);
  if (std::optional<Manifest> previous = RecordingToContinue(ManifestPath(options), options)) {
    manifest = *previous;
    ManifestPart& last = manifest.parts.back();
    try {
      RecountPart(folder / last.file, &last);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(std::string("cannot continue the recording: ") + e.what());
    }
    int number = static_cast<int>(manifest.parts.size()) + 1;
    while (fs::exists(folder / PartFileName(manifest.parts.front().file, number))) ++number;
    start.log_path = (folder / PartFileName(manifest.parts.front().file, number)).string();
    start.continuing =
        "continuing the unfinished recording " + manifest.parts.front().file + " in part " +
        std::to_string(number) + ": its part " + last.file + " holds " + std::to_string(last.events) +
        " events" +
        (last.damaged_bytes > 0 ? " and " + std::to_string(last.damaged_bytes) + " damaged bytes" : "");
  } else {
    start.log_path = NewLogPath(options, start_utime);
    manifest.start_utime = start_utime;
  }
  ManifestPart part;
  part.file = fs::path(start.log_path).filename().string();
  part.start_utime = start_utime;
  manifest.parts.push_back(part);
  manifest.command_line = options.command_line;
  manifest.orbed_version = ORBED_VERSION;
  manifest.lcm_version = std::to_string(LCM_MAJOR_VERSION) + "." + std::to_string(LCM_MINOR_VERSION) + "." +
                         std::to_string(LCM_MICRO_VERSION);
  manifest.lcm_url = lcm_url;
  manifest.channels_regex = options.channels;
  manifest.files.clear();
  for (const std::string& path : options.hash_files) {
    std::string error;
    const std::string hash = Sha256FileHex(path, &error);
    manifest.files.push_back({path, hash, hash.empty() ? error : ""});
  }
  return start;
}

bool QueueFits(const LoggerOptions& options, int64_t events, int64_t bytes, int64_t size) {
  return events < options.queue_capacity_events && bytes + size <= options.queue_capacity_bytes;
}

void PartCounts::Written(const std::string& channel, int64_t utime, int64_t payload, int64_t written) {
  ++events_written;
  bytes_written += written;
  ChannelStats& stats = channels[channel];
  if (stats.events == 0) stats.first_utime = utime;
  ++stats.events;
  stats.bytes += payload;
  stats.last_utime = utime;
}

Manifest ManifestNow(const Manifest& recording, const PartCounts& counts, int64_t drops, bool complete,
                     int64_t stop_utime) {
  Manifest m = recording;
  ManifestPart& part = m.parts.back();
  part.drops = drops;
  part.events = counts.events_written;
  part.bytes = counts.bytes_written;
  part.channels = counts.channels;
  if (complete) {
    m.complete = part.complete = true;
    m.stop_utime = part.stop_utime = stop_utime;
  }
  return m;
}

Manifest FailedRecording(Manifest manifest, const std::string& error, bool in_log,
                         const std::string& log_path, int64_t handed_to_writer, std::string* line) {
  // What the file really holds, whatever was handed to the writer before the failure.
  ManifestPart& part = manifest.parts.back();
  try {
    RecountPart(log_path, &part);
    const int64_t size = part.bytes + part.damaged_bytes;  // the file's size: every byte is one or the other
    *line = error + (in_log ? " after " : "; the log " + log_path + " holds ") + std::to_string(size) +
            " bytes, " + std::to_string(part.events) + " events";
  } catch (const std::exception& e) {
    *line = error + "; the log cannot be read back: " + e.what();
  }
  part.drops += handed_to_writer - part.events;  // buffered when the write failed: not in the file
  part.error = *line;
  return manifest;
}

}  // namespace orbed::logger
