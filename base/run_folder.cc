#include "base/run_folder.h"

#include <filesystem>
#include <system_error>

namespace orbed {

std::string ProvenanceRecordIn(const std::string& dir) {
  std::error_code ec;
  return std::filesystem::is_regular_file(std::filesystem::path(dir) / kProvenanceRecord, ec)
             ? kProvenanceRecord
             : "";
}

}  // namespace orbed
