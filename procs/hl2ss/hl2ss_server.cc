#include "procs/hl2ss/hl2ss_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>
#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace orbed::hl2ss {
namespace {

std::string Peer(const sockaddr_in& address) {
  char text[INET_ADDRSTRLEN] = "?";
  inet_ntop(AF_INET, &address.sin_addr, text, sizeof(text));
  return std::string(text) + ":" + std::to_string(ntohs(address.sin_port));
}

// The most a client may have sent and we not yet used: its port's largest legal message.
size_t MaxInput(PortKind kind) {
  if (kind == PortKind::kRc) return 13 + static_cast<size_t>(kMaxRcPoints) * 8;
  if (kind == PortKind::kUmq) return 64 << 10;  // one read: on_bytes takes all of it at once
  return 1 + kMrcVideoOptionsBytes + 5 + 8 + 16 * kMaxEncoderOptions;
}

}  // namespace

std::string PortName(PortKind kind) {
  switch (kind) {
    case PortKind::kPv:
      return "pv";
    case PortKind::kSi:
      return "si";
    case PortKind::kRc:
      return "rc";
    case PortKind::kRmDepthLongThrow:
      return "rm_depth";
    case PortKind::kUmq:
      return "umq";
  }
  return "?";
}

Hl2ssServer::Hl2ssServer(const ServerOptions& options) : options_(options) {
  for (const auto& [kind, port] : options.ports) {
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<uint16_t>(port));
    const std::string where = options.bind_address + ":" + std::to_string(port);
    if (port < 0 || port > 65535 || inet_pton(AF_INET, options.bind_address.c_str(), &address.sin_addr) != 1)
      throw std::runtime_error("cannot listen on '" + where + "': not an IPv4 address and port");
    const int fd = socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    const int yes = 1;
    if (fd < 0 || setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes)) != 0 ||
        bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0 || listen(fd, 8) != 0) {
      const std::string error = std::strerror(errno);
      if (fd >= 0) close(fd);
      for (const Listener& l : listeners_) close(l.fd);
      throw std::runtime_error("cannot listen on " + where + " (" + PortName(kind) + "): " + error);
    }
    socklen_t size = sizeof(address);
    getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size);
    listeners_.push_back({kind, fd, ntohs(address.sin_port)});
  }
}

Hl2ssServer::~Hl2ssServer() {
  for (const auto& c : clients_) close(c->fd);
  for (const Listener& l : listeners_) close(l.fd);
}

int Hl2ssServer::port(PortKind kind) const {
  for (const Listener& l : listeners_)
    if (l.kind == kind) return l.port;
  return 0;
}

std::vector<std::pair<int, const StreamConfig*>> Hl2ssServer::Serving(PortKind kind) const {
  std::vector<std::pair<int, const StreamConfig*>> out;
  for (const auto& c : clients_)
    if (c->port == kind && c->state == Client::kServing) out.emplace_back(c->id, &c->config);
  return out;
}

void Hl2ssServer::Queue(Client& c, std::vector<uint8_t> bytes) {
  if (bytes.empty()) return;
  c.out_bytes += bytes.size();
  c.out.push_back(std::move(bytes));
}

void Hl2ssServer::Refuse(Client& c, const std::string& key, const std::string& reason,
                         const ServerHandlers& h) {
  if (h.on_event) h.on_event({ServerEvent::kRefused, c.port, c.id, c.peer, key, reason});
}

bool Hl2ssServer::Send(int client, std::vector<uint8_t> packet,
                       const std::function<void(const ServerEvent&)>& on_event) {
  const auto it =
      std::find_if(clients_.begin(), clients_.end(), [client](const auto& c) { return c->id == client; });
  if (it == clients_.end() || (*it)->state != Client::kServing) return false;
  Client& c = **it;
  if (c.out.size() < options_.max_queue_packets && c.out_bytes + packet.size() <= options_.max_queue_bytes) {
    c.consecutive_drops = 0;
    Queue(c, std::move(packet));
    return true;
  }
  ++c.consecutive_drops;
  if (on_event) on_event({ServerEvent::kDropped, c.port, c.id, c.peer, PortName(c.port) + "/backlog", ""});
  if (c.consecutive_drops >= options_.max_consecutive_drops) {
    const std::string why =
        "stalled: " + std::to_string(c.consecutive_drops) + " packets in a row found its queue full";
    if (on_event) on_event({ServerEvent::kStalled, c.port, c.id, c.peer, PortName(c.port) + "/stalled", why});
    if (on_event) on_event({ServerEvent::kDisconnected, c.port, c.id, c.peer, "", why});
    close(c.fd);
    clients_.erase(it);
  }
  return false;
}

void Hl2ssServer::Accept(Listener& listener, int64_t now_us, const ServerHandlers& h) {
  for (;;) {
    sockaddr_in address{};
    socklen_t size = sizeof(address);
    const int fd =
        accept4(listener.fd, reinterpret_cast<sockaddr*>(&address), &size, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) return;
    const size_t on_port = static_cast<size_t>(std::count_if(
        clients_.begin(), clients_.end(), [&](const auto& c) { return c->port == listener.kind; }));
    auto client = std::make_unique<Client>();
    client->id = next_id_++;
    client->fd = fd;
    client->port = listener.kind;
    client->peer = Peer(address);
    client->connected_us = now_us;
    if (on_port >= options_.max_clients) {
      Refuse(*client, PortName(listener.kind) + "/clients",
             "connection refused: " + std::to_string(options_.max_clients) + " clients already", h);
      close(fd);
      continue;
    }
    const int yes = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof(yes));
    if (h.on_event) h.on_event({ServerEvent::kConnected, client->port, client->id, client->peer, "", ""});
    if (listener.kind == PortKind::kSi) {  // no configuration: served at once
      client->config = SiConfig{};
      const Decision d =
          h.on_configured ? h.on_configured(client->id, PortKind::kSi, client->config) : Decision{};
      if (d.kind == Decision::kRefuse) {
        Refuse(*client, d.key, d.reason, h);
        close(fd);
        continue;
      }
      client->state = Client::kServing;
    }
    if (listener.kind == PortKind::kRc || listener.kind == PortKind::kUmq)
      client->state = Client::kServing;  // commands, no configuration
    clients_.push_back(std::move(client));
  }
}

bool Hl2ssServer::Consume(Client& c, int64_t now_us, const ServerHandlers& h, std::string* why) {
  const auto refuse = [&](const std::string& key, const std::string& reason) {
    Refuse(c, key, reason, h);
    *why = "refused: " + reason;
    return false;
  };
  if (c.in.empty()) return true;
  const bool commands = c.port == PortKind::kRc || c.port == PortKind::kUmq;
  if (commands && c.out_bytes > options_.max_queue_bytes)
    return refuse(
        PortName(c.port) + "/not_reading",
        std::to_string(c.out_bytes) + " bytes of answers unread (it sends commands but does not read)");
  if (c.state == Client::kServing && !commands)
    return refuse(
        PortName(c.port) + "/unexpected",
        std::to_string(c.in.size()) + " bytes after the configuration (a stream client only reads)");
  if (c.state == Client::kClosing) {
    c.in.clear();
    return true;
  }
  if (c.port == PortKind::kUmq) {
    std::vector<uint8_t> reply;
    const bool keep = h.on_bytes && h.on_bytes(c.id, c.in.data(), c.in.size(), &reply);
    c.in.clear();
    Queue(c, std::move(reply));
    if (!keep) c.state = Client::kClosing;
    return true;
  }
  if (c.port == PortKind::kRc) {
    while (!c.in.empty()) {
      const Parsed<RcCommand> p = ParseRcCommand(c.in.data(), c.in.size());
      if (p.status == ParseStatus::kRefused) return refuse(p.key, p.reason);
      if (p.status == ParseStatus::kNeedMore) {
        if (c.pending_since_us == 0) c.pending_since_us = now_us;
        return true;
      }
      c.in.erase(c.in.begin(), c.in.begin() + static_cast<std::ptrdiff_t>(p.used));
      c.pending_since_us = 0;
      const Decision d = h.on_rc ? h.on_rc(c.id, p.value) : Decision{};
      if (d.kind == Decision::kRefuse) return refuse(d.key, d.reason);
      Queue(c, d.reply);
      if (d.kind == Decision::kReplyAndClose) {
        c.state = Client::kClosing;
        c.in.clear();
      }
    }
    return true;
  }
  // A stream port's configuration.
  StreamConfig config;
  size_t used = 0;
  if (c.port == PortKind::kPv) {
    Parsed<PvConfig> p = ParsePvConfig(c.in.data(), c.in.size());
    if (p.status == ParseStatus::kRefused) return refuse(p.key, p.reason);
    if (p.status == ParseStatus::kNeedMore) return true;
    used = p.used;
    config = std::move(p.value);
  } else if (c.port == PortKind::kRmDepthLongThrow) {
    const Parsed<RmDepthLongThrowConfig> p = ParseRmDepthLongThrowConfig(c.in.data(), c.in.size());
    if (p.status == ParseStatus::kRefused) return refuse(p.key, p.reason);
    if (p.status == ParseStatus::kNeedMore) return true;
    used = p.used;
    config = p.value;
  } else {
    const Parsed<SiConfig> p = ParseSiConfig(c.in.data(), c.in.size());
    return refuse(p.key, p.reason);
  }
  c.in.erase(c.in.begin(), c.in.begin() + static_cast<std::ptrdiff_t>(used));
  c.config = std::move(config);
  const Decision d = h.on_configured ? h.on_configured(c.id, c.port, c.config) : Decision{};
  if (d.kind == Decision::kRefuse) return refuse(d.key, d.reason);
  Queue(c, d.reply);
  c.state = d.kind == Decision::kServe ? Client::kServing : Client::kClosing;
  return Consume(c, now_us, h, why);  // anything sent after the configuration
}

bool Hl2ssServer::Read(Client& c, int64_t now_us, const ServerHandlers& h, std::string* why) {
  uint8_t buffer[64 << 10];
  const size_t max_in = MaxInput(c.port);
  for (int reads = 0; reads < 16; ++reads) {
    const ssize_t n = recv(c.fd, buffer, sizeof(buffer), MSG_DONTWAIT);
    if (n > 0) {
      if (c.in.size() + static_cast<size_t>(n) > max_in) {
        Refuse(c, PortName(c.port) + "/too_long", "more than " + std::to_string(max_in) + " bytes unparsed",
               h);
        *why = "refused: input too long";
        return false;
      }
      c.in.insert(c.in.end(), buffer, buffer + n);
      if (!Consume(c, now_us, h, why)) return false;
      continue;
    }
    if (n == 0) {
      *why = "the client closed the connection";
      return false;
    }
    if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) return true;
    *why = std::string("receive failed: ") + std::strerror(errno);
    return false;
  }
  return true;
}

bool Hl2ssServer::Write(Client& c, std::string* why) {
  while (!c.out.empty()) {
    const std::vector<uint8_t>& front = c.out.front();
    const ssize_t n = send(c.fd, front.data() + c.out_front_sent, front.size() - c.out_front_sent,
                           MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      c.out_front_sent += static_cast<size_t>(n);
      if (c.out_front_sent == front.size()) {
        c.out_bytes -= front.size();
        c.out.pop_front();
        c.out_front_sent = 0;
      }
    } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) {
      return true;
    } else {
      *why = std::string("send failed: ") + std::strerror(errno);
      return false;
    }
  }
  return true;
}

void Hl2ssServer::Poll(int64_t now_us, const ServerHandlers& h) {
  for (Listener& l : listeners_) Accept(l, now_us, h);
  const int64_t timeout_us = static_cast<int64_t>(options_.config_timeout_s * 1e6);
  for (size_t i = 0; i < clients_.size();) {
    Client& c = *clients_[i];
    std::string why;
    bool keep = Write(c, &why) && Read(c, now_us, h, &why);
    if (keep && c.state == Client::kConfiguring && now_us - c.connected_us > timeout_us) {
      Refuse(c, PortName(c.port) + "/timeout",
             "no complete configuration within " + std::to_string(options_.config_timeout_s) + " s", h);
      why = "refused: configuration timeout";
      keep = false;
    }
    if (keep && c.port == PortKind::kRc && c.pending_since_us != 0 &&
        now_us - c.pending_since_us > timeout_us) {
      Refuse(c, "rc/timeout",
             "a command left unfinished for " + std::to_string(options_.config_timeout_s) + " s", h);
      why = "refused: command timeout";
      keep = false;
    }
    if (keep && c.state == Client::kClosing && c.out.empty()) {
      why = "done";
      keep = false;
    }
    if (keep) keep = Write(c, &why);  // answers queued by Read
    if (!keep) {
      std::string ignored;
      Write(c, &ignored);  // best effort: answers to the commands before a refused one
      if (h.on_event) h.on_event({ServerEvent::kDisconnected, c.port, c.id, c.peer, "", why});
      close(c.fd);
      clients_.erase(clients_.begin() + static_cast<std::ptrdiff_t>(i));
      continue;
    }
    ++i;
  }
}

}  // namespace orbed::hl2ss
