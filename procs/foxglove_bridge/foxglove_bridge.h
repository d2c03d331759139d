#pragma once
/// @file
/// The Foxglove WebSocket protocol (subprotocol foxglove.websocket.v1) as orbed-foxglove-bridge
/// speaks it, pure: the server's info, the channels it advertises (sim/foxglove_messages.h: their
/// topics, schemas and JSON messages, shared with orbed-log export --mcap), the binary Message Data
/// frame and what clients ask.
///
/// Threading: pure functions.

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim/foxglove_messages.h"

namespace orbed::foxglove {

inline constexpr char kSubprotocol[] = "foxglove.websocket.v1";

/// {"op":"serverInfo",...} and {"op":"advertise",...}: what a client receives on connecting.
nlohmann::json ServerInfo(const std::string& session_id);
nlohmann::json Advertise();

/// The binary Message Data frame: opcode 1, subscription id (uint32 LE), timestamp [ns] (uint64 LE),
/// payload.
std::string MessageData(uint32_t subscription_id, uint64_t timestamp_ns, const std::string& payload);

/// What a client asked for. Malformed requests (not JSON, not an object, unknown op, ids that are
/// not unsigned 32-bit integers, more than kMaxSubscriptions) are refused with a reason.
struct ClientRequest {
  enum Kind { kSubscribe, kUnsubscribe, kIgnored } kind{kIgnored};
  std::vector<std::pair<uint32_t, uint32_t>> subscribe;  ///< (subscription id, channel id)
  std::vector<uint32_t> unsubscribe;                     ///< subscription ids
  std::string op;                                        ///< for kIgnored: the op
};
inline constexpr size_t kMaxSubscriptions = 64;
inline constexpr size_t kMaxClientMessageBytes = 64 << 10;
/// The request, or the reason it is refused (returned in *reason, the result then kIgnored with
/// reason non-empty).
ClientRequest ParseClientMessage(const std::string& text, std::string* reason);

}  // namespace orbed::foxglove
