#pragma once
/// @file
/// manifest.json, the description orbed-logger writes beside its recording, and the one reader of it
/// (for the logger continuing a recording, tools and fuzzing).
///
/// A recording is one or more parts: orbed-logger writes part 1, and every logger started on an
/// unfinished recording (manifest "complete": false, i.e. its logger died) continues it in the next
/// part, <stem>.part<N>.lcmlog beside the first (events received while no logger ran are not in
/// any part). Part files are named relative to the log's folder.
///
/// The document (units: utime [µs since the epoch], bytes):
///   "log_file"        the first part's file name (the recording's name)
///   "complete"        true once a logger stopped cleanly (then no part is written to)
///   "start_utime", "start_time_utc"   when the recording started (part 1)
///   "stop_utime", "stop_time_utc"     when it stopped (complete only)
///   "command_line", "versions" {"orbed", "lcm"}, "lcm_url", "channels_regex"   of the last logger
///   "files": [{"path", "sha256"} or {"path", "error"}]   the --hash-file files
///   "parts": [{"file", "start_utime", "stop_utime" (when it ended: a clean stop, or the last
///              event of a part whose logger died), "complete" (its logger stopped cleanly),
///              "events", "bytes" (whole events: header + channel + data), "drops" (queue
///              overflows counted by its logger, as last written), "damaged_bytes" (bytes that are
///              not a whole event: a torn tail after a crash), "channels" {name: {"events",
///              "bytes" (payload), "first_utime", "last_utime"}}, and "error" (optional: why its
///              logger could not go on writing, e.g. "cannot write …: No space left on device
///              (ENOSPC) after 262144 bytes, 251 events"; its counts are then those of the file)}]
///   "events_written", "bytes_written", "drops", "channels"   the sums over the parts
///
/// Reading (ParseManifest) checks the document like any input from outside: at most
/// kMaxManifestBytes of JSON nested at most 8 deep (base/json_fields.h), every field present with
/// its type and range, at most kMaxParts parts and kMaxChannels channels, part files plain names
/// (no '/', not "." or ".."), event counts and times consistent, and the sums equal to the parts'.
/// A failure throws JsonReadError naming the key.
///
/// Threading: plain data and pure functions (WriteManifestFile writes a file).

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "base/json_fields.h"

namespace orbed::logger {

constexpr size_t kMaxManifestBytes = 4 << 20;
constexpr size_t kMaxParts = 1000;
constexpr size_t kMaxChannels = 1000;

/// Events of one channel.
struct ChannelStats {
  int64_t events = 0;
  int64_t bytes = 0;  ///< payload bytes
  int64_t first_utime = 0;
  int64_t last_utime = 0;
};
/// Adds `more` (events of the same channel, later or earlier) to `*into`.
void Accumulate(const ChannelStats& more, ChannelStats* into);

struct ManifestPart {
  std::string file;
  int64_t start_utime = 0;
  std::optional<int64_t> stop_utime;
  bool complete = false;
  int64_t events = 0;
  int64_t bytes = 0;
  int64_t drops = 0;
  int64_t damaged_bytes = 0;
  std::map<std::string, ChannelStats> channels;
  std::string error;  ///< "" unless its logger stopped on a write error
};

struct HashedFile {
  std::string path;
  std::string sha256;  ///< "" when it could not be read
  std::string error;
};

struct Manifest {
  bool complete = false;
  int64_t start_utime = 0;
  std::optional<int64_t> stop_utime;
  std::string command_line;
  std::string orbed_version;
  std::string lcm_version;
  std::string lcm_url;
  std::string channels_regex;
  std::vector<HashedFile> files;
  std::vector<ManifestPart> parts;  ///< at least one

  /// Sums over the parts.
  int64_t events() const;
  int64_t bytes() const;
  int64_t drops() const;
  std::map<std::string, ChannelStats> channels() const;
};

/// The document's text (pretty-printed, 2 spaces).
std::string ManifestJson(const Manifest& manifest);
/// Checks and reads a document; `source` names it in errors. Throws JsonReadError.
Manifest ParseManifest(const std::string& text, const std::string& source);
/// Reads and checks the file at `path` (at most kMaxManifestBytes). Throws JsonReadError.
Manifest ReadManifestFile(const std::string& path);
/// Writes `manifest` to `path` through a temporary file and a rename (a reader never sees half a
/// manifest). Returns false and sets *error on failure.
bool WriteManifestFile(const std::string& path, const Manifest& manifest, std::string* error);

/// The name of part `number` (1-based) of a recording whose first part is `first_file`:
/// "orbed-X.lcmlog" → "orbed-X.part2.lcmlog" (the extension kept, whatever it is).
std::string PartFileName(const std::string& first_file, int number);

}  // namespace orbed::logger
