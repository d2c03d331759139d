#pragma once
/// @file
/// orbed-logger's shell: records LCM traffic to a standard LCM event log. What a recording is (its
/// file, the continued recording, the manifest's content, the counts, the queue's bounds, a failed
/// recording's account) is the core, recording.h; here the subscription, the queue, the writer
/// thread, the timers and the writes.
///
/// LCM's internal LCM_SELF_TEST probe packets are not recorded.
///
/// Threads: the receive thread (Process::Run, LCM's handler) stamps each message with LCM's
/// receive time and appends it to a bounded in-memory queue, or counts a drop when the queue is
/// full (by events or bytes) — never a silent loss. The writer thread drains the queue into the
/// file and flushes every `flush_interval_s`, so after a SIGKILL the log is valid up to the last
/// flush. SIGINT/SIGTERM stop the receive loop, the writer drains what is queued, flushes, closes,
/// and the manifest is rewritten with complete = true.
///
/// Outputs: the log file, `manifest.json` beside it (manifest.h: start/stop time, command line,
/// versions, SHA-256 of the files given with --hash-file, the parts with their per-channel events
/// and bytes; rewritten at start, every 5 s and at the end), LOGGER_STATUS at 1 Hz (this part's
/// counts) and the PROCESS_STATUS heartbeat.
///
/// Write errors: a failed fwrite, fflush or fclose of the log (e.g. ENOSPC: a full disk) or a failed
/// write of the manifest stops the logger. Nothing is written to the log after the failure
/// (event_log_writer.h), the part is re-counted from its file as it is, and the logger says, as its
/// last line, e.g. "cannot write <log>: No space left on device (ENOSPC) after 262144 bytes, 251
/// events" (the file's size, its whole events; a torn last event is damaged bytes), puts the same
/// text in its manifest part's "error" when the manifest can still be written (the recording stays
/// unfinished), or says that it could not, and exits with kExitCannotWrite (74, process.h), which
/// orbed-launch does not respawn: a full disk is not a crash, and a new logger would fail the same
/// way.
///
/// Crash recovery: a logger whose manifest already exists and says the recording is not complete
/// (its logger died: SIGKILL, power) continues that recording in a new part, <stem>.part<N>.lcmlog
/// beside the first (with --file only if the recording's first part is that file; otherwise, and
/// after a complete recording, it starts a new recording and a new manifest). The earlier parts are
/// not touched: the part whose logger died is re-counted from its file (event_log_reader.h), so the
/// manifest lists what is really there, valid up to its last flush, a torn last event counted as
/// damaged bytes. A manifest that does not read back (manifest.h) or names a part file that is
/// missing is an error: the logger does not start.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <orbed/logger_status_t.hpp>

#include "procs/logger/event_log_writer.h"
#include "procs/logger/manifest.h"
#include "procs/logger/recording.h"
#include "runtime/process.h"

namespace orbed::logger {

class Logger {
 public:
  /// Opens the log (a new recording, or the next part of an unfinished one); throws
  /// std::runtime_error naming the path when it cannot, or when the recording to continue does not
  /// read back.
  Logger(const CommonFlags& flags, LoggerOptions options);
  ~Logger();

  /// Records until stopped; returns the exit code: 0, 1 (Process::Fail), or kExitCannotWrite.
  int Run();

  /// This logger's part.
  const std::string& log_path() const { return log_path_; }
  std::string manifest_path() const;
  /// The manifest as it would be written now.
  Manifest MakeManifest(bool complete) const;
  orbed::logger_status_t MakeStatus() const;
  /// This part's per-channel counts.
  std::map<std::string, ChannelStats> channel_stats() const;
  Process& process() { return process_; }
  /// Writes what is queued, on the caller's thread, as Run()'s writer thread does (for fuzzing:
  /// each input's event is written and freed before the next). Not while Run() is running.
  void WriteQueued();

 private:
  struct Event {
    int64_t utime;
    std::string channel;
    std::vector<uint8_t> data;
  };
  void OnMessage(const lcm::ReceiveBuffer& rbuf, const std::string& channel);
  void WriterLoop();
  // Writes `batch` to the file and counts it (the writer thread, or WriteQueued()).
  void WriteBatch(const std::deque<Event>& batch);
  // Writes the manifest; false with *error set when it cannot.
  bool WriteManifest(bool complete, std::string* error) const;
  // Keeps the first write error (`in_log`: of the log, else of the manifest) and stops the logger.
  void StopOnWriteError(const std::string& error, bool in_log);
  // After a write error: re-counts this part from its file, marks the manifest if it can, says
  // so and returns kExitCannotWrite.
  int EndFailedRecording();

  LoggerOptions options_;
  CommonFlags flags_;
  Process process_;
  std::string log_path_;
  Manifest manifest_;  // the recording: earlier parts as found, this part's static fields last
  int64_t start_utime_;
  int64_t stop_utime_ = 0;

  mutable std::mutex queue_mutex_;
  std::condition_variable queue_cv_;
  std::deque<Event> queue_;   // guarded by queue_mutex_
  int64_t queue_bytes_ = 0;   // guarded by queue_mutex_
  int64_t drops_ = 0;         // guarded by queue_mutex_
  bool writer_stop_ = false;  // guarded by queue_mutex_

  mutable std::mutex stats_mutex_;
  PartCounts counts_;              // guarded by stats_mutex_
  int64_t last_flush_utime_ = 0;   // guarded by stats_mutex_
  std::string write_error_;        // guarded by stats_mutex_
  bool log_write_failed_ = false;  // guarded by stats_mutex_ (else the manifest's)

  std::unique_ptr<EventLogWriter> file_;  // used by the writer thread only, after Run() starts
  std::thread writer_;
};

}  // namespace orbed::logger
