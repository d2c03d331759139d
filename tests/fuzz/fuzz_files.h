#pragma once
/// @file
/// The file-parser fuzz targets' one rule: a parser may refuse its input by throwing a
/// std::exception (that is the documented way each loader reports a bad file); anything else — a
/// crash, a sanitizer report, a hang, unbounded memory — is a bug libFuzzer reports.

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include <unistd.h>

namespace orbed::fuzz {

/// Runs `parse()`; a std::exception is a refusal and is swallowed.
template <class F>
void RefuseOrAccept(F parse) {
  try {
    parse();
  } catch (const std::exception&) {
  }
}

/// The input as text.
inline std::string AsText(const uint8_t* data, size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

/// A file this process rewrites per input (for loaders that only take paths), in a private folder.
inline const std::string& ScratchFile(const char* name) {
  static const std::string dir = [] {
    char path[] = "/tmp/orbed_fuzz_filesXXXXXX";
    if (mkdtemp(path) == nullptr) std::abort();
    return std::string(path);
  }();
  static std::string path;
  path = dir + "/" + name;
  return path;
}

inline void WriteFile(const std::string& path, const uint8_t* data, size_t size) {
  FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) std::abort();
  if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
}

}  // namespace orbed::fuzz
