#include "procs/foxglove_bridge/foxglove_bridge.h"

#include <exception>

#include "base/json_fields.h"

namespace orbed::foxglove {

using json = nlohmann::json;

json ServerInfo(const std::string& session_id) {
  return {{"op", "serverInfo"},
          {"name", "orbed-foxglove-bridge"},
          {"capabilities", json::array()},
          {"supportedEncodings", json::array({"json"})},
          {"metadata", json::object()},
          {"sessionId", session_id}};
}

json Advertise() {
  json channels = json::array();
  for (const ChannelSpec& c : Channels()) {
    channels.push_back({{"id", static_cast<uint32_t>(c.id)},
                        {"topic", c.topic},
                        {"encoding", "json"},
                        {"schemaName", c.schema_name},
                        {"schema", c.schema.dump()},
                        {"schemaEncoding", "jsonschema"}});
  }
  return {{"op", "advertise"}, {"channels", channels}};
}

std::string MessageData(uint32_t subscription_id, uint64_t timestamp_ns, const std::string& payload) {
  std::string frame(1 + 4 + 8, '\0');
  frame[0] = 1;
  for (int i = 0; i < 4; ++i) frame[1 + i] = static_cast<char>((subscription_id >> (8 * i)) & 0xff);
  for (int i = 0; i < 8; ++i) frame[5 + i] = static_cast<char>((timestamp_ns >> (8 * i)) & 0xff);
  return frame + payload;
}

ClientRequest ParseClientMessage(const std::string& text, std::string* reason) {
  ClientRequest request;
  reason->clear();
  if (text.size() > kMaxClientMessageBytes) {
    *reason = "a message of " + std::to_string(text.size()) + " bytes";
    return request;
  }
  json doc;
  try {
    doc = JsonFields("client message").Parse(text, kMaxClientMessageBytes, 8);  // bounded depth
  } catch (const std::exception& e) {
    *reason = e.what();
    return request;
  }
  if (!doc.is_object() || !doc.contains("op") || !doc["op"].is_string()) {
    *reason = "not a JSON object with an \"op\"";
    return request;
  }
  const auto id = [](const json& v, uint32_t* out) {
    if (!v.is_number_unsigned() || v.get<uint64_t>() > 0xffffffffu) return false;
    *out = static_cast<uint32_t>(v.get<uint64_t>());
    return true;
  };
  request.op = doc["op"].get<std::string>();
  if (request.op == "subscribe") {
    const json& subs = doc.value("subscriptions", json());
    if (!subs.is_array() || subs.size() > kMaxSubscriptions) {
      *reason = "subscribe: \"subscriptions\" is not an array of at most 64";
      return request;
    }
    for (const json& s : subs) {
      uint32_t sub = 0, channel = 0;
      if (!s.is_object() || !s.contains("id") || !s.contains("channelId") || !id(s["id"], &sub) ||
          !id(s["channelId"], &channel)) {
        *reason = "subscribe: an entry without unsigned 32-bit \"id\" and \"channelId\"";
        request.subscribe.clear();
        return request;
      }
      request.subscribe.emplace_back(sub, channel);
    }
    request.kind = ClientRequest::kSubscribe;
  } else if (request.op == "unsubscribe") {
    const json& ids = doc.value("subscriptionIds", json());
    if (!ids.is_array() || ids.size() > kMaxSubscriptions) {
      *reason = "unsubscribe: \"subscriptionIds\" is not an array of at most 64";
      return request;
    }
    for (const json& v : ids) {
      uint32_t sub = 0;
      if (!id(v, &sub)) {
        *reason = "unsubscribe: an id that is not an unsigned 32-bit integer";
        request.unsubscribe.clear();
        return request;
      }
      request.unsubscribe.push_back(sub);
    }
    request.kind = ClientRequest::kUnsubscribe;
  }
  return request;
}

}  // namespace orbed::foxglove
