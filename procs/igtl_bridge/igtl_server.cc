#include "procs/igtl_bridge/igtl_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>
#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace orbed::igtl_bridge {
namespace {

std::string Peer(const sockaddr_in& address) {
  char text[INET_ADDRSTRLEN] = "?";
  inet_ntop(AF_INET, &address.sin_addr, text, sizeof(text));
  return std::string(text) + ":" + std::to_string(ntohs(address.sin_port));
}

}  // namespace

IgtlServer::IgtlServer(const IgtlServerOptions& options) : options_(options) {
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(options.port));
  if (options.port < 0 || options.port > 65535 ||
      inet_pton(AF_INET, options.bind_address.c_str(), &address.sin_addr) != 1)
    throw std::runtime_error("cannot listen on '" + options.bind_address + ":" +
                             std::to_string(options.port) + "': not an IPv4 address and port");
  listen_fd_ = socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  const int yes = 1;
  if (listen_fd_ < 0 || setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes)) != 0 ||
      bind(listen_fd_, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0 ||
      listen(listen_fd_, 8) != 0) {
    const std::string error = std::strerror(errno);
    if (listen_fd_ >= 0) close(listen_fd_);
    throw std::runtime_error("cannot listen on " + options.bind_address + ":" + std::to_string(options.port) +
                             ": " + error);
  }
  socklen_t size = sizeof(address);
  getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&address), &size);
  port_ = ntohs(address.sin_port);
}

IgtlServer::~IgtlServer() {
  for (const auto& c : clients_) close(c->fd);
  if (listen_fd_ >= 0) close(listen_fd_);
}

int IgtlServer::Broadcast(const std::vector<uint8_t>& packet) {
  int missed = 0;
  for (const auto& c : clients_) {
    if (c->out.size() - c->out_sent + packet.size() > options_.max_backlog_bytes) {
      ++missed;
      continue;
    }
    c->out.insert(c->out.end(), packet.begin(), packet.end());
  }
  return missed;
}

void IgtlServer::Close(size_t index, const std::string& why,
                       const std::function<void(const IgtlEvent&)>& on_event) {
  on_event({IgtlEvent::kDisconnected, clients_[index]->peer, why});
  close(clients_[index]->fd);
  clients_.erase(clients_.begin() + static_cast<std::ptrdiff_t>(index));
}

void IgtlServer::Poll(const std::function<void(const IgtlPose&, const std::string& peer)>& on_pose,
                      const std::function<void(const IgtlEvent&)>& on_event) {
  for (;;) {
    sockaddr_in address{};
    socklen_t size = sizeof(address);
    const int fd =
        accept4(listen_fd_, reinterpret_cast<sockaddr*>(&address), &size, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) break;
    if (clients_.size() >= options_.max_clients) {
      on_event({IgtlEvent::kRefused, Peer(address),
                "connection refused: " + std::to_string(options_.max_clients) + " clients already"});
      close(fd);
      continue;
    }
    const int yes = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof(yes));
    auto client = std::make_unique<Client>();
    client->fd = fd;
    client->peer = Peer(address);
    on_event({IgtlEvent::kConnected, client->peer, ""});
    clients_.push_back(std::move(client));
  }
  uint8_t buffer[64 << 10];
  for (size_t i = 0; i < clients_.size();) {
    Client& c = *clients_[i];
    bool closed = false;
    while (c.out_sent < c.out.size()) {
      const ssize_t n =
          send(c.fd, c.out.data() + c.out_sent, c.out.size() - c.out_sent, MSG_NOSIGNAL | MSG_DONTWAIT);
      if (n > 0) {
        c.out_sent += static_cast<size_t>(n);
      } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) {
        break;
      } else {
        Close(i, std::string("send failed: ") + std::strerror(errno), on_event);
        closed = true;
        break;
      }
    }
    if (closed) continue;
    if (c.out_sent == c.out.size()) {
      c.out.clear();
      c.out_sent = 0;
    } else if (c.out_sent > (1u << 20)) {
      c.out.erase(c.out.begin(), c.out.begin() + static_cast<std::ptrdiff_t>(c.out_sent));
      c.out_sent = 0;
    }
    std::string why;
    for (int reads = 0; reads < 16; ++reads) {  // at most 1 MiB per client per round
      const ssize_t n = recv(c.fd, buffer, sizeof(buffer), MSG_DONTWAIT);
      if (n > 0) {
        c.reader.Feed(buffer, static_cast<size_t>(n));
        IgtlPose pose;
        std::string reason;
        for (IgtlReader::Result r; (r = c.reader.Next(&pose, &reason)) != IgtlReader::Result::kNeedMore;) {
          if (r == IgtlReader::Result::kPose) on_pose(pose, c.peer);
          if (r == IgtlReader::Result::kSkipped) on_event({IgtlEvent::kSkipped, c.peer, reason});
          if (r == IgtlReader::Result::kRefused) on_event({IgtlEvent::kRefused, c.peer, reason});
          if (r == IgtlReader::Result::kFatal) {
            on_event({IgtlEvent::kRefused, c.peer, reason});
            why = "closed: " + reason;
            break;
          }
        }
        if (!why.empty()) break;
        continue;
      }
      if (n == 0) why = "the client closed the connection";
      if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)
        why = std::string("receive failed: ") + std::strerror(errno);
      break;
    }
    if (!why.empty()) {
      Close(i, why, on_event);
      continue;
    }
    ++i;
  }
}

}  // namespace orbed::igtl_bridge
