// libFuzzer: orbed-hmd's message handlers (SESSION_CONTROL, IIWA_STATUS, ROBOT_STATE,
// REGISTRATION, ...) in-process, images made inline.
#include "hmd_emulator/hmd_process.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static auto* hmd = [] {
    orbed::hmd::HmdOptions options;
    options.threaded = false;
    return new orbed::hmd::HmdProcess(orbed::fuzz::FuzzFlags("orbed-hmd"), options);
  }();
  orbed::fuzz::FeedToProcess(hmd->process(), data, size);
  return 0;
}
