// libFuzzer: orbed-igtl-bridge's OpenIGTLink stream reader (igtl_bridge.h), fed a client's bytes in
// two pieces. Whatever the bytes, it ends every call without crashing; a pose it accepts is rigid
// and finite; and it never holds more than a header, the largest body and the last piece.
#include <cstdlib>

#include "procs/igtl_bridge/igtl_bridge.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using orbed::igtl_bridge::IgtlReader;
  IgtlReader reader;
  const size_t split = size > 0 ? data[0] % (size + 1) : 0;
  const std::pair<size_t, size_t> pieces[] = {{0, split}, {split, size - split}};
  bool fatal = false;  // the bridge closes the connection then: nothing more is fed
  for (const auto& [from, length] : pieces) {
    if (fatal) break;
    reader.Feed(data + from, length);
    orbed::igtl_bridge::IgtlPose pose;
    std::string reason;
    for (IgtlReader::Result r; (r = reader.Next(&pose, &reason)) != IgtlReader::Result::kNeedMore;) {
      if (r == IgtlReader::Result::kFatal) {
        fatal = true;
        break;
      }
      if (r == IgtlReader::Result::kPose) {
        const Eigen::Matrix3d R = pose.X_m.linear();
        if (!pose.X_m.matrix().allFinite() ||
            (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-2)
          std::abort();
      }
    }
    if (!fatal &&
        reader.buffered() > orbed::igtl_bridge::kHeaderBytes + orbed::igtl_bridge::kMaxBodyBytes + length)
      std::abort();
  }
  return 0;
}
