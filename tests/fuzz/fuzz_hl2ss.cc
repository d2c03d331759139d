// libFuzzer: what an hl2ss client sends to orbed-hl2ss (procs/hl2ss/protocol.h). The first byte picks
// the port (PV, RM depth long throw, SI, RC); the rest is the client's bytes. Whatever they are, each
// parser ends without crashing and uses no more than it was given; a configuration it accepts is in
// range (a video mode of protocol.h PvVideoModes, divisor >= 1, PNG filter <= 6); the RC
// command stream is parsed command after command as the server does, each accepted command answered
// by the emulated device without crashing, until more bytes are needed or one is refused.
#include <cstdlib>

#include "procs/hl2ss/emulated_device.h"
#include "procs/hl2ss/protocol.h"

using namespace orbed::hl2ss;

namespace {

void Check(bool condition) {
  if (!condition) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const uint8_t port = data[0] % 4;
  data += 1;
  size -= 1;
  switch (port) {
    case 0: {
      const Parsed<PvConfig> p = ParsePvConfig(data, size);
      if (p.status != ParseStatus::kDone) break;
      Check(p.used <= size && p.used >= 1);
      const PvConfig& c = p.value;
      if (c.mode == kMode3) break;
      bool known = false;
      for (const PvVideoMode& m : PvVideoModes())
        known = known || (m.width == c.width && m.height == c.height && m.framerate == c.framerate);
      Check(known);
      if (c.mode != kMode2) Check(c.divisor >= 1 && c.bitrate > 0 && c.options.size() <= kMaxEncoderOptions);
      break;
    }
    case 1: {
      const Parsed<RmDepthLongThrowConfig> p = ParseRmDepthLongThrowConfig(data, size);
      if (p.status == ParseStatus::kDone)
        Check(p.used <= size && p.value.mode <= kMode2 && p.value.divisor >= 1 && p.value.png_filter <= 6);
      break;
    }
    case 2:
      Check((ParseSiConfig(data, size).status == ParseStatus::kDone) == (size == 0));
      break;
    default: {
      EmulatedDevice device(TimeBase{1'700'000'000'000'000}, {1, 0, 0, 0});
      size_t at = 0;
      for (;;) {
        const Parsed<RcCommand> p = ParseRcCommand(data + at, size - at);
        if (p.status != ParseStatus::kDone) break;
        Check(p.used >= 1 && p.used <= size - at);
        at += p.used;
        const RcOutcome outcome = device.HandleRc(p.value, 1'700'000'001'000'000);
        Check(outcome.reply.size() <= static_cast<size_t>(kMaxRcPoints) * kPoseBytes);
      }
      break;
    }
  }
  return 0;
}
