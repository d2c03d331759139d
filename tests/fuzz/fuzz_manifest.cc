// libFuzzer: the logger's manifest.json reader (procs/logger/manifest.h), which a logger continuing
// a recording and the tools read from disk. It may refuse (JsonReadError); whatever it accepts must
// write back to a document it reads as the same manifest.
#include <cstdlib>

#include "procs/logger/manifest.h"
#include "tests/fuzz/fuzz_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  orbed::fuzz::RefuseOrAccept([&] {
    const orbed::logger::Manifest manifest =
        orbed::logger::ParseManifest(orbed::fuzz::AsText(data, size), "fuzz");
    const std::string again = orbed::logger::ManifestJson(manifest);
    if (orbed::logger::ManifestJson(orbed::logger::ParseManifest(again, "rewritten")) != again) std::abort();
  });
  return 0;
}
