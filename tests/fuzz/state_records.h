#pragma once
/// @file
/// The input form of fuzz_state_files (and of the seeds orbed-fuzz-seeds writes for it): after the
/// mode byte, a list of records [channel byte][uint16 little-endian length][data], made into a
/// well-formed journal (runtime/journal.h) before a reader replays it, so that fuzzing reaches
/// what the records say rather than stopping at their checksums. The channel byte picks among
/// kStateRecordChannels (modulo their number); a length running past the end takes what is left.
///
/// Threading: pure functions.

#include <cstddef>
#include <cstdint>
#include <iterator>
#include <string>

#include "runtime/journal.h"

namespace orbed::fuzz {

/// The record channels the state-file readers know, and one they do not.
inline constexpr const char* kStateRecordChannels[] = {"SESSION_CONTROL", "ALIGNMENT_TRIAL", "IIWA_STATUS",
                                                       "NOT_A_RECORD"};

/// Modes (the input's first byte, modulo 4).
enum StateFileMode : uint8_t {
  kRawJournal = 0,
  kRegistrationJournal = 1,
  kHmdStateFile = 2,
  kSimStateFile = 3
};

/// One record in the input form.
inline std::string StateRecord(uint8_t channel_index, const uint8_t* data, size_t size) {
  const size_t n = size > 0xffff ? 0xffff : size;
  std::string record{static_cast<char>(channel_index), static_cast<char>(n & 0xff),
                     static_cast<char>(n >> 8)};
  record.append(reinterpret_cast<const char*>(data), n);
  return record;
}

/// The records of `data` (the input after its mode byte) as journal bytes.
inline std::string StateRecordsToJournal(const uint8_t* data, size_t size) {
  std::string journal;
  size_t at = 0;
  while (at + 3 <= size) {
    const char* channel = kStateRecordChannels[data[at] % std::size(kStateRecordChannels)];
    size_t length = data[at + 1] | (static_cast<size_t>(data[at + 2]) << 8);
    at += 3;
    if (length > size - at) length = size - at;
    journal += EncodeJournalRecord(channel, data + at, length);
    at += length;
  }
  return journal;
}

}  // namespace orbed::fuzz
