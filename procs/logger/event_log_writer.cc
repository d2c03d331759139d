#include "procs/logger/event_log_writer.h"

#include <cerrno>
#include <cstring>

#include <lcm/eventlog.h>

namespace orbed::logger {

EventLogWriter::EventLogWriter(const std::string& path, size_t buffer_bytes) : path_(path) {
  errno = 0;
  log_ = lcm_eventlog_create(path.c_str(), "w");
  if (log_ == nullptr) {
    error_ = "cannot open " + path + " for writing: " + std::strerror(errno);
    return;
  }
  std::setvbuf(log_->f, nullptr, _IOFBF, buffer_bytes);
}

EventLogWriter::~EventLogWriter() { Close(); }

size_t EventLogWriter::Write(int64_t timestamp_us, const std::string& channel, const uint8_t* data,
                             size_t size) {
  if (!ok()) return 0;
  static const uint8_t kNoData = 0;
  lcm_eventlog_event_t event{};
  event.timestamp = timestamp_us;
  event.channellen = static_cast<int32_t>(channel.size());
  event.datalen = static_cast<int32_t>(size);
  // LCM's struct is not const-correct; lcm_eventlog_write_event only reads the two buffers.
  event.channel = const_cast<char*>(channel.data());
  event.data = const_cast<uint8_t*>(size > 0 ? data : &kNoData);
  errno = 0;
  if (lcm_eventlog_write_event(log_, &event) != 0) {
    error_ = "write to " + path_ + " failed: " + std::strerror(errno);
    return 0;
  }
  return kHeaderBytes + channel.size() + size;
}

bool EventLogWriter::Flush() {
  if (log_ == nullptr) return false;
  if (std::fflush(log_->f) != 0) {
    error_ = "flush of " + path_ + " failed: " + std::strerror(errno);
    return false;
  }
  return true;
}

void EventLogWriter::Close() {
  if (log_ == nullptr) return;
  Flush();
  lcm_eventlog_destroy(log_);
  log_ = nullptr;
}

}  // namespace orbed::logger
