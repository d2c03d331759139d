// libFuzzer: orbed-assistant's handlers (GUIDANCE, IIWA_STATUS, ROBOT_STATE, REGISTRATION, HMD_POSE,
// HMD_POSE_TRUTH, SETUP_TASK) and a step of its set-up after every input (looks and moves
// included: a task and a GUIDANCE in the corpus reach them).
#include "procs/assistant/assistant_process.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static auto* assistant = [] {
    orbed::assistant::AssistantOptions options;
    return new orbed::assistant::AssistantProcess(orbed::fuzz::FuzzFlags("orbed-assistant"), options);
  }();
  orbed::fuzz::FeedToProcess(assistant->process(), data, size);
  assistant->Step();
  return 0;
}
