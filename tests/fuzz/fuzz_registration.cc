// libFuzzer: orbed-registration's message handlers (SESSION_CONTROL, ALIGNMENT_TRIAL,
// LANDMARK_REQUEST, MISALIGNMENT_REQUEST) in-process.
#include "procs/registration_server/registration_server_process.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static auto* server = new orbed::registration::RegistrationServer(
      orbed::fuzz::FuzzFlags("orbed-registration"), orbed::registration::RegistrationServerOptions{});
  orbed::fuzz::FeedToProcess(*server, data, size);
  return 0;
}
