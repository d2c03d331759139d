// orbed-logger under the testbed's load, side by side with LCM's own lcm-logger on the same
// traffic in the same run: 200 Hz iiwa_status_t (~412 B), 60 Hz hmd_pose_t, 30 Hz 300 kB
// image-sized messages, for ORBED_BENCH_SECONDS (default 30) s. Both loggers and orbed-monitor
// receive everything. Reports per process: CPU seconds (user + system, from wait4), peak RSS
// [MB], events written and drops (published − written). Run in a private network namespace:
// scripts/orbed bench logger_bench.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <benchmark/benchmark.h>
#include <lcm/lcm-cpp.hpp>
#include <orbed/hmd_pose_t.hpp>
#include <orbed/iiwa_status_t.hpp>
#include <orbed/image_t.hpp>

#include "tests/bench/bench_util.h"

namespace {

using orbed::bench::BinDir;
using orbed::bench::Spawn;
using orbed::bench::StopAndMeasure;
using orbed::bench::Usage;

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

int64_t CountEvents(const std::string& path, const std::string& prefix) {
  lcm::LogFile log(path, "r");
  int64_t n = 0;
  if (!log.good()) return -1;
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    if (e->channel.rfind(prefix, 0) == 0) ++n;
  }
  return n;
}

void BM_LoggerUnderLoad_VsLcmLogger(benchmark::State& state) {
  const char* seconds_env = std::getenv("ORBED_BENCH_SECONDS");
  const double seconds = seconds_env ? std::atof(seconds_env) : 30.0;
  const std::string bin = BinDir();
  const fs::path dir = fs::temp_directory_path() / ("orbed_logger_bench_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const std::string ours = (dir / "orbed.lcmlog").string();
  const std::string theirs = (dir / "lcm.lcmlog").string();
  // Only the load channels (both loggers), so heartbeats do not blur the comparison.
  const std::string channels = "BENCH_.*";

  Usage orbed_usage, lcm_usage, monitor_usage;
  int64_t published = 0, orbed_events = 0, lcm_events = 0;
  for (auto _ : state) {
    const pid_t orbed_logger =
        Spawn({bin + "/orbed-logger", "--file", ours, "--channels", channels, "--log-level", "warn"});
    // The same receive buffer for both (orbed-logger asks for 8 MB itself).
    const pid_t lcm_logger =
        Spawn({"/usr/bin/lcm-logger", "-q", "-f", "-c", channels,
               "--lcm-url=udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608", theirs});
    const pid_t monitor = Spawn({bin + "/orbed-monitor", "--log-level", "warn"});
    std::this_thread::sleep_for(std::chrono::milliseconds(500));

    lcm::LCM lcm("udpm://239.255.76.67:7667?ttl=0");
    orbed::iiwa_status_t status{};
    status.num_joints = 7;
    for (auto* v :
         {&status.joint_position_measured, &status.joint_velocity_estimated, &status.joint_position_commanded,
          &status.joint_position_ipo, &status.joint_torque_measured, &status.joint_torque_commanded,
          &status.joint_torque_external}) {
      v->assign(7, 0.5);
    }
    orbed::hmd_pose_t pose{};
    pose.X_WH.quaternion_wxyz[0] = 1;
    pose.X_WC.quaternion_wxyz[0] = 1;
    orbed::image_t image{};
    image.width = 1280;
    image.height = 720;
    image.pixel_format = orbed::image_t::FORMAT_JPEG;
    image.num_bytes = 300000;
    image.data.assign(300000, 0x5a);
    image.X_WC.quaternion_wxyz[0] = 1;

    const auto start = Clock::now();
    int64_t tick = 0;  // 1200 Hz base tick: status every 6, pose every 20, image every 40
    while (std::chrono::duration<double>(Clock::now() - start).count() < seconds) {
      status.utime = tick;
      if (tick % 6 == 0) {
        lcm.publish("BENCH_IIWA_STATUS", &status);
        ++published;
      }
      if (tick % 20 == 0) {
        pose.seq = tick;
        lcm.publish("BENCH_HMD_POSE", &pose);
        ++published;
      }
      if (tick % 40 == 0) {
        image.utime = tick;
        lcm.publish("BENCH_HMD_CAMERA", &image);
        ++published;
      }
      ++tick;
      std::this_thread::sleep_until(start + std::chrono::microseconds(tick * 1000000 / 1200));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    orbed_usage = StopAndMeasure(orbed_logger);
    lcm_usage = StopAndMeasure(lcm_logger);
    monitor_usage = StopAndMeasure(monitor);
    orbed_events = CountEvents(ours, "BENCH_");
    lcm_events = CountEvents(theirs, "BENCH_");
    state.SetIterationTime(seconds);
  }
  state.counters["published"] = published;
  state.counters["orbed_drops"] = published - orbed_events;
  state.counters["lcm_drops"] = published - lcm_events;
  state.counters["orbed_cpu_s"] = orbed_usage.cpu_s;
  state.counters["lcm_cpu_s"] = lcm_usage.cpu_s;
  state.counters["cpu_ratio"] = orbed_usage.cpu_s / std::max(1e-9, lcm_usage.cpu_s);
  state.counters["orbed_rss_mb"] = orbed_usage.peak_rss_mb;
  state.counters["lcm_rss_mb"] = lcm_usage.peak_rss_mb;
  state.counters["monitor_rss_mb"] = monitor_usage.peak_rss_mb;
  state.counters["monitor_cpu_s"] = monitor_usage.cpu_s;
  fs::remove_all(dir);
}
BENCHMARK(BM_LoggerUnderLoad_VsLcmLogger)->Iterations(1)->UseManualTime()->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
