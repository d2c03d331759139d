#include "runtime/journal.h"

#include <algorithm>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "base/replace_file.h"
#include "base/sha256.h"

namespace orbed {
namespace {

constexpr char kMagic[4] = {'O', 'R', 'J', '1'};
constexpr size_t kChecksumBytes = 8;
constexpr size_t kHeaderBytes = 4 + 4 + 4 + kChecksumBytes;

void PutU32(uint32_t value, std::string* out) {
  for (int shift = 24; shift >= 0; shift -= 8) out->push_back(static_cast<char>((value >> shift) & 0xFF));
}

uint32_t GetU32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | uint32_t{p[3]};
}

// The first kChecksumBytes of SHA-256(channel, data).
std::string Checksum(const char* channel, size_t channel_size, const uint8_t* data, size_t size) {
  std::string bytes(channel, channel_size);
  bytes.append(reinterpret_cast<const char*>(data), size);
  const std::string hex = Sha256Hex(bytes);
  std::string out;
  for (size_t i = 0; i < kChecksumBytes; ++i) {
    out.push_back(static_cast<char>(std::stoi(hex.substr(2 * i, 2), nullptr, 16)));
  }
  return out;
}

// Why the bytes at `p` (`left` of them) are not a record, or "" with *record_bytes set.
std::string CheckRecord(const uint8_t* p, size_t left, const JournalLimits& limits, size_t* record_bytes) {
  if (left < kHeaderBytes) return "a record header cut short (" + std::to_string(left) + " bytes)";
  if (std::memcmp(p, kMagic, sizeof(kMagic)) != 0) return "no record magic";
  const uint32_t channel_size = GetU32(p + 4);
  const uint32_t data_size = GetU32(p + 8);
  if (channel_size == 0 || channel_size > limits.max_channel_bytes) {
    return "channel length " + std::to_string(channel_size);
  }
  if (data_size > limits.max_data_bytes) return "data length " + std::to_string(data_size);
  const uint64_t body = uint64_t{channel_size} + data_size;
  if (body > left - kHeaderBytes) {
    return "a record of " + std::to_string(kHeaderBytes + body) + " bytes cut short (" +
           std::to_string(left) + " bytes)";
  }
  const char* channel = reinterpret_cast<const char*>(p + kHeaderBytes);
  if (Checksum(channel, channel_size, p + kHeaderBytes + channel_size, data_size) !=
      std::string(reinterpret_cast<const char*>(p + 12), kChecksumBytes)) {
    return "checksum mismatch";
  }
  *record_bytes = static_cast<size_t>(kHeaderBytes + body);
  return "";
}

}  // namespace

std::string EncodeJournalRecord(const std::string& channel, const uint8_t* data, size_t size) {
  std::string out(kMagic, sizeof(kMagic));
  PutU32(static_cast<uint32_t>(channel.size()), &out);
  PutU32(static_cast<uint32_t>(size), &out);
  out += Checksum(channel.data(), channel.size(), data, size);
  out += channel;
  out.append(reinterpret_cast<const char*>(data), size);
  return out;
}

JournalContents ParseJournal(const uint8_t* data, size_t size, const JournalLimits& limits) {
  JournalContents contents;
  size_t pos = 0;
  while (pos < size) {
    size_t record_bytes = 0;
    const std::string problem = CheckRecord(data + pos, size - pos, limits, &record_bytes);
    if (!problem.empty()) {
      contents.damage = problem + " at byte " + std::to_string(pos);
      break;
    }
    const uint8_t* p = data + pos;
    const uint32_t channel_size = GetU32(p + 4);
    const uint8_t* body = p + kHeaderBytes;
    contents.records.push_back(JournalRecord{std::string(reinterpret_cast<const char*>(body), channel_size),
                                             std::vector<uint8_t>(body + channel_size, p + record_bytes)});
    pos += record_bytes;
  }
  contents.valid_bytes = pos;
  contents.damaged_bytes = size - pos;
  return contents;
}

JournalContents ReadJournal(const std::string& path, const JournalLimits& limits) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    if (errno == ENOENT) return {};
    throw std::runtime_error("cannot read the journal " + path + ": " + std::strerror(errno));
  }
  // Sized by the file, not by the limit: a small journal costs what it holds (fuzz_state_files
  // found the old buffer of max_file_bytes + 1 for every read).
  in.seekg(0, std::ios::end);
  const uint64_t file_bytes = in ? static_cast<uint64_t>(in.tellg()) : 0;
  in.seekg(0, std::ios::beg);
  std::vector<uint8_t> bytes(std::min<uint64_t>(file_bytes, limits.max_file_bytes + 1));
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (in.bad()) throw std::runtime_error("cannot read the journal " + path);
  bytes.resize(static_cast<size_t>(in.gcount()));
  if (bytes.size() <= limits.max_file_bytes) return ParseJournal(bytes.data(), bytes.size(), limits);
  in.seekg(0, std::ios::end);
  JournalContents contents = ParseJournal(bytes.data(), limits.max_file_bytes, limits);
  contents.damaged_bytes = static_cast<uint64_t>(in.tellg()) - contents.valid_bytes;
  if (contents.damage.empty()) {
    contents.damage = "the file is larger than " + std::to_string(limits.max_file_bytes) + " bytes";
  }
  return contents;
}

bool WriteJournalFile(const std::string& path, const std::vector<JournalRecord>& records,
                      std::string* error) {
  std::string bytes;
  for (const JournalRecord& r : records)
    bytes += EncodeJournalRecord(r.channel, r.data.data(), r.data.size());
  return ReplaceFile(path, bytes, error);
}

Journal::Journal(std::string path, JournalLimits limits) : path_(std::move(path)), limits_(limits) {
  contents_ = ReadJournal(path_, limits_);
  if (contents_.damaged_bytes > 0) {
    // Cut the damage off, so that appends follow whole records.
    if (!Replace(contents_.records)) throw std::runtime_error(error_);
    return;
  }
  if (!Reopen()) throw std::runtime_error(error_);
}

Journal::~Journal() {
  if (fd_ >= 0) ::close(fd_);
}

bool Journal::Reopen() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    error_ = "cannot open the journal " + path_ + ": " + std::strerror(errno);
    return false;
  }
  const off_t size = ::lseek(fd_, 0, SEEK_END);
  size_ = size < 0 ? 0 : static_cast<uint64_t>(size);
  return true;
}

bool Journal::Append(const JournalRecord& record) {
  if (fd_ < 0) return false;
  const std::string bytes = EncodeJournalRecord(record.channel, record.data.data(), record.data.size());
  if (size_ + bytes.size() > limits_.max_file_bytes) {
    error_ = "the journal " + path_ + " is full (" + std::to_string(size_) + " bytes)";
    return false;
  }
  size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(fd_, bytes.data() + written, bytes.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      error_ = "cannot append to the journal " + path_ + ": " + std::strerror(errno);
      return false;
    }
    written += static_cast<size_t>(n);
  }
  size_ += bytes.size();
  return true;
}

bool Journal::Replace(const std::vector<JournalRecord>& records) {
  return WriteJournalFile(path_, records, &error_) && Reopen();
}

}  // namespace orbed
