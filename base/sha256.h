#pragma once
/// @file
/// SHA-256 (FIPS 180-4) of a byte string or a file, as lowercase hex, computed by OpenSSL's
/// libcrypto (EVP interface): the implementation users already trust. Used to pin the URDF, scene
/// and config files a session ran with in the logger's manifest, and the journals' records.
/// Thread-safe (each call has its own digest context).

#include <string>

namespace orbed {

std::string Sha256Hex(const std::string& bytes);
/// Hash of a file's contents, read in 64 KiB blocks; returns "" if it cannot be read (and sets
/// *error if given).
std::string Sha256FileHex(const std::string& path, std::string* error = nullptr);

}  // namespace orbed
