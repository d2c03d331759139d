// libFuzzer: orbed-drake-viewer's handlers (ROBOT_STATE, REGISTRATION, GUIDANCE) and the draw it
// would publish after each input.
#include "lcmtypes/contract/conversions.h"
#include "procs/drake_viewer/drake_viewer_process.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static auto* viewer = [] {
    return new orbed::viewer::ViewerBridge(orbed::fuzz::FuzzFlags("orbed-drake-viewer"),
                                           orbed::viewer::ViewerOptions{});
  }();
  orbed::fuzz::FeedToProcess(viewer->process(), data, size);
  (void)viewer->DrawNow(orbed::NowMicros());
  return 0;
}
