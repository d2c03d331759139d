// libFuzzer: the offline trial file of `orbed-registration mean` / `send`.
#include <sstream>

#include "procs/registration_server/trial_file.h"
#include "tests/fuzz/fuzz_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::istringstream in(orbed::fuzz::AsText(data, size));
  orbed::fuzz::RefuseOrAccept([&] { orbed::registration::ParseTrialFile(in); });
  return 0;
}
