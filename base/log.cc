#include "base/log.h"

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <mutex>

#include "base/format.h"

namespace orbed {
namespace {
std::mutex g_mutex;
std::string g_name = "orbed";  // guarded by g_mutex
std::atomic<int> g_level{static_cast<int>(LogLevel::kInfo)};
const char* LevelName(LogLevel level) {
  switch (level) {
    case LogLevel::kDebug:
      return "DEBUG";
    case LogLevel::kInfo:
      return "INFO";
    case LogLevel::kWarn:
      return "WARN";
    case LogLevel::kError:
      return "ERROR";
  }
  return "?";
}
}  // namespace

bool ParseLogLevel(const std::string& text, LogLevel* level) {
  if (text == "debug")
    *level = LogLevel::kDebug;
  else if (text == "info")
    *level = LogLevel::kInfo;
  else if (text == "warn")
    *level = LogLevel::kWarn;
  else if (text == "error")
    *level = LogLevel::kError;
  else
    return false;
  return true;
}

void SetLogName(const std::string& name) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_name = name;
}
void SetLogLevel(LogLevel level) { g_level = static_cast<int>(level); }
LogLevel GetLogLevel() { return static_cast<LogLevel>(g_level.load()); }

void Log(LogLevel level, const std::string& message) {
  if (static_cast<int>(level) < g_level.load()) return;
  // Under orbed-launch every output line is already prefixed with the process name.
  static const bool prefixed = std::getenv("ORBED_LOG_PREFIXED") != nullptr;
  // Messages quote text from the bus and from files: one escaped line each, whatever the bytes.
  const std::string line = EscapeText(message);
  std::lock_guard<std::mutex> lock(g_mutex);
  if (prefixed) {
    std::fprintf(stderr, "%s %s\n", LevelName(level), line.c_str());
  } else {
    std::fprintf(stderr, "[%s] %s %s\n", g_name.c_str(), LevelName(level), line.c_str());
  }
  std::fflush(stderr);
}

}  // namespace orbed
