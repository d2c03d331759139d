// libFuzzer: DecodeBounded on every message type (the first byte picks the type). A message that
// passes must be exactly one message for LCM: decoded in full and re-encoded byte for byte; and it
// flattens (orbed-log export's cells) into as many cells as names.
#include <cstdlib>
#include <cstring>
#include <vector>

#include <orbed/all_types.hpp>
#include <orbed/flatten.hpp>

#include "lcmtypes/bounded_decode.h"

namespace {

template <class Msg>
void CheckOne(const uint8_t* data, size_t size) {
  Msg msg;
  if (!orbed::DecodeBounded(data, size, &msg).ok()) return;
  std::vector<uint8_t> again(static_cast<size_t>(msg.getEncodedSize()));
  if (again.size() != size ||
      msg.encode(again.data(), 0, static_cast<int>(again.size())) != static_cast<int>(size) ||
      std::memcmp(again.data(), data, size) != 0) {
    std::abort();  // the wire check let through bytes that are not one message
  }
  orbed::flat::FlatRow row;
  orbed::flat::Flatten(msg, "", row);
  if (row.names.size() != row.cells.size() || row.names.empty()) std::abort();
}

using Checker = void (*)(const uint8_t*, size_t);
#define ORBED_FUZZ_CHECKER(type) &CheckOne<orbed::type>,
const Checker kCheckers[] = {ORBED_FOR_EACH_LCM_TYPE(ORBED_FUZZ_CHECKER)};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  kCheckers[data[0] % (sizeof(kCheckers) / sizeof(kCheckers[0]))](data + 1, size - 1);
  return 0;
}
