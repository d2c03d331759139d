// libFuzzer: setup_results.json as orbed-setup --resume reads it back. What it accepts must write
// back to a document that reads again to the same text (the reader and the writer agree).
#include <cstdlib>
#include <string>

#include "experiments/setup/setup_conductor.h"
#include "tests/fuzz/fuzz_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  orbed::fuzz::RefuseOrAccept([&] {
    std::string status;
    const orbed::setup::SetupRun run =
        orbed::setup::ParseSetupRunJson(orbed::fuzz::AsText(data, size), "fuzz", &status);
    const std::string written = orbed::setup::SetupRunJson(run, status == "partial");
    std::string again_status;
    const orbed::setup::SetupRun again = orbed::setup::ParseSetupRunJson(written, "written", &again_status);
    if (orbed::setup::SetupRunJson(again, again_status == "partial") != written) std::abort();
  });
  return 0;
}
