// libFuzzer: the launch-file YAML (procs/launcher/launch_file.h), with ${VAR} expansion.
#include "procs/launcher/launch_file.h"
#include "tests/fuzz/fuzz_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::map<std::string, std::string> environment = {{"ORBED_LOG_DIR", "/tmp/logs"},
                                                                 {"ORBED_SOURCE_DIR", "/src"}};
  const std::string text = orbed::fuzz::AsText(data, size);
  orbed::fuzz::RefuseOrAccept([&] { orbed::launcher::ParseLaunchYaml(text, "fuzz.yaml", environment); });
  return 0;
}
