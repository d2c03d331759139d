#include "base/source_paths.h"

#include <cstdlib>

#ifndef ORBED_BUILD_SOURCE_DIR
#define ORBED_BUILD_SOURCE_DIR "."
#endif

namespace orbed {

std::string SourceDir() {
  const char* env = std::getenv("ORBED_SOURCE_DIR");
  return env && *env ? std::string(env) : std::string(ORBED_BUILD_SOURCE_DIR);
}

std::string SourceTreePath(const std::string& relative) { return SourceDir() + "/" + relative; }

}  // namespace orbed
