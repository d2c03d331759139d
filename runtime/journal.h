#pragma once
/// @file
/// A journal: a file of LCM messages (channel + encoded bytes) from which a process rebuilds its
/// state after a crash. orbed-registration and orbed-hmd append the inputs that changed their
/// session and replay them at start; orbed-iiwa-sim replaces a one-record file holding its last
/// measured configuration.
///
/// Format, per record, big-endian:
///   "ORJ1" | uint32 channel length | uint32 data length | the first 8 bytes of
///   SHA-256(channel bytes, data bytes) | channel bytes | data bytes.
/// Append() writes a record with one write(2) on an O_APPEND descriptor, so a SIGKILL leaves at most
/// one torn record at the end; WriteJournalFile() / Replace() write a temporary file and rename it
/// over the old one, so a reader sees the old file or the new one. No fsync: a journal survives a
/// crash of its process, not of the machine.
///
/// Reading is checked like any input from outside: a record whose magic, lengths (bounded by
/// JournalLimits and by the bytes left) or checksum is wrong ends the readable part, and everything
/// after it is reported as damage, never read. A record is a message: whoever replays it decodes
/// it with DecodeBounded and checks it as if it had come from the bus. A file of n bytes costs O(n)
/// time and memory.
///
/// Threading: a Journal is not synchronised; one thread owns it.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace orbed {

struct JournalRecord {
  std::string channel;
  std::vector<uint8_t> data;
};

struct JournalLimits {
  uint64_t max_file_bytes = 64ull << 20;
  uint32_t max_channel_bytes = 256;
  uint32_t max_data_bytes = 1u << 20;
};

/// What a journal holds: its readable records and what follows them.
struct JournalContents {
  std::vector<JournalRecord> records;
  uint64_t valid_bytes = 0;    ///< bytes of the readable records
  uint64_t damaged_bytes = 0;  ///< bytes after them (a torn last record, or damage)
  std::string damage;          ///< why the bytes at valid_bytes are not a record ("" when none)
};

/// The bytes of one record.
std::string EncodeJournalRecord(const std::string& channel, const uint8_t* data, size_t size);
/// Parses journal bytes.
JournalContents ParseJournal(const uint8_t* data, size_t size, const JournalLimits& limits = {});
/// Reads a journal file; a missing file is an empty journal. Bytes beyond limits.max_file_bytes
/// are damage. Throws std::runtime_error naming the path when the file exists but cannot be read.
JournalContents ReadJournal(const std::string& path, const JournalLimits& limits = {});
/// Writes `records` as the whole file `path` (temporary file + rename). Returns false and sets
/// *error naming the path on failure.
bool WriteJournalFile(const std::string& path, const std::vector<JournalRecord>& records, std::string* error);

/// A message as a record: its channel and LCM encoding.
template <class Msg>
JournalRecord MakeJournalRecord(const std::string& channel, const Msg& msg) {
  JournalRecord record{channel, std::vector<uint8_t>(static_cast<size_t>(msg.getEncodedSize()))};
  msg.encode(record.data.data(), 0, static_cast<int>(record.data.size()));
  return record;
}

/// A journal open for appending.
class Journal {
 public:
  /// Reads `path` (ReadJournal; contents() keeps what was read) and opens it for appending; when
  /// damage follows the readable records the file is first rewritten to them, so that appends
  /// follow whole records. Throws std::runtime_error naming the path when it cannot read or write.
  explicit Journal(std::string path, JournalLimits limits = {});
  ~Journal();
  Journal(const Journal&) = delete;
  Journal& operator=(const Journal&) = delete;

  const std::string& path() const { return path_; }
  /// The journal as read when it was opened.
  const JournalContents& contents() const { return contents_; }
  /// Appends one record. Returns false, with error() saying why, when it cannot be written or
  /// the file would grow beyond limits.max_file_bytes (it could not be read back whole).
  bool Append(const JournalRecord& record);
  /// Replaces the file by `records` (temporary file + rename); appends then follow them.
  bool Replace(const std::vector<JournalRecord>& records);
  const std::string& error() const { return error_; }

 private:
  bool Reopen();

  std::string path_;
  JournalLimits limits_;
  JournalContents contents_;
  int fd_ = -1;
  uint64_t size_ = 0;
  std::string error_;
};

}  // namespace orbed
