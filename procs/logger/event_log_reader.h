#pragma once
/// @file
/// Reads the LCM event-log format that EventLogWriter (and LCM's lcm-logger) writes, and survives
/// damage: a header that is not an event, or an event cut short, is skipped by searching for the
/// next sync word, and the skipped byte ranges are reported with their offsets. Nothing is
/// allocated from a length field before it is checked against the bytes that are there, so a log
/// of n bytes costs O(n) time and at most O(events) memory.
///
/// Per event, big-endian: uint32 sync 0xEDA1DA01 | int64 event number | int64 timestamp [us] |
/// int32 channel length | int32 data length | channel bytes | data bytes.
///
/// Threading: a scanner is not synchronised (one reader); MappedLog is immutable once open.

#include <cstddef>
#include <cstdint>
#include <regex>
#include <string>
#include <utility>
#include <vector>

namespace orbed::logger {

/// One event as stored. `data` points into the scanned bytes (valid while they are).
struct LogEvent {
  int64_t event_number = 0;
  int64_t timestamp_us = 0;
  std::string channel;
  const uint8_t* data = nullptr;
  size_t size = 0;
  uint64_t offset = 0;  ///< byte offset of the event's sync word
};

/// A byte range that held no readable event.
struct LogDamage {
  uint64_t offset = 0;
  uint64_t bytes = 0;
  std::string reason;  ///< what the first bad header looked like
};

/// LCM's channel names are at most 63 bytes; anything longer than this is not a header.
constexpr size_t kMaxLogChannelBytes = 256;

/// Walks an event log held in memory, event by event.
class EventLogScanner {
 public:
  EventLogScanner(const uint8_t* data, size_t size) : data_(data), size_(size) {}

  /// The next whole event (damage before it is skipped and recorded); false at the end.
  bool Next(LogEvent* event);
  /// The skipped ranges so far, in file order (adjacent damage merged into one range).
  const std::vector<LogDamage>& damage() const { return damage_; }
  uint64_t damaged_bytes() const;

 private:
  // Why the bytes at pos_ are not an event ("" if they are one).
  std::string CheckHeader(size_t pos) const;
  void RecordDamage(size_t from, size_t to, const std::string& reason);

  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
  std::vector<LogDamage> damage_;
};

/// Which events a tool takes (orbed-log cut and export): those from `from_s` to `to_s` seconds
/// after the log's first event (of any channel) whose channel matches `channels` whole. Give it
/// every event in log order.
class EventWindow {
 public:
  EventWindow(double from_s, double to_s, std::regex channels)
      : from_s_(from_s), to_s_(to_s), channels_(std::move(channels)) {}
  bool Take(const LogEvent& e) {
    if (!have_start_) {
      start_us_ = e.timestamp_us;
      have_start_ = true;
    }
    const double t_s = (e.timestamp_us - start_us_) * 1e-6;
    return t_s >= from_s_ && t_s <= to_s_ && std::regex_match(e.channel, channels_);
  }

 private:
  double from_s_, to_s_;
  std::regex channels_;
  bool have_start_{false};
  int64_t start_us_{0};
};

/// A log file mapped read-only (empty files are fine). Check ok() / error().
class MappedLog {
 public:
  explicit MappedLog(const std::string& path);
  ~MappedLog();
  MappedLog(const MappedLog&) = delete;
  MappedLog& operator=(const MappedLog&) = delete;

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  const uint8_t* data() const { return data_; }
  size_t size() const { return size_; }
  EventLogScanner Scanner() const { return EventLogScanner(data_, size_); }

 private:
  const uint8_t* data_ = nullptr;
  size_t size_ = 0;
  std::string error_;
};

}  // namespace orbed::logger
