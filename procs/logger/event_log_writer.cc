#include "procs/logger/event_log_writer.h"

#include <stdio_ext.h>

#include <cerrno>
#include <cstdlib>

#include <lcm/eventlog.h>

#include "base/format.h"

namespace orbed::logger {

EventLogWriter::EventLogWriter(const std::string& path, size_t buffer_bytes) : path_(path) {
  errno = 0;
  log_ = lcm_eventlog_create(path.c_str(), "w");
  if (log_ == nullptr) {
    error_number_ = errno;
    error_ = "cannot open " + path + " for writing: " + DescribeErrno(errno);
    return;
  }
  std::setvbuf(log_->f, nullptr, _IOFBF, buffer_bytes);
}

EventLogWriter::~EventLogWriter() { Close(); }

void EventLogWriter::SetError(int error_number) {
  error_number_ = error_number;
  error_ = "cannot write " + path_ + ": " + DescribeErrno(error_number);
  // What is still buffered never reaches the file: the file stays as the failure left it.
  __fpurge(log_->f);
}

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
  if (lcm_eventlog_write_event(log_, &event) != 0) {  // one of its fwrites was short
    SetError(errno);
    return 0;
  }
  return kHeaderBytes + channel.size() + size;
}

bool EventLogWriter::Flush() {
  if (!ok()) return false;
  if (std::fflush(log_->f) != 0) {
    SetError(errno);
    return false;
  }
  return true;
}

bool EventLogWriter::Close() {
  if (log_ == nullptr) return error_.empty();
  Flush();
  // lcm_eventlog_destroy is fflush, fclose and free(), none of them checked: the same here with
  // fclose's result looked at (a write the kernel deferred can fail there).
  if (std::fclose(log_->f) != 0 && error_.empty()) {
    error_number_ = errno;
    error_ = "cannot write " + path_ + ": " + DescribeErrno(errno);
  }
  std::free(log_);
  log_ = nullptr;
  return error_.empty();
}

}  // namespace orbed::logger
