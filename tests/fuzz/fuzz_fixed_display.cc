// libFuzzer: orbed-fixed-display's handlers (ROBOT_STATE, GUIDANCE) and the picture it would
// publish after each input (every mode, a small picture: each accepted target is rendered).
#include "lcmtypes/contract/conversions.h"
#include "procs/fixed_display/fixed_display_process.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static auto* display = [] {
    orbed::fixed_display::FixedDisplayOptions options;
    options.all_modes = true;
    options.picture.width_px = 96;
    options.picture.height_px = 72;
    return new orbed::fixed_display::FixedDisplay(orbed::fuzz::FuzzFlags("orbed-fixed-display"), options);
  }();
  orbed::fuzz::FeedToProcess(display->process(), data, size);
  if (size > 0) display->PressKey(data[size - 1]);
  (void)display->PictureNow(orbed::NowMicros());
  return 0;
}
