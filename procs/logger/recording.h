#pragma once
/// @file
/// orbed-logger's core (the process is logger.h, its LCM shell): what a recording is, without a bus
/// or threads. Which file a part goes to, whether an unfinished recording is continued, what the
/// manifest says, what is counted per channel, when a message is dropped, what a recording ended by
/// a write error says. It reads the files it decides on (the manifest, a dead logger's part, the
/// files to hash); it writes none.
///
///   A new recording: the log at --file, else <log_dir>/orbed-YYYYMMDDTHHMMSSZ.lcmlog by start time
///   (UTC), with -1, -2, ... when that exists; its manifest starts at the start time.
///   A continued one: a manifest that exists and says the recording is not complete (with --file:
///   only if its first part is that file) gets a new part <stem>.part<N>.lcmlog, N the first number
///   past the parts whose file is free; the last part is re-counted from its file (RecountPart).
///   The manifest's static fields: command line, versions, LCM URL, channel regex, the SHA-256 of the
///   --hash-file files (hashed once: they do not change while recording).
///
/// Units: utime [us since the epoch], sizes [bytes]. Threading: plain functions; PartCounts is not
/// synchronised (the shell guards it).

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "procs/logger/manifest.h"

namespace orbed::logger {

struct LoggerOptions {
  /// Folder for the log (created if missing); the file is named by start time (UTC):
  /// orbed-YYYYMMDDTHHMMSSZ.lcmlog.
  std::string log_dir = "logs";
  /// Explicit log path; overrides log_dir + start-time name when set.
  std::string file;
  /// Manifest path; empty = manifest.json in the log's folder.
  std::string manifest;
  /// Regular expression of the channels to record (LCM's full-match channel regex).
  std::string channels = ".*";
  /// Queue bounds: a message that does not fit is dropped and counted.
  int64_t queue_capacity_events = 100000;
  int64_t queue_capacity_bytes = 128ll << 20;
  /// Period of the writer's fflush [s].
  double flush_interval_s = 0.25;
  /// Files whose SHA-256 the manifest records (URDF, scene, launch file, ...).
  std::vector<std::string> hash_files;
  /// The command line, for the manifest.
  std::string command_line;
  /// Capacity of LCM's own per-subscription queue (LCM's default, 30, drops bursts).
  int lcm_queue_capacity = 10000;
  /// Channel of this logger's status messages.
  std::string status_channel = "LOGGER_STATUS";
};

/// The folder of the log's parts: --file's, else log_dir.
std::filesystem::path LogFolder(const LoggerOptions& options);
/// --manifest, else manifest.json in LogFolder.
std::string ManifestPath(const LoggerOptions& options);

/// What is really in a part whose logger died: its whole events, per channel, and the bytes that
/// are not a whole event (a torn tail); keeps the part's file, start and drops. Throws
/// std::runtime_error when the file cannot be read.
void RecountPart(const std::filesystem::path& path, ManifestPart* part);

/// Where a logger started at start_utime records, and the manifest it starts from.
struct RecordingStart {
  Manifest manifest;       ///< earlier parts (the last re-counted), then this part; static fields set
  std::string log_path;    ///< this part's file
  std::string continuing;  ///< "" for a new recording, else what the logger says about the old one
};
/// Decides the above (see the file comment); throws std::runtime_error when the manifest does not
/// read back or its last part cannot be re-counted.
RecordingStart StartRecording(const LoggerOptions& options, const std::string& lcm_url, int64_t start_utime);

/// Whether a message of `size` bytes fits a queue holding `events` and `bytes` (else it is dropped).
bool QueueFits(const LoggerOptions& options, int64_t events, int64_t bytes, int64_t size);
/// Whether the drop numbered `drops` is logged (the first and every 1000th).
inline bool LogDrop(int64_t drops) { return drops == 1 || drops % 1000 == 0; }

/// This part's counts: events and bytes written (with their headers), per channel (payload bytes,
/// first and last receive utime), events lost after a write error.
struct PartCounts {
  int64_t events_written = 0;
  int64_t bytes_written = 0;
  int64_t lost_events = 0;
  std::map<std::string, ChannelStats> channels;
  /// One event of `payload` bytes on `channel` received at `utime`, `written` bytes in the file.
  void Written(const std::string& channel, int64_t utime, int64_t payload, int64_t written);
};

/// The manifest now: `recording` with its last part (this one) counted and `drops`; when
/// `complete`, marked complete and stopped at stop_utime.
Manifest ManifestNow(const Manifest& recording, const PartCounts& counts, int64_t drops, bool complete,
                     int64_t stop_utime);

/// After a write error: the manifest with this part re-counted from `log_path` as it is (the events
/// handed to the writer but not in the file counted as drops) and the error in the part's "error";
/// *line is what the logger says (the file's size and whole events, or why it cannot be read).
Manifest FailedRecording(Manifest manifest, const std::string& error, bool in_log,
                         const std::string& log_path, int64_t handed_to_writer, std::string* line);

}  // namespace orbed::logger
