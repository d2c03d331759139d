// orbed-hmd as a process at full rates (HMD_POSE + HMD_POSE_TRUTH 60 Hz, HMD_CAMERA 30 Hz,
// REFLECTIVE_VIEW 30 Hz for one display, AR_VIEW 5 Hz, GAZE_RAY 10 Hz) beside orbed-iiwa-sim
// (200 Hz), for ORBED_BENCH_SECONDS (default 30) s each, in two situations:
//   BM_HmdStandingArmAtRest  the shipped walk (2 s at the foot end, 2.8 s walking, then standing at
//                            the head end) with the arm at rest: after the walk every camera frame
//                            has the inputs of the one before and its JPEG is reused;
//   BM_HmdWalkingArmMoving   hmd_emulator/config/walk_loop.yaml (walking back and forth around the
//                            robot, 0.5 s dwells) while a client moves the arm between two
//                            configurations every 1.5 s: nearly every frame is rendered anew.
// A subscriber (8 MB receive buffer) counts HMD_POSE and HMD_CAMERA and takes HMD_POSE's
// inter-arrival times from LCM's receive stamps. Reported: orbed-hmd's CPU share of one core
// (user + system from wait4 over its wall time), its peak RSS [MB] (goal <= 400 MB), the received
// rates, and the HMD_POSE jitter: percentiles of |inter-arrival − 1/60 s| [ms].
// Run in a private network namespace: scripts/orbed bench hmd_bench.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>
#include "base/source_paths.h"

#include <benchmark/benchmark.h>
#include <lcm/lcm-cpp.hpp>
#include <orbed/iiwa_command_t.hpp>

#include "base/units.h"
#include "runtime/flags.h"
#include "tests/bench/bench_util.h"

namespace {

using orbed::bench::BinDir;
using orbed::bench::Spawn;
using orbed::bench::StopAndMeasure;
using orbed::bench::Usage;
using Clock = std::chrono::steady_clock;

struct Counter {
  std::vector<int64_t> pose_recv_utime;
  int64_t cameras = 0, reflective = 0;
  void OnPose(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    pose_recv_utime.push_back(rbuf->recv_utime);
  }
  void OnCamera(const lcm::ReceiveBuffer*, const std::string&) { ++cameras; }
  void OnReflective(const lcm::ReceiveBuffer*, const std::string&) { ++reflective; }
};

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(std::ceil(p * v.size())) - (p > 0 ? 1 : 0));
  return v[k];
}

void RunHmd(benchmark::State& state, bool walking_and_moving) {
  const char* seconds_env = std::getenv("ORBED_BENCH_SECONDS");
  const double seconds = seconds_env ? std::atof(seconds_env) : 30.0;
  Usage usage;
  double wall_s = 0;
  Counter counter;
  for (auto _ : state) {
    lcm::LCM lcm(orbed::WithRecvBufSize(orbed::DefaultLcmUrl(), 8 << 20));
    lcm.subscribe("HMD_POSE", &Counter::OnPose, &counter);
    lcm.subscribe("HMD_CAMERA", &Counter::OnCamera, &counter);
    lcm.subscribe("REFLECTIVE_VIEW", &Counter::OnReflective, &counter);
    const pid_t sim = Spawn({BinDir() + "/orbed-iiwa-sim", "--name", "hmd_bench_sim", "--log-level", "warn",
                             "--initial-q-deg", "0,30,0,-60,0,45,0"});
    std::vector<std::string> argv{
        BinDir() + "/orbed-hmd", "--name", "hmd_bench", "--log-level", "warn", "--displays", "1"};
    if (walking_and_moving) {
      argv.push_back("--config");
      argv.push_back(orbed::SourceDir() + "/hmd_emulator/config/walk_loop.yaml");
    }
    const auto spawned = Clock::now();
    const pid_t hmd = Spawn(argv);
    while (counter.cameras == 0 && Clock::now() - spawned < std::chrono::seconds(20)) lcm.handleTimeout(50);
    counter = Counter{};
    const std::vector<std::vector<double>> targets{{0, 30, 0, -60, 0, 45, 0}, {40, 20, -30, -80, 20, 50, 30}};
    size_t next_target = 1;
    const auto start = Clock::now();
    auto next_command = start;
    while (Clock::now() - start < std::chrono::duration<double>(seconds)) {
      if (walking_and_moving && Clock::now() >= next_command) {
        orbed::iiwa_command_t cmd{};
        cmd.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                        std::chrono::system_clock::now().time_since_epoch())
                        .count();
        cmd.num_joints = 7;
        for (double q : targets[next_target++ % targets.size()])
          cmd.joint_position.push_back(q * orbed::kDegToRad);
        cmd.num_torques = 0;
        lcm.publish("IIWA_COMMAND", &cmd);
        next_command += std::chrono::milliseconds(1500);
      }
      lcm.handleTimeout(10);
    }
    usage = StopAndMeasure(hmd);
    wall_s = std::chrono::duration<double>(Clock::now() - spawned).count();
    StopAndMeasure(sim);
    state.SetIterationTime(seconds);
  }
  std::vector<double> jitter_ms, interval_ms;
  for (size_t k = 1; k < counter.pose_recv_utime.size(); ++k) {
    const double dt_ms = (counter.pose_recv_utime[k] - counter.pose_recv_utime[k - 1]) * 1e-3;
    interval_ms.push_back(dt_ms);
    jitter_ms.push_back(std::abs(dt_ms - 1000.0 / 60.0));
  }
  const double cpu_pct = 100.0 * usage.cpu_s / wall_s;
  state.counters["cpu_share_pct"] = cpu_pct;
  state.counters["cpu_s"] = usage.cpu_s;
  state.counters["wall_s"] = wall_s;
  state.counters["peak_rss_mb"] = usage.peak_rss_mb;
  state.counters["pose_rate_hz"] = counter.pose_recv_utime.size() / seconds;
  state.counters["camera_rate_hz"] = counter.cameras / seconds;
  state.counters["reflective_rate_hz"] = counter.reflective / seconds;
  state.counters["pose_jitter_p50_ms"] = Percentile(jitter_ms, 0.50);
  state.counters["pose_jitter_p99_ms"] = Percentile(jitter_ms, 0.99);
  state.counters["pose_interval_max_ms"] = Percentile(interval_ms, 1.0);
  state.counters["exit_code"] = usage.exit_code;
  state.counters["rss_goal_met"] = usage.peak_rss_mb <= 400.0 ? 1 : 0;
}

void BM_HmdStandingArmAtRest(benchmark::State& state) { RunHmd(state, false); }
void BM_HmdWalkingArmMoving(benchmark::State& state) { RunHmd(state, true); }
BENCHMARK(BM_HmdStandingArmAtRest)->Iterations(1)->UseManualTime()->Unit(benchmark::kSecond);
BENCHMARK(BM_HmdWalkingArmMoving)->Iterations(1)->UseManualTime()->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
