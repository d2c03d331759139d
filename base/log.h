#pragma once
/// @file
/// Minimal leveled logging to stderr, one line per call: "[name] LEVEL message" ("LEVEL message"
/// when ORBED_LOG_PREFIXED is set, as orbed-launch does since it prefixes lines itself). The launcher
/// prefixes each child's output again with its name, so lines stay attributable in a merged
/// stream. The message is written through EscapeText (base/format.h): bytes outside printable
/// ASCII, from the bus or a file, appear as \xNN and can never break the line or drive the
/// terminal. Thread-safe (one mutex around each write).

#include <sstream>
#include <string>

namespace orbed {

enum class LogLevel { kDebug = 0, kInfo = 1, kWarn = 2, kError = 3 };

/// Parses "debug" | "info" | "warn" | "error"; returns false for anything else.
bool ParseLogLevel(const std::string& text, LogLevel* level);

/// Process-wide settings; call once from main before threads start.
void SetLogName(const std::string& name);
void SetLogLevel(LogLevel level);
LogLevel GetLogLevel();

void Log(LogLevel level, const std::string& message);

namespace internal {
/// Collects a streamed message and writes it on destruction.
class LogLine {
 public:
  explicit LogLine(LogLevel level) : level_(level) {}
  ~LogLine() { Log(level_, stream_.str()); }
  template <typename T>
  LogLine& operator<<(const T& value) {
    stream_ << value;
    return *this;
  }

 private:
  LogLevel level_;
  std::ostringstream stream_;
};
}  // namespace internal

}  // namespace orbed

/// Usage: ORBED_LOG(kInfo) << "listening on " << url;  (the stream is not evaluated when filtered)
/// (A one-shot for loop rather than if/else, so that `if (x) ORBED_LOG(kInfo) << ...;` has no
/// dangling else.)
#define ORBED_LOG(level)                                                                         \
  for (bool orbed_log_once = ::orbed::LogLevel::level >= ::orbed::GetLogLevel(); orbed_log_once; \
       orbed_log_once = false)                                                                   \
  ::orbed::internal::LogLine(::orbed::LogLevel::level)
