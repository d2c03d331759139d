#pragma once
/// @file
/// DecodeBounded: the one way orbed turns bytes from the bus or a log into a message.
///
/// LCM 1.3.1's generated decode resizes every vector to the count it reads before it checks that
/// the bytes exist, so one 77-byte PROCESS_STATUS claiming 2^31 - 1 reasons costs gigabytes. Here
/// the encoding is first walked (orbed/wire_checks.hpp, generated from the .lcm files) with every
/// count bounded by the bytes left; only a message that fits exactly is handed to LCM's decode. A
/// message of n bytes therefore costs O(n) time and memory. Pure; thread-safe.

#include <cstddef>
#include <cstdint>
#include <exception>
#include <limits>
#include <string>
#include <vector>

#include <orbed/wire_checks.hpp>

#include "lcmtypes/wire_reader.h"

namespace orbed {

/// What DecodeBounded found: ok, or why not (kind names the class counted as a rejection reason,
/// error the field and byte offset).
struct DecodeResult {
  wire::WireError kind = wire::WireError::kNone;
  std::string error;
  bool ok() const { return kind == wire::WireError::kNone; }
};

/// The entry of `types` whose `fingerprint` (an LCM type hash) the encoded message `data` starts
/// with (8 bytes, big-endian), or null (unknown, or fewer than 8 bytes). For tools that take any
/// type (the log exports).
template <class Type>
const Type* FindTypeByFingerprint(const std::vector<Type>& types, const uint8_t* data, size_t size) {
  if (size < 8) return nullptr;
  uint64_t fingerprint = 0;
  for (int i = 0; i < 8; ++i) fingerprint = (fingerprint << 8) | data[i];
  for (const Type& type : types)
    if (static_cast<uint64_t>(type.fingerprint) == fingerprint) return &type;
  return nullptr;
}

/// Walks `size` bytes as an encoded `Msg` (fingerprint first) without allocating.
template <class Msg>
DecodeResult CheckEncoding(const void* data, size_t size) {
  wire::WireReader reader(data, size);
  int64_t fingerprint = 0;
  DecodeResult result;
  if (size > static_cast<size_t>(std::numeric_limits<int>::max())) {
    reader.Fail(wire::WireError::kTooLarge, Msg::getTypeName(),
                "message of " + std::to_string(size) + " bytes");
  } else if (!reader.ReadInteger(8, &fingerprint, "fingerprint")) {
  } else if (fingerprint != Msg::getHash()) {
    reader.Fail(wire::WireError::kFingerprint, Msg::getTypeName(), "not this type's fingerprint");
  } else if (wire::CheckBody(static_cast<const Msg*>(nullptr), reader) && reader.remaining() > 0) {
    reader.Fail(wire::WireError::kTrailing, Msg::getTypeName(),
                std::to_string(reader.remaining()) + " bytes left over");
  }
  result.kind = reader.kind();
  result.error = reader.error();
  return result;
}

/// Decodes `size` bytes into `*msg` if and only if they are exactly one well-formed `Msg`.
template <class Msg>
DecodeResult DecodeBounded(const void* data, size_t size, Msg* msg) {
  DecodeResult result = CheckEncoding<Msg>(data, size);
  if (!result.ok()) return result;
  int decoded = -1;
  try {
    decoded = msg->decode(data, 0, static_cast<int>(size));
  } catch (const std::exception&) {
    decoded = -1;
  }
  if (decoded != static_cast<int>(size)) {
    result.kind = wire::WireError::kDecode;
    result.error = std::string(Msg::getTypeName()) + ": the walk accepted " + std::to_string(size) +
                   " bytes but LCM's decode returned " + std::to_string(decoded);
  }
  return result;
}

}  // namespace orbed
