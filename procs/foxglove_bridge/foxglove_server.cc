#include "procs/foxglove_bridge/foxglove_server.h"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

#include "procs/foxglove_bridge/foxglove_bridge.h"

namespace orbed::foxglove {

using Endpoint = websocketpp::server<websocketpp::config::asio>;
using Handle = websocketpp::connection_hdl;

struct FoxgloveServer::Impl {
  Endpoint endpoint;
  ServerOptions options;
  std::function<void(const ServerEvent&)> on_event;
  struct Client {
    std::string peer;
    std::map<uint32_t, uint32_t> subscription_of_channel;  // channel id → subscription id
  };
  std::map<Handle, Client, std::owner_less<Handle>> clients;
  int session = 0;

  std::string Peer(Handle h) {
    std::error_code ec;
    const auto con = endpoint.get_con_from_hdl(h, ec);
    return ec ? "?" : con->get_remote_endpoint();
  }
  void Refuse(Handle h, const std::string& why) { on_event({ServerEvent::kRefused, Peer(h), why}); }

  void OnMessage(Handle h, Endpoint::message_ptr msg) {
    const auto it = clients.find(h);
    if (it == clients.end()) return;
    if (msg->get_opcode() != websocketpp::frame::opcode::text)
      return Refuse(h, "a binary message (this server takes no client data)");
    std::string reason;
    const ClientRequest request = ParseClientMessage(msg->get_payload(), &reason);
    if (!reason.empty()) return Refuse(h, reason);
    auto& subs = it->second.subscription_of_channel;
    if (request.kind == ClientRequest::kSubscribe) {
      for (const auto& [sub, channel] : request.subscribe) {
        if (channel < kTf || channel > kLastChannel) {
          Refuse(h, "subscribe: no channel " + std::to_string(channel));
          continue;
        }
        subs[channel] = sub;
      }
    } else if (request.kind == ClientRequest::kUnsubscribe) {
      for (uint32_t sub : request.unsubscribe) {
        for (auto s = subs.begin(); s != subs.end();) s = s->second == sub ? subs.erase(s) : std::next(s);
      }
    } else {
      Refuse(h, "op \"" + request.op + "\" is not supported");
    }
  }
};

FoxgloveServer::FoxgloveServer(const ServerOptions& options, std::function<void(const ServerEvent&)> on_event)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.options = options;
  s.on_event = std::move(on_event);
  s.endpoint.clear_access_channels(websocketpp::log::alevel::all);
  s.endpoint.clear_error_channels(websocketpp::log::elevel::all);
  s.endpoint.init_asio();
  s.endpoint.set_reuse_addr(true);
  s.endpoint.set_max_message_size(kMaxClientMessageBytes);
  s.endpoint.set_validate_handler([this](Handle h) {
    Impl& s = *impl_;
    const auto con = s.endpoint.get_con_from_hdl(h);
    const std::vector<std::string>& offered = con->get_requested_subprotocols();
    if (std::find(offered.begin(), offered.end(), kSubprotocol) == offered.end()) {
      s.Refuse(h, std::string("handshake without the subprotocol ") + kSubprotocol);
      return false;
    }
    if (s.clients.size() >= s.options.max_clients) {
      s.Refuse(h, std::to_string(s.options.max_clients) + " clients already");
      return false;
    }
    con->select_subprotocol(kSubprotocol);
    return true;
  });
  s.endpoint.set_open_handler([this](Handle h) {
    Impl& s = *impl_;
    s.clients[h].peer = s.Peer(h);
    std::error_code ec;
    s.endpoint.send(h, ServerInfo("orbed-" + std::to_string(++s.session)).dump(),
                    websocketpp::frame::opcode::text, ec);
    if (!ec) s.endpoint.send(h, Advertise().dump(), websocketpp::frame::opcode::text, ec);
    s.on_event({ServerEvent::kConnected, s.clients[h].peer, ""});
  });
  const auto closed = [this](Handle h) {
    Impl& s = *impl_;
    const auto it = s.clients.find(h);
    if (it == s.clients.end()) return;
    s.on_event({ServerEvent::kDisconnected, it->second.peer, ""});
    s.clients.erase(it);
  };
  s.endpoint.set_close_handler(closed);
  s.endpoint.set_fail_handler(closed);
  s.endpoint.set_message_handler([this](Handle h, Endpoint::message_ptr msg) { impl_->OnMessage(h, msg); });
  std::error_code ec;
  const asio::ip::address address = asio::ip::make_address(options.bind_address, ec);
  if (ec || options.port < 0 || options.port > 65535)
    throw std::runtime_error("cannot listen on '" + options.bind_address + ":" +
                             std::to_string(options.port) + "': not an IP address and port");
  s.endpoint.listen(asio::ip::tcp::endpoint(address, static_cast<uint16_t>(options.port)), ec);
  if (!ec) s.endpoint.start_accept(ec);
  if (ec)
    throw std::runtime_error("cannot listen on " + options.bind_address + ":" + std::to_string(options.port) +
                             ": " + ec.message());
  port_ = s.endpoint.get_local_endpoint(ec).port();
}

FoxgloveServer::~FoxgloveServer() {
  Impl& s = *impl_;
  std::error_code ec;
  s.endpoint.stop_listening(ec);
  for (auto& [h, client] : s.clients) s.endpoint.close(h, websocketpp::close::status::going_away, "bye", ec);
  for (int i = 0; i < 100 && s.endpoint.poll() > 0; ++i) {
  }
}

size_t FoxgloveServer::num_clients() const { return impl_->clients.size(); }

bool FoxgloveServer::HasSubscribers(uint32_t channel) const {
  for (const auto& [h, client] : impl_->clients)
    if (client.subscription_of_channel.count(channel)) return true;
  return false;
}

void FoxgloveServer::Poll() { impl_->endpoint.poll(); }

int FoxgloveServer::Publish(uint32_t channel, uint64_t timestamp_ns, const std::string& payload) {
  Impl& s = *impl_;
  int missed = 0;
  for (const auto& [h, client] : s.clients) {
    const auto sub = client.subscription_of_channel.find(channel);
    if (sub == client.subscription_of_channel.end()) continue;
    std::error_code ec;
    const auto con = s.endpoint.get_con_from_hdl(h, ec);
    if (ec || con->get_buffered_amount() > s.options.max_buffered_bytes) {
      ++missed;
      continue;
    }
    con->send(MessageData(sub->second, timestamp_ns, payload), websocketpp::frame::opcode::binary);
  }
  return missed;
}

}  // namespace orbed::foxglove
