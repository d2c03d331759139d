// libFuzzer: orbed-guidance's handler (IIWA_STATUS) and the GUIDANCE it would publish.
#include "lcmtypes/contract/conversions.h"
#include "procs/guidance/guidance_process.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static auto* guidance = [] {
    orbed::guidance::GuidanceOptions options;
    options.target.q_target_rad = Eigen::VectorXd::Zero(7);
    return new orbed::guidance::GuidanceProcess(orbed::fuzz::FuzzFlags("orbed-guidance"), options);
  }();
  orbed::fuzz::FeedToProcess(guidance->process(), data, size);
  (void)guidance->GuidanceNow(orbed::NowMicros());
  return 0;
}
