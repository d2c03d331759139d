#pragma once
/// @file
/// The WebSocket side of orbed-foxglove-bridge: a websocketpp server (Debian's websocketpp on
/// standalone asio) that speaks foxglove.websocket.v1 (foxglove_bridge.h), driven by Poll() from
/// one thread (asio's poll: it runs what is ready and returns), so the bridge needs no locks.
///
/// A client must offer the subprotocol foxglove.websocket.v1 (others are refused in the
/// handshake); beyond max_clients a handshake is refused. On open it receives serverInfo and
/// advertise; it subscribes and unsubscribes by JSON; what it sends otherwise (binary frames,
/// unknown ops, malformed JSON, messages over 64 KiB: those close the connection) is refused and
/// reported. Publish() sends a Message Data frame to every subscriber of a channel; a client with
/// more than max_buffered_bytes not yet written misses it (the count is returned).
///
/// Threading: not thread-safe; one thread calls everything.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>

namespace orbed::foxglove {

struct ServerOptions {
  std::string bind_address{"127.0.0.1"};
  int port{8765};  ///< Foxglove's default; 0: any free port (see port())
  size_t max_clients{8};
  size_t max_buffered_bytes{32u << 20};
};

struct ServerEvent {
  enum Kind { kConnected, kDisconnected, kRefused } kind;
  std::string peer, detail;
};

class FoxgloveServer {
 public:
  /// Listens. Throws std::runtime_error naming the address and the error.
  FoxgloveServer(const ServerOptions& options, std::function<void(const ServerEvent&)> on_event);
  ~FoxgloveServer();
  FoxgloveServer(const FoxgloveServer&) = delete;
  FoxgloveServer& operator=(const FoxgloveServer&) = delete;

  int port() const { return port_; }
  size_t num_clients() const;
  bool HasSubscribers(uint32_t channel) const;
  /// Runs the ready handlers (accepts, handshakes, reads, writes) without blocking.
  void Poll();
  /// Message Data to every subscriber of `channel`; returns how many subscribers missed it.
  int Publish(uint32_t channel, uint64_t timestamp_ns, const std::string& payload);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int port_ = 0;
};

}  // namespace orbed::foxglove
