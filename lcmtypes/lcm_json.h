#pragma once
/// @file
/// The runtime half of the generated orbed/to_json.hpp (lcmtypes/gen_json.py): a decoded LCM message
/// as JSON for `orbed-log export --mcap`. Doubles as themselves (nlohmann writes the shortest decimal
/// that reads back to the same value), NaN and infinities as null (JSON has no NaN); byte arrays as
/// one base64 string. Write documents with Dump() so text that is not UTF-8 becomes U+FFFD instead of
/// an exception. Pure; thread-safe.

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/base64.h"

namespace orbed {
namespace lcm_json {

inline nlohmann::ordered_json JsonDouble(double value) {
  if (!std::isfinite(value)) return nullptr;
  return value;
}

inline nlohmann::ordered_json JsonBase64(const std::vector<uint8_t>& bytes) { return Base64(bytes); }

/// One line of JSON; invalid UTF-8 in strings replaced by U+FFFD.
template <class Json>
std::string Dump(const Json& j) {
  return j.dump(-1, ' ', false, nlohmann::detail::error_handler_t::replace);
}

}  // namespace lcm_json
}  // namespace orbed
