#pragma once
/// @file
/// The TCP side of orbed-hl2ss: one listening socket per hl2ss port (PV 3810, SI 3812, RC 3809, RM
/// depth long throw 3805), bound to one address (loopback by default), and their clients, all
/// non-blocking and driven by Poll() from one thread.
///
/// A client's life: it connects (beyond max_clients on that port it is closed at once, refused);
/// it sends its configuration (protocol.h's parser for the port; SI takes none), which must be
/// complete within config_timeout_s of connecting; the owner's on_configured decides: serve it
/// (stream clients then get packets through Send()), answer bytes and close (a calibration or a
/// control-only connection), or refuse it. The RC port instead carries a stream of commands, each
/// answered through on_rc; the Unity message queue (UMQ) port a stream of commands the owner parses
/// (on_bytes); a command left half-sent for config_timeout_s is refused. Bytes a stream
/// client sends after its configuration, a configuration a parser refuses, an unknown RC command:
/// refused (the client closed), other clients unaffected.
///
/// Memory: a client's unread input is at most its port's largest legal message (the parsers refuse
/// larger counts first; a UMQ client's input is handed over as it arrives); its output queue at most
/// max_queue_bytes and max_queue_packets whole packets; an RC or UMQ client whose answers pile up
/// beyond max_queue_bytes (it sends commands but does not read) is refused ("<port>/not_reading"). Send() to
/// a full queue drops that packet (a client that stops reading loses frames); after max_consecutive_drops
/// drops in a row the client is closed as stalled. Packets are never cut: a queued packet is sent whole.
///
/// Threading: not thread-safe; one thread calls everything.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "procs/hl2ss/protocol.h"

namespace orbed::hl2ss {

enum class PortKind { kPv, kSi, kRc, kRmDepthLongThrow, kUmq };
std::string PortName(PortKind kind);  // "pv", "si", "rc", "rm_depth", "umq"

struct ServerOptions {
  std::string bind_address{"127.0.0.1"};  ///< an IPv4 address; 0.0.0.0 for every interface
  /// Port per kind; 0: any free port (see port()); a kind left out is not served.
  std::map<PortKind, int> ports{{PortKind::kPv, kPortPersonalVideo},
                                {PortKind::kSi, kPortSpatialInput},
                                {PortKind::kRc, kPortRemoteConfiguration},
                                {PortKind::kRmDepthLongThrow, kPortRmDepthLongThrow},
                                {PortKind::kUmq, kPortUnityMessageQueue}};
  size_t max_clients{4};              ///< per port
  size_t max_queue_bytes{64u << 20};  ///< per client
  size_t max_queue_packets{8};        ///< per client
  int max_consecutive_drops{90};      ///< then the client is closed (3 s of PV at 30 Hz)
  double config_timeout_s{5.0};
};

using StreamConfig = std::variant<std::monostate, PvConfig, SiConfig, RmDepthLongThrowConfig>;

/// What the owner decides for a configured client or an RC command.
struct Decision {
  enum Kind { kServe, kReplyAndClose, kRefuse } kind{kServe};
  std::vector<uint8_t> reply;  ///< sent first (kServe on RC: the command's answer)
  std::string key, reason;     ///< kRefuse
};

struct ServerEvent {
  enum Kind { kConnected, kDisconnected, kRefused, kDropped, kStalled } kind;
  PortKind port;
  int client{0};
  std::string peer;
  std::string key;     ///< kRefused: "<port>/<what>" for PROCESS_STATUS
  std::string detail;  ///< the reason
};

struct ServerHandlers {
  std::function<Decision(int client, PortKind port, const StreamConfig& config)> on_configured;
  std::function<Decision(int client, const RcCommand& command)> on_rc;
  /// The Unity message queue's bytes as they arrive (the owner's parser keeps its own state): append
  /// the answers to *reply; false closes the client once *reply is sent.
  std::function<bool(int client, const uint8_t* data, size_t size, std::vector<uint8_t>* reply)> on_bytes;
  std::function<void(const ServerEvent&)> on_event;
};

class Hl2ssServer {
 public:
  /// Listens on every port in options.ports. Throws std::runtime_error naming the address, port
  /// and the system's error.
  explicit Hl2ssServer(const ServerOptions& options);
  ~Hl2ssServer();
  Hl2ssServer(const Hl2ssServer&) = delete;
  Hl2ssServer& operator=(const Hl2ssServer&) = delete;

  /// The bound port of a kind (0 when not served).
  int port(PortKind kind) const;
  /// The configured stream clients of a port being served, with their configurations.
  std::vector<std::pair<int, const StreamConfig*>> Serving(PortKind kind) const;
  size_t num_clients() const { return clients_.size(); }

  /// Queues a whole packet for a served client; false when dropped (queue full; counted as a
  /// kDropped event, and past the limit the client is closed with kStalled) or the client is gone.
  bool Send(int client, std::vector<uint8_t> packet, const std::function<void(const ServerEvent&)>& on_event);

  /// One round of accepting, reading, parsing and writing, without blocking. `now_us` is a
  /// monotonic clock [µs] for the configuration timeout.
  void Poll(int64_t now_us, const ServerHandlers& handlers);

 private:
  struct Client {
    int id{0};
    int fd{-1};
    PortKind port{PortKind::kPv};
    std::string peer;
    int64_t connected_us{0};
    int64_t pending_since_us{0};  // RC: when the unfinished command began
    enum State { kConfiguring, kServing, kClosing } state{kConfiguring};
    StreamConfig config;
    std::vector<uint8_t> in;
    std::deque<std::vector<uint8_t>> out;
    size_t out_front_sent{0};
    size_t out_bytes{0};
    int consecutive_drops{0};
  };
  struct Listener {
    PortKind kind;
    int fd{-1};
    int port{0};
  };
  void Accept(Listener& listener, int64_t now_us, const ServerHandlers& h);
  // Reads what arrived and acts on it; false when the client is to be closed (`why` says).
  bool Read(Client& c, int64_t now_us, const ServerHandlers& h, std::string* why);
  // Parses the configuration or RC commands in c.in; false: close (`why`).
  bool Consume(Client& c, int64_t now_us, const ServerHandlers& h, std::string* why);
  bool Write(Client& c, std::string* why);
  void Queue(Client& c, std::vector<uint8_t> bytes);
  void Refuse(Client& c, const std::string& key, const std::string& reason, const ServerHandlers& h);

  ServerOptions options_;
  std::vector<Listener> listeners_;
  std::vector<std::unique_ptr<Client>> clients_;
  int next_id_{1};
};

}  // namespace orbed::hl2ss
