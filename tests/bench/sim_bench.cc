// orbed-iiwa-sim as a process at 1 kHz status (--period-s 0.001: IIWA_STATUS, ROBOT_STATE and
// COLLISION_STATUS every millisecond) for ORBED_BENCH_SECONDS (default 30) s, while a client keeps
// it busy: every 1.5 s a new IIWA_COMMAND cycling upright -> a far pose -> upright -> a pose whose
// path runs into the table (the arm stops before it) -> upright ..., so most ticks move the arm
// and run the collision check on a new configuration. The client counts the IIWA_STATUS it
// receives. Reports the sim's CPU share of one core (user + system from wait4, over the wall
// time it ran), its peak RSS [MB] and the received status rate. Goal: <= 25 %, <= 60 MB.
// Run in a private network namespace: scripts/orbed bench sim_bench.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <benchmark/benchmark.h>
#include <lcm/lcm-cpp.hpp>
#include <orbed/iiwa_command_t.hpp>

#include "base/units.h"
#include "tests/bench/bench_util.h"

namespace {

using orbed::bench::BinDir;
using orbed::bench::Spawn;
using orbed::bench::StopAndMeasure;
using orbed::bench::Usage;

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct StatusCounter {
  int64_t count = 0;
  void On(const lcm::ReceiveBuffer*, const std::string&) { ++count; }
};

orbed::iiwa_command_t CommandDeg(const std::vector<double>& q_deg) {
  orbed::iiwa_command_t cmd{};
  cmd.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                  std::chrono::system_clock::now().time_since_epoch())
                  .count();
  cmd.num_joints = 7;
  for (double q : q_deg) cmd.joint_position.push_back(q * orbed::kDegToRad);
  cmd.num_torques = 0;
  return cmd;
}

void BM_IiwaSimAt1kHz(benchmark::State& state) {
  const char* seconds_env = std::getenv("ORBED_BENCH_SECONDS");
  const double seconds = seconds_env ? std::atof(seconds_env) : 30.0;
  const std::vector<std::vector<double>> targets{
      {0, 0, 0, 0, 0, 0, 0},
      {90, -40, 30, -60, 20, 40, 90},  // far, collision-free path
      {0, 0, 0, 0, 0, 0, 0},
      {-30, 80, 0, -30, 0, 60, 0},  // into the table: stops before contact
  };
  Usage usage;
  double wall_s = 0;
  int64_t received = 0;
  for (auto _ : state) {
    lcm::LCM lcm("");
    StatusCounter counter;
    lcm.subscribe("IIWA_STATUS", &StatusCounter::On, &counter);
    const auto spawned = Clock::now();
    const pid_t sim = Spawn(
        {BinDir() + "/orbed-iiwa-sim", "--period-s", "0.001", "--name", "sim_bench", "--log-level", "warn"});
    // Wait for the first status, then measure over `seconds`.
    while (counter.count == 0 && Clock::now() - spawned < std::chrono::seconds(10)) lcm.handleTimeout(50);
    counter.count = 0;
    const auto start = Clock::now();
    size_t next_target = 1;
    auto next_command = start;
    while (Clock::now() - start < std::chrono::duration<double>(seconds)) {
      if (Clock::now() >= next_command) {
        const orbed::iiwa_command_t cmd = CommandDeg(targets[next_target++ % targets.size()]);
        lcm.publish("IIWA_COMMAND", &cmd);
        next_command += std::chrono::milliseconds(1500);
      }
      lcm.handleTimeout(10);
    }
    received = counter.count;
    usage = StopAndMeasure(sim);
    wall_s = std::chrono::duration<double>(Clock::now() - spawned).count();
    state.SetIterationTime(seconds);
  }
  state.counters["cpu_share_pct"] = 100.0 * usage.cpu_s / wall_s;
  state.counters["cpu_s"] = usage.cpu_s;
  state.counters["wall_s"] = wall_s;
  state.counters["peak_rss_mb"] = usage.peak_rss_mb;
  state.counters["status_rate_hz"] = received / seconds;
  state.counters["exit_code"] = usage.exit_code;
  state.counters["goal_met"] = (100.0 * usage.cpu_s / wall_s <= 25.0 && usage.peak_rss_mb <= 60.0) ? 1 : 0;
}
BENCHMARK(BM_IiwaSimAt1kHz)->Iterations(1)->UseManualTime()->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
