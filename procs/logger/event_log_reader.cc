#include "procs/logger/event_log_reader.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "procs/logger/event_log_writer.h"

namespace orbed::logger {
namespace {

uint64_t BigEndian(const uint8_t* p, int bytes) {
  uint64_t value = 0;
  for (int i = 0; i < bytes; ++i) value = (value << 8) | p[i];
  return value;
}

constexpr uint8_t kSyncBytes[4] = {0xED, 0xA1, 0xDA, 0x01};

}  // namespace

std::string EventLogScanner::CheckHeader(size_t pos) const {
  const size_t left = size_ - pos;
  if (left < EventLogWriter::kHeaderBytes) return "header cut short (" + std::to_string(left) + " bytes left)";
  const uint8_t* p = data_ + pos;
  if (BigEndian(p, 4) != EventLogWriter::kSyncWord) return "no sync word";
  const auto channel_bytes = static_cast<int32_t>(BigEndian(p + 20, 4));
  const auto data_bytes = static_cast<int32_t>(BigEndian(p + 24, 4));
  if (channel_bytes < 1 || static_cast<size_t>(channel_bytes) > kMaxLogChannelBytes) {
    return "channel length " + std::to_string(channel_bytes);
  }
  if (data_bytes < 0) return "data length " + std::to_string(data_bytes);
  const uint64_t body = static_cast<uint64_t>(channel_bytes) + static_cast<uint64_t>(data_bytes);
  if (body > left - EventLogWriter::kHeaderBytes) {
    return "event of " + std::to_string(body) + " bytes cut short (" + std::to_string(left) + " bytes left)";
  }
  return "";
}

void EventLogScanner::RecordDamage(size_t from, size_t to, const std::string& reason) {
  if (!damage_.empty() && damage_.back().offset + damage_.back().bytes == from) {
    damage_.back().bytes += to - from;
    return;
  }
  damage_.push_back(LogDamage{from, to - from, reason});
}

bool EventLogScanner::Next(LogEvent* event) {
  while (pos_ < size_) {
    const std::string problem = CheckHeader(pos_);
    if (!problem.empty()) {
      // Resync: the next sync word after this byte, or the end.
      const void* next = size_ - pos_ > 1 ? memmem(data_ + pos_ + 1, size_ - pos_ - 1, kSyncBytes, 4) : nullptr;
      const size_t to = next == nullptr ? size_ : static_cast<size_t>(static_cast<const uint8_t*>(next) - data_);
      RecordDamage(pos_, to, problem);
      pos_ = to;
      continue;
    }
    const uint8_t* p = data_ + pos_;
    const size_t channel_bytes = BigEndian(p + 20, 4);
    const size_t data_bytes = BigEndian(p + 24, 4);
    event->event_number = static_cast<int64_t>(BigEndian(p + 4, 8));
    event->timestamp_us = static_cast<int64_t>(BigEndian(p + 12, 8));
    event->channel.assign(reinterpret_cast<const char*>(p + EventLogWriter::kHeaderBytes), channel_bytes);
    event->data = p + EventLogWriter::kHeaderBytes + channel_bytes;
    event->size = data_bytes;
    event->offset = pos_;
    pos_ += EventLogWriter::kHeaderBytes + channel_bytes + data_bytes;
    return true;
  }
  return false;
}

uint64_t EventLogScanner::damaged_bytes() const {
  uint64_t total = 0;
  for (const LogDamage& d : damage_) total += d.bytes;
  return total;
}

MappedLog::MappedLog(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    error_ = "cannot open " + path + ": " + std::strerror(errno);
    return;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    error_ = path + " is not a regular file";
    ::close(fd);
    return;
  }
  size_ = static_cast<size_t>(st.st_size);
  if (size_ > 0) {
    void* mapped = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
    if (mapped == MAP_FAILED) {
      error_ = "cannot map " + path + ": " + std::strerror(errno);
      size_ = 0;
    } else {
      data_ = static_cast<const uint8_t*>(mapped);
    }
  }
  ::close(fd);
}

MappedLog::~MappedLog() {
  if (data_ != nullptr) ::munmap(const_cast<uint8_t*>(data_), size_);
}

}  // namespace orbed::logger
