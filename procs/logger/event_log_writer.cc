#include "procs/logger/event_log_writer.h"

#include <cerrno>
#include <cstring>

namespace orbed::logger {
namespace {

void PutBigEndian(uint8_t* out, uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out[i] = static_cast<uint8_t>(value >> (8 * (bytes - 1 - i)));
}

}  // namespace

EventLogWriter::EventLogWriter(const std::string& path, size_t buffer_bytes) : path_(path) {
  file_ = std::fopen(path.c_str(), "wb");
  if (file_ == nullptr) {
    error_ = "cannot open " + path + " for writing: " + std::strerror(errno);
    return;
  }
  std::setvbuf(file_, nullptr, _IOFBF, buffer_bytes);
}

EventLogWriter::~EventLogWriter() { Close(); }

size_t EventLogWriter::Write(int64_t timestamp_us, const std::string& channel, const uint8_t* data,
                             size_t size) {
  if (!ok()) return 0;
  uint8_t header[kHeaderBytes];
  PutBigEndian(header, kSyncWord, 4);
  PutBigEndian(header + 4, static_cast<uint64_t>(next_event_number_), 8);
  PutBigEndian(header + 12, static_cast<uint64_t>(timestamp_us), 8);
  PutBigEndian(header + 20, channel.size(), 4);
  PutBigEndian(header + 24, size, 4);
  if (std::fwrite(header, 1, kHeaderBytes, file_) != kHeaderBytes ||
      std::fwrite(channel.data(), 1, channel.size(), file_) != channel.size() ||
      (size > 0 && std::fwrite(data, 1, size, file_) != size)) {
    error_ = "write to " + path_ + " failed: " + std::strerror(errno);
    return 0;
  }
  ++next_event_number_;
  return kHeaderBytes + channel.size() + size;
}

bool EventLogWriter::Flush() {
  if (file_ == nullptr) return false;
  if (std::fflush(file_) != 0) {
    error_ = "flush of " + path_ + " failed: " + std::strerror(errno);
    return false;
  }
  return true;
}

void EventLogWriter::Close() {
  if (file_ == nullptr) return;
  Flush();
  std::fclose(file_);
  file_ = nullptr;
}

}  // namespace orbed::logger
