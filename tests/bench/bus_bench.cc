// Bus latency: a 412-byte message publish→receive over LCM (udpm, loopback, ttl=0) beside a raw
// UDP multicast ping-pong on the same loopback in the same run. One-way latency = round trip / 2,
// measured by a ping thread and an echo thread. Reports median and p99 [us] and the LCM/raw
// ratio. Run inside a private network namespace: scripts/orbed bench bus_bench.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <thread>
#include <vector>

#include <benchmark/benchmark.h>
#include <lcm/lcm-cpp.hpp>

namespace {

constexpr int kPayloadBytes = 412;
constexpr int kPings = 3000;
using Clock = std::chrono::steady_clock;

struct Percentiles {
  double median_us, p99_us;
};

Percentiles Summarise(std::vector<double> one_way_us) {
  std::sort(one_way_us.begin(), one_way_us.end());
  return {one_way_us[one_way_us.size() / 2], one_way_us[one_way_us.size() * 99 / 100]};
}

// ---- LCM ----------------------------------------------------------------------------------
class LcmEcho {
 public:
  void OnPing(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    lcm_->publish("BENCH_PONG", rbuf->data, rbuf->data_size);
  }
  lcm::LCM* lcm_;
};

class LcmPinger {
 public:
  void OnPong(const lcm::ReceiveBuffer*, const std::string&) { got_ = true; }
  bool got_ = false;
};

Percentiles MeasureLcm() {
  lcm::LCM ping_lcm("udpm://239.255.76.67:7667?ttl=0");
  lcm::LCM echo_lcm("udpm://239.255.76.67:7667?ttl=0");
  if (!ping_lcm.good() || !echo_lcm.good()) throw std::runtime_error("LCM unavailable");
  LcmEcho echo{&echo_lcm};
  LcmPinger pinger;
  echo_lcm.subscribe("BENCH_PING", &LcmEcho::OnPing, &echo);
  ping_lcm.subscribe("BENCH_PONG", &LcmPinger::OnPong, &pinger);
  std::atomic<bool> stop{false};
  std::thread echo_thread([&] {
    while (!stop) echo_lcm.handleTimeout(50);
  });
  std::vector<char> payload(kPayloadBytes, 'x');
  std::vector<double> samples;
  for (int i = 0; i < kPings + 100; ++i) {
    pinger.got_ = false;
    const auto t0 = Clock::now();
    ping_lcm.publish("BENCH_PING", payload.data(), kPayloadBytes);
    while (!pinger.got_) {
      if (ping_lcm.handleTimeout(1000) <= 0) break;  // lost: skip this sample
    }
    const double rtt_us = std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
    if (pinger.got_ && i >= 100) samples.push_back(rtt_us / 2);  // first 100 warm up
  }
  stop = true;
  echo_thread.join();
  return Summarise(samples);
}

// ---- raw UDP multicast ---------------------------------------------------------------------
int MulticastSocket(const char* group, int port) {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  const int one = 1;
  setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  addr.sin_addr.s_addr = htonl(INADDR_ANY);
  if (bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0) {
    throw std::runtime_error("bind failed");
  }
  ip_mreq mreq{};
  inet_pton(AF_INET, group, &mreq.imr_multiaddr);
  mreq.imr_interface.s_addr = htonl(INADDR_ANY);
  setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof(mreq));
  const unsigned char ttl = 0, loop = 1;
  setsockopt(fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof(ttl));
  setsockopt(fd, IPPROTO_IP, IP_MULTICAST_LOOP, &loop, sizeof(loop));
  return fd;
}

sockaddr_in GroupAddress(const char* group, int port) {
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  inet_pton(AF_INET, group, &addr.sin_addr);
  return addr;
}

bool ReceiveWithin(int fd, char* buffer, int size, int timeout_ms) {
  pollfd p{fd, POLLIN, 0};
  if (poll(&p, 1, timeout_ms) <= 0) return false;
  return recv(fd, buffer, size, 0) > 0;
}

Percentiles MeasureRawUdp() {
  const char* kGroup = "239.255.76.68";
  const int kPingPort = 7701, kPongPort = 7702;
  const int ping_rx = MulticastSocket(kGroup, kPongPort);
  const int echo_rx = MulticastSocket(kGroup, kPingPort);
  const sockaddr_in ping_to = GroupAddress(kGroup, kPingPort);
  const sockaddr_in pong_to = GroupAddress(kGroup, kPongPort);
  std::atomic<bool> stop{false};
  std::thread echo_thread([&] {
    char buffer[2048];
    while (!stop) {
      pollfd p{echo_rx, POLLIN, 0};
      if (poll(&p, 1, 50) <= 0) continue;
      const ssize_t n = recv(echo_rx, buffer, sizeof(buffer), 0);
      if (n > 0) {
        sendto(echo_rx, buffer, n, 0, reinterpret_cast<const sockaddr*>(&pong_to), sizeof(pong_to));
      }
    }
  });
  std::vector<char> payload(kPayloadBytes, 'x');
  char buffer[2048];
  std::vector<double> samples;
  for (int i = 0; i < kPings + 100; ++i) {
    const auto t0 = Clock::now();
    sendto(ping_rx, payload.data(), payload.size(), 0, reinterpret_cast<const sockaddr*>(&ping_to),
           sizeof(ping_to));
    const bool got = ReceiveWithin(ping_rx, buffer, sizeof(buffer), 1000);
    const double rtt_us = std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
    if (got && i >= 100) samples.push_back(rtt_us / 2);
  }
  stop = true;
  echo_thread.join();
  close(ping_rx);
  close(echo_rx);
  return Summarise(samples);
}

void BM_BusLatency_LcmVsRawUdp(benchmark::State& state) {
  Percentiles lcm{}, raw{};
  for (auto _ : state) {
    raw = MeasureRawUdp();
    lcm = MeasureLcm();
    state.SetIterationTime(1.0);
  }
  state.counters["raw_median_us"] = raw.median_us;
  state.counters["raw_p99_us"] = raw.p99_us;
  state.counters["lcm_median_us"] = lcm.median_us;
  state.counters["lcm_p99_us"] = lcm.p99_us;
  state.counters["ratio_median"] = lcm.median_us / raw.median_us;
  state.counters["ratio_p99"] = lcm.p99_us / raw.p99_us;
}
BENCHMARK(BM_BusLatency_LcmVsRawUdp)->Iterations(1)->UseManualTime()->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
