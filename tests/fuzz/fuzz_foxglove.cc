// libFuzzer: orbed-foxglove-bridge's reader of what a Foxglove client sends (ParseClientMessage).
// Whatever the text, it returns; a request it reads is within its bounds; a refusal leaves no ids.
#include <cstdlib>
#include <string>

#include "procs/foxglove_bridge/foxglove_bridge.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using orbed::foxglove::ClientRequest;
  std::string reason;
  const ClientRequest r =
      orbed::foxglove::ParseClientMessage(std::string(reinterpret_cast<const char*>(data), size), &reason);
  if (r.subscribe.size() > orbed::foxglove::kMaxSubscriptions ||
      r.unsubscribe.size() > orbed::foxglove::kMaxSubscriptions)
    std::abort();
  if (!reason.empty() &&
      (r.kind != ClientRequest::kIgnored || !r.subscribe.empty() || !r.unsubscribe.empty()))
    std::abort();
  return 0;
}
