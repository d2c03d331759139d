#include "base/sha256.h"

#include <fstream>
#include <memory>
#include <stdexcept>
#include <vector>

#include <openssl/evp.h>

namespace orbed {
namespace {

// One digest in progress; throws only when libcrypto itself fails (out of memory).
class Digest {
 public:
  Digest() : context_(EVP_MD_CTX_new(), &EVP_MD_CTX_free) {
    if (!context_ || EVP_DigestInit_ex(context_.get(), EVP_sha256(), nullptr) != 1)
      throw std::runtime_error("libcrypto: cannot start a SHA-256 digest");
  }
  void Update(const char* data, size_t size) {
    if (size > 0 && EVP_DigestUpdate(context_.get(), data, size) != 1)
      throw std::runtime_error("libcrypto: SHA-256 update failed");
  }
  std::string FinalHex() {
    unsigned char digest[EVP_MAX_MD_SIZE];
    unsigned int length = 0;
    if (EVP_DigestFinal_ex(context_.get(), digest, &length) != 1)
      throw std::runtime_error("libcrypto: SHA-256 final failed");
    static const char kHex[] = "0123456789abcdef";
    std::string hex;
    for (unsigned int i = 0; i < length; ++i) {
      hex.push_back(kHex[digest[i] >> 4]);
      hex.push_back(kHex[digest[i] & 0xf]);
    }
    return hex;
  }

 private:
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> context_;
};

}  // namespace

std::string Sha256Hex(const std::string& bytes) {
  Digest digest;
  digest.Update(bytes.data(), bytes.size());
  return digest.FinalHex();
}

std::string Sha256FileHex(const std::string& path, std::string* error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    if (error) *error = "cannot read " + path;
    return "";
  }
  Digest digest;
  std::vector<char> block(64 * 1024);
  while (in) {
    in.read(block.data(), static_cast<std::streamsize>(block.size()));
    digest.Update(block.data(), static_cast<size_t>(in.gcount()));
  }
  if (in.bad()) {
    if (error) *error = "read error in " + path;
    return "";
  }
  return digest.FinalHex();
}

}  // namespace orbed
