#pragma once
/// @file
/// WireReader: a cursor over the bytes of one LCM message that checks, without allocating, that an
/// encoding fits in its bytes. The generated CheckBody functions (orbed/wire_checks.hpp, from
/// lcmtypes/gen_wire_checks.py) drive it field by field; DecodeBounded (lcmtypes/bounded_decode.h)
/// is the one entry point that uses them.
///
/// Every array count is bounded by the bytes left before anything is skipped, so a walk over n
/// bytes takes O(n) time and O(1) memory whatever the counts say. On the first failure the reader
/// keeps its class (kind()) and a description naming the field and byte offset (error()).
/// Not thread-safe; one reader per message.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <string>

namespace orbed {
namespace wire {

/// Why a walk stopped. The names (KindName) are the reasons counted in PROCESS_STATUS.
enum class WireError {
  kNone,
  kTruncated,    // a field runs past the end of the bytes
  kFingerprint,  // the first 8 bytes are not the type's fingerprint
  kCount,        // an array dimension is negative or cannot fit in the bytes left
  kString,       // a string length below 1, or a string without its terminating NUL
  kTrailing,     // bytes left over after the last field
  kTooLarge,     // more bytes than LCM's decode can index (int)
  kDecode,       // the walk passed but LCM's decode disagreed (a generator bug)
};

inline const char* KindName(WireError kind) {
  switch (kind) {
    case WireError::kNone:
      return "ok";
    case WireError::kTruncated:
      return "truncated";
    case WireError::kFingerprint:
      return "fingerprint";
    case WireError::kCount:
      return "count";
    case WireError::kString:
      return "string";
    case WireError::kTrailing:
      return "trailing";
    case WireError::kTooLarge:
      return "too_large";
    case WireError::kDecode:
      return "decode";
  }
  return "unknown";
}

class WireReader {
 public:
  WireReader(const void* data, size_t size) : data_(static_cast<const uint8_t*>(data)), size_(size) {}

  size_t position() const { return pos_; }
  size_t remaining() const { return size_ - pos_; }
  WireError kind() const { return kind_; }
  const std::string& error() const { return error_; }

  /// Skips `bytes` bytes of `field`.
  bool Skip(size_t bytes, const char* field) {
    if (bytes > remaining())
      return Fail(WireError::kTruncated, field, "needs " + std::to_string(bytes) + " bytes");
    pos_ += bytes;
    return true;
  }

  /// Reads a big-endian signed integer of 1, 2, 4 or 8 bytes (an array dimension).
  bool ReadInteger(size_t bytes, int64_t* value, const char* field) {
    if (bytes > remaining())
      return Fail(WireError::kTruncated, field, "needs " + std::to_string(bytes) + " bytes");
    uint64_t bits = 0;
    for (size_t i = 0; i < bytes; ++i) bits = (bits << 8) | data_[pos_ + i];
    pos_ += bytes;
    const unsigned shift = static_cast<unsigned>(64 - 8 * bytes);
    // Sign-extend from the field's width.
    *value = static_cast<int64_t>(bits << shift) >> shift;
    return true;
  }

  /// Skips one string: int32 length L >= 1 (counting the NUL), then L bytes whose only NUL is the
  /// last.
  bool SkipString(const char* field) {
    int64_t length = 0;
    if (!ReadInteger(4, &length, field)) return false;
    if (length < 1)
      return Fail(WireError::kString, field, "string length " + std::to_string(length) + " < 1");
    if (static_cast<uint64_t>(length) > remaining()) {
      return Fail(WireError::kTruncated, field, "string of " + std::to_string(length) + " bytes");
    }
    // LCM's decode keeps bytes after an embedded NUL that its encode (strlen) drops: refuse them.
    const void* first_nul = std::memchr(data_ + pos_, 0, static_cast<size_t>(length));
    if (first_nul != data_ + pos_ + length - 1) {
      return Fail(
          WireError::kString, field,
          first_nul == nullptr ? "string without its terminating NUL" : "string with an embedded NUL");
    }
    pos_ += static_cast<size_t>(length);
    return true;
  }

  /// The element count of an array with dimensions `dims`, each element taking at least one byte:
  /// refuses a negative dimension or a count larger than the bytes left.
  bool Count(std::initializer_list<int64_t> dims, int64_t* count, const char* field) {
    int64_t n = 1;
    for (const int64_t dim : dims) {
      if (dim < 0) return Fail(WireError::kCount, field, "negative dimension " + std::to_string(dim));
      if (dim > 0 && n > static_cast<int64_t>(remaining()) / dim) {
        return Fail(
            WireError::kCount, field,
            "dimension " + std::to_string(dim) + " cannot fit in " + std::to_string(remaining()) + " bytes");
      }
      n *= dim;
    }
    *count = n;
    return true;
  }

  /// Skips an array of fixed-size elements: the count is checked before the bytes.
  bool SkipArray(std::initializer_list<int64_t> dims, size_t element_bytes, const char* field) {
    int64_t count = 0;
    if (!Count(dims, &count, field)) return false;
    if (static_cast<uint64_t>(count) > remaining() / element_bytes) {
      return Fail(WireError::kCount, field,
                  std::to_string(count) + " elements of " + std::to_string(element_bytes) +
                      " bytes cannot fit in " + std::to_string(remaining()) + " bytes");
    }
    pos_ += static_cast<size_t>(count) * element_bytes;
    return true;
  }

  /// Records the first failure; always returns false.
  bool Fail(WireError kind, const std::string& field, const std::string& what) {
    if (kind_ == WireError::kNone) {
      kind_ = kind;
      error_ = field + ": " + what + " at byte " + std::to_string(pos_) + " of " + std::to_string(size_);
    }
    return false;
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
  WireError kind_ = WireError::kNone;
  std::string error_;
};

}  // namespace wire
}  // namespace orbed
