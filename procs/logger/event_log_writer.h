#pragma once
/// @file
/// Writes the standard LCM event-log format (what lcm-logger writes and lcm-logplayer, lcm-spy
/// and LCM's LogFile API read) through LCM's own C writer (lcm/eventlog.h), adding errors that name
/// the file and errno, byte counts and a chosen buffer size. Per event, big-endian:
///   uint32 sync 0xEDA1DA01 | int64 event number | int64 timestamp [us] |
///   int32 channel length | int32 data length | channel bytes | data bytes
/// Buffered; Flush() pushes the buffer to the kernel, so after a SIGKILL the file holds every
/// event up to the last flush, and at most one partial event after it (which readers skip).
///
/// Errors: every fwrite, fflush and fclose is checked. The first failure (e.g. ENOSPC, a full disk)
/// is final: what is still buffered is discarded and nothing more is written, so the file stays
/// exactly as the failure left it (whole events, then possibly part of one) and its size on disk
/// is what was written. error() says "cannot write <path>: No space left on device (ENOSPC)".
///
/// Threading: not thread-safe; the logger calls it from its writer thread only.

#include <cstdint>
#include <cstdio>
#include <string>

struct _lcm_eventlog_t;

namespace orbed::logger {

class EventLogWriter {
 public:
  /// Opens `path` for writing (truncates). Check ok() / error().
  explicit EventLogWriter(const std::string& path, size_t buffer_bytes = 64 << 10);
  ~EventLogWriter();
  EventLogWriter(const EventLogWriter&) = delete;
  EventLogWriter& operator=(const EventLogWriter&) = delete;

  bool ok() const { return log_ != nullptr && error_.empty(); }
  const std::string& error() const { return error_; }
  /// errno of the first failure; 0 without one.
  int error_number() const { return error_number_; }

  /// Appends one event; the event number is assigned in order from 0. Returns bytes written
  /// (header + channel + data), or 0 after an error.
  size_t Write(int64_t timestamp_us, const std::string& channel, const uint8_t* data, size_t size);
  /// Pushes buffered bytes to the kernel (fflush). Returns false on an I/O error.
  bool Flush();
  /// Flushes and closes; further writes fail. Returns false after any error (error() says which).
  bool Close();

  /// Size of the event header in bytes.
  static constexpr size_t kHeaderBytes = 4 + 8 + 8 + 4 + 4;
  static constexpr uint32_t kSyncWord = 0xEDA1DA01;

 private:
  // Records the first failure and discards the buffer.
  void SetError(int error_number);

  _lcm_eventlog_t* log_ = nullptr;  // LCM's writer (it numbers the events from 0)
  std::string path_;
  std::string error_;
  int error_number_ = 0;
};

}  // namespace orbed::logger
