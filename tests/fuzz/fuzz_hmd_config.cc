// libFuzzer: the headset's YAML (SLAM, user, walk, display) as an overlay file on the shipped
// configs, through the loader orbed-hmd --config uses (key-by-key merge and cross-reference checks).
#include "base/source_paths.h"
#include "hmd_emulator/hmd_config.h"
#include "tests/fuzz/fuzz_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::vector<std::string> shipped = [] {
    std::vector<std::string> paths;
    for (const std::string& relative : orbed::hmd::DefaultHmdConfigRelativePaths()) {
      paths.push_back(orbed::SourceTreePath(relative));
    }
    return paths;
  }();
  const std::string& overlay = orbed::fuzz::ScratchFile("overlay.yaml");
  orbed::fuzz::WriteFile(overlay, data, size);
  std::vector<std::string> paths = shipped;
  paths.push_back(overlay);
  orbed::fuzz::RefuseOrAccept([&] { orbed::hmd::LoadHmdConfigs(paths); });
  return 0;
}
