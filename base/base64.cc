#include "base/base64.h"

#include <climits>
#include <stdexcept>

#include <openssl/evp.h>

namespace orbed {

std::string Base64(const uint8_t* data, size_t size) {
  if (size > static_cast<size_t>(INT_MAX / 4 * 3)) throw std::length_error("base64: more than 1.5 GB");
  std::string text(4 * ((size + 2) / 3) + 1, '\0');  // EVP_EncodeBlock adds a NUL
  const int n = EVP_EncodeBlock(reinterpret_cast<unsigned char*>(text.data()), data, static_cast<int>(size));
  text.resize(static_cast<size_t>(n));
  return text;
}

}  // namespace orbed
