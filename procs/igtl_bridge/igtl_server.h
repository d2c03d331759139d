#pragma once
/// @file
/// The TCP side of orbed-igtl-bridge: a listening socket and its clients (OpenIGTLink clients such
/// as 3D Slicer's OpenIGTLinkIF connector), all non-blocking and driven by Poll() from one thread,
/// so the bridge needs no locks. Messages are whole packets from igtl_bridge.h.
///
/// Broadcast() queues a packet for every client; a client whose queue would pass max_backlog_bytes
/// (it reads slower than the bridge sends) misses that packet, and the miss is counted. Poll()
/// accepts (beyond max_clients a new connection is closed at once), writes what the socket takes,
/// reads what arrived and hands each client's bytes to its IgtlReader. A client that closes, fails
/// or sends what igtl_bridge.h calls fatal is closed.
///
/// Threading: not thread-safe; one thread calls everything.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "procs/igtl_bridge/igtl_bridge.h"

namespace orbed::igtl_bridge {

struct IgtlServerOptions {
  std::string bind_address{"127.0.0.1"};  ///< an IPv4 address; 0.0.0.0 for every interface
  int port{18944};                        ///< 0: any free port (see port())
  size_t max_clients{8};
  size_t max_backlog_bytes{64u << 20};
};

/// What Poll() reports besides poses: a client came or went, or a message was skipped or refused.
struct IgtlEvent {
  enum Kind { kConnected, kDisconnected, kSkipped, kRefused } kind;
  std::string peer;    ///< "address:port"
  std::string detail;  ///< the reason, or what was skipped
};

class IgtlServer {
 public:
  /// Listens. Throws std::runtime_error naming the address and the system's error.
  explicit IgtlServer(const IgtlServerOptions& options);
  ~IgtlServer();
  IgtlServer(const IgtlServer&) = delete;
  IgtlServer& operator=(const IgtlServer&) = delete;

  int port() const { return port_; }
  size_t num_clients() const { return clients_.size(); }

  /// Queues `packet` for every client; returns how many clients missed it (backlog full).
  int Broadcast(const std::vector<uint8_t>& packet);
  /// One round of accepting, writing and reading without blocking.
  void Poll(const std::function<void(const IgtlPose&, const std::string& peer)>& on_pose,
            const std::function<void(const IgtlEvent&)>& on_event);

 private:
  struct Client {
    int fd = -1;
    std::string peer;
    std::vector<uint8_t> out;  // queued bytes, out_sent of them already written
    size_t out_sent = 0;
    IgtlReader reader;
  };
  void Close(size_t index, const std::string& why, const std::function<void(const IgtlEvent&)>& on_event);

  IgtlServerOptions options_;
  int listen_fd_ = -1;
  int port_ = 0;
  std::vector<std::unique_ptr<Client>> clients_;
};

}  // namespace orbed::igtl_bridge
