#pragma once
/// @file
/// Base64 (RFC 4648, standard alphabet, '=' padding, no line breaks) of a byte string, computed by
/// OpenSSL's libcrypto (EVP_EncodeBlock). Used where bytes travel inside JSON: Foxglove's
/// CompressedImage and the byte arrays of `orbed-log export --mcap`. Thread-safe.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace orbed {

std::string Base64(const uint8_t* data, size_t size);
inline std::string Base64(const std::vector<uint8_t>& bytes) { return Base64(bytes.data(), bytes.size()); }

}  // namespace orbed
