// libFuzzer: the OR scene YAML (sim/scene.h).
#include "sim/scene.h"
#include "tests/fuzz/fuzz_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = orbed::fuzz::AsText(data, size);
  orbed::fuzz::RefuseOrAccept([&] { orbed::sim::LoadSceneString(text, "fuzz.yaml"); });
  return 0;
}
