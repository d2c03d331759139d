// The TCP server on loopback with real client sockets: a configuration in two pieces reaches the
// owner once and the client then gets exactly the bytes sent; garbage, a silent client, one too
// many and an unknown RC command are refused with their keys while another client keeps
// receiving; a client that stops reading loses packets and is closed as stalled; RC answers.
// Waits are poll(2) on the client sockets between server rounds, never sleeps.
#include "procs/hl2ss/hl2ss_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <functional>

#include <gtest/gtest.h>

namespace orbed::hl2ss {
namespace {

int Connect(int port, int receive_buffer = 0) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (receive_buffer > 0) setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof(receive_buffer));
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
  EXPECT_EQ(connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)), 0);
  return fd;
}

void SendAll(int fd, const std::vector<uint8_t>& bytes) {
  ASSERT_EQ(send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL), static_cast<ssize_t>(bytes.size()));
}

struct Harness {
  explicit Harness(ServerOptions options = Options()) : server(options) {
    handlers.on_configured = [this](int client, PortKind port, const StreamConfig& config) {
      configured.emplace_back(client, port, config);
      return decision;
    };
    handlers.on_rc = [this](int, const RcCommand& command) {
      Decision d;
      d.reply = {static_cast<uint8_t>(command.id), 0x42};
      return d;
    };
    handlers.on_event = [this](const ServerEvent& e) { events.push_back(e); };
  }
  static ServerOptions Options() {
    ServerOptions o;
    for (auto& [kind, port] : o.ports) port = 0;
    o.max_clients = 2;
    return o;
  }
  // Server rounds until `done` or 2000 rounds, each waiting up to 1 ms on the server's sockets'
  // far ends (the client fds given).
  bool PumpUntil(const std::function<bool()>& done, std::vector<int> fds = {}, int64_t now_us = 0) {
    for (int i = 0; i < 2000; ++i) {
      server.Poll(now_us, handlers);
      if (done()) return true;
      std::vector<pollfd> p;
      for (int fd : fds) p.push_back({fd, POLLIN, 0});
      ::poll(p.data(), p.size(), 1);
    }
    return false;
  }
  bool Refused(const std::string& key) const {
    for (const ServerEvent& e : events)
      if (e.kind == ServerEvent::kRefused && e.key == key) return true;
    return false;
  }
  int Count(ServerEvent::Kind kind) const {
    int n = 0;
    for (const ServerEvent& e : events) n += e.kind == kind;
    return n;
  }
  Hl2ssServer server;
  ServerHandlers handlers;
  Decision decision;
  std::vector<std::tuple<int, PortKind, StreamConfig>> configured;
  std::vector<ServerEvent> events;
};

// Reads exactly n bytes (or fewer when the peer closes), pumping the server meanwhile.
std::vector<uint8_t> ReadN(Harness* h, int fd, size_t n) {
  std::vector<uint8_t> got;
  h->PumpUntil(
      [&] {
        uint8_t b[65536];
        const ssize_t k = recv(fd, b, std::min(sizeof(b), n - got.size()), MSG_DONTWAIT);
        if (k > 0) got.insert(got.end(), b, b + k);
        return got.size() == n || k == 0;
      },
      {fd});
  return got;
}

// True once the peer closed fd (recv returns 0), pumping the server meanwhile.
bool Closed(Harness* h, int fd) {
  return h->PumpUntil(
      [&] {
        uint8_t b[4096];
        return recv(fd, b, sizeof(b), MSG_DONTWAIT) == 0;
      },
      {fd});
}

const std::vector<uint8_t> kPvRaw720 = {0x01, 0x00, 0x05, 0xd0, 0x02, 0x1e, 0x01,
                                        0xff, 0xff, 0x00, 0x00, 0x10, 0x00, 0x00};  // no encoder options

TEST(Hl2ssServer, ConfigurationInPiecesThenThePacketsSent) {
  Harness h;
  const int fd = Connect(h.server.port(PortKind::kPv));
  SendAll(fd, std::vector<uint8_t>(kPvRaw720.begin(), kPvRaw720.begin() + 5));
  for (int i = 0; i < 20; ++i) h.server.Poll(0, h.handlers);  // half a configuration: nothing yet
  ASSERT_TRUE(h.configured.empty());
  SendAll(fd, std::vector<uint8_t>(kPvRaw720.begin() + 5, kPvRaw720.end()));
  ASSERT_TRUE(h.PumpUntil([&] { return !h.configured.empty(); }));
  ASSERT_EQ(h.configured.size(), 1u);
  const PvConfig& c = std::get<PvConfig>(std::get<2>(h.configured[0]));
  EXPECT_EQ(c.width, 1280);
  EXPECT_EQ(c.bitrate, 0x100000u);
  const auto serving = h.server.Serving(PortKind::kPv);
  ASSERT_EQ(serving.size(), 1u);
  const std::vector<uint8_t> packet = PackPacket(99, std::vector<uint8_t>(100000, 7), nullptr);
  ASSERT_TRUE(h.server.Send(serving[0].first, packet, h.handlers.on_event));
  EXPECT_EQ(ReadN(&h, fd, packet.size()), packet);
  close(fd);
  ASSERT_TRUE(h.PumpUntil([&] { return h.Count(ServerEvent::kDisconnected) == 1; }));
}

TEST(Hl2ssServer, HostileClientsAreRefusedWhileAnotherKeepsReceiving) {
  Harness h;
  const int si = Connect(h.server.port(PortKind::kSi));
  ASSERT_TRUE(h.PumpUntil([&] { return h.server.Serving(PortKind::kSi).size() == 1; }));
  const int si_id = h.server.Serving(PortKind::kSi)[0].first;
  const std::vector<uint8_t> packet = PackPacket(1, {1, 2, 3}, nullptr);

  const int garbage = Connect(h.server.port(PortKind::kPv));
  SendAll(garbage, {0xF3, 0x00, 0x11});
  EXPECT_TRUE(Closed(&h, garbage));
  EXPECT_TRUE(h.Refused("pv/mode"));

  const int rc = Connect(h.server.port(PortKind::kRc));
  SendAll(rc, {0x00, 0x7F});  // a good command, then an unknown one
  EXPECT_EQ(ReadN(&h, rc, 2), (std::vector<uint8_t>{0x00, 0x42}));
  EXPECT_TRUE(Closed(&h, rc));
  EXPECT_TRUE(h.Refused("rc/unknown"));

  const int talker = Connect(h.server.port(PortKind::kSi));  // SI takes no bytes
  SendAll(talker, {0x01});
  EXPECT_TRUE(Closed(&h, talker));
  EXPECT_TRUE(h.Refused("si/unexpected"));

  const int a = Connect(h.server.port(PortKind::kRmDepthLongThrow));
  const int b = Connect(h.server.port(PortKind::kRmDepthLongThrow));
  const int c = Connect(h.server.port(PortKind::kRmDepthLongThrow));  // max_clients = 2
  EXPECT_TRUE(Closed(&h, c));
  EXPECT_TRUE(h.Refused("rm_depth/clients"));
  // a and b never configure: refused once the timeout (5 s of the server's clock) passes.
  h.PumpUntil([] { return true; }, {}, 6'000'000);
  EXPECT_TRUE(Closed(&h, a));
  EXPECT_TRUE(Closed(&h, b));
  EXPECT_TRUE(h.Refused("rm_depth/timeout"));

  ASSERT_TRUE(h.server.Send(si_id, packet, h.handlers.on_event)) << "the SI client is still served";
  EXPECT_EQ(ReadN(&h, si, packet.size()), packet);
  for (int fd : {si, garbage, rc, talker, a, b, c}) close(fd);
}

TEST(Hl2ssServer, AClientThatStopsReadingLosesPacketsThenIsClosed) {
  ServerOptions o = Harness::Options();
  o.max_queue_packets = 2;
  o.max_consecutive_drops = 5;
  Harness h(o);
  const int stuck = Connect(h.server.port(PortKind::kSi), 4096);  // never reads
  const int reader = Connect(h.server.port(PortKind::kSi));
  ASSERT_TRUE(h.PumpUntil([&] { return h.server.Serving(PortKind::kSi).size() == 2; }));
  const std::vector<uint8_t> packet = PackPacket(5, std::vector<uint8_t>(1 << 20, 9), nullptr);
  int delivered = 0;
  for (int i = 0; i < 60 && h.Count(ServerEvent::kStalled) == 0; ++i) {
    for (const auto& [id, config] : h.server.Serving(PortKind::kSi))
      h.server.Send(id, packet, h.handlers.on_event);
    const std::vector<uint8_t> got = ReadN(&h, reader, packet.size());
    ASSERT_EQ(got, packet);
    ++delivered;
  }
  EXPECT_EQ(h.Count(ServerEvent::kStalled), 1);
  EXPECT_GE(h.Count(ServerEvent::kDropped), 5);
  EXPECT_TRUE(Closed(&h, stuck));
  EXPECT_EQ(h.server.Serving(PortKind::kSi).size(), 1u) << "the reader is still served";
  EXPECT_GT(delivered, 5);
  close(stuck);
  close(reader);
}

TEST(Hl2ssServer, AnIdleRcClientStaysAndAHalfCommandTimesOut) {
  Harness h;
  const int idle = Connect(h.server.port(PortKind::kRc));
  const int half = Connect(h.server.port(PortKind::kRc));
  ASSERT_TRUE(h.PumpUntil([&] { return h.Count(ServerEvent::kConnected) == 2; }));
  SendAll(half, {0x04, 0x03, 0x00});  // pv_set_focus, 2 of its 21 bytes
  for (int i = 0; i < 20; ++i) h.server.Poll(1'000'000, h.handlers);
  h.PumpUntil([] { return true; }, {}, 7'000'000);  // 6 s after the half command began
  EXPECT_TRUE(Closed(&h, half));
  EXPECT_TRUE(h.Refused("rc/timeout"));
  SendAll(idle, {0x00});  // idle for 7 s: still answered
  EXPECT_EQ(ReadN(&h, idle, 2), (std::vector<uint8_t>{0x00, 0x42}));
  close(idle);
  close(half);
}

TEST(Hl2ssServer, ReplyAndCloseSendsTheAnswerFirst) {
  Harness h;
  h.decision.kind = Decision::kReplyAndClose;
  h.decision.reply = {1, 2, 3, 4};
  const int fd = Connect(h.server.port(PortKind::kPv));
  SendAll(fd, {0x02, 0x00, 0x05, 0xd0, 0x02, 0x1e});  // mode 2, 1280x720 at 30
  EXPECT_EQ(ReadN(&h, fd, 4), (std::vector<uint8_t>{1, 2, 3, 4}));
  EXPECT_TRUE(Closed(&h, fd));
  close(fd);
}

TEST(Hl2ssServer, APortTakenIsAnErrorNamingIt) {
  Harness h;
  ServerOptions o = Harness::Options();
  o.ports = {{PortKind::kPv, h.server.port(PortKind::kPv)}};
  try {
    Hl2ssServer second(o);
    FAIL() << "two servers on one port";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("(pv)"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace orbed::hl2ss
