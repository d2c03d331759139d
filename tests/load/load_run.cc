#include "tests/load/load_run.h"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <thread>

#include <lcm/lcm-cpp.hpp>
#include <orbed/hmd_pose_t.hpp>
#include <orbed/image_t.hpp>
#include <orbed/process_status_t.hpp>

#include "base/proc_stats.h"
#include "base/source_paths.h"
#include "lcmtypes/bounded_decode.h"
#include "lcmtypes/contract/channels.h"
#include "lcmtypes/contract/conversions.h"
#include "procs/launcher/child.h"
#include "procs/launcher/launch_file.h"
#include "procs/logger/manifest.h"
#include "runtime/flags.h"

namespace orbed::load {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr char kLcmSelfTest[] = "LCM_SELF_TEST";
// The launch files' name of orbed-logger, whose account RunLoad checks.
constexpr char kLoggerName[] = "logger";
// Every process hears every datagram, images included; so does the watcher.
constexpr int64_t kWatcherRecvBufBytes = 16 << 20;
constexpr int kWatcherQueueCapacity = 100000;

// Every message on the bus: counts per channel, hmd_pose_t seq, and a Snapshot per heartbeat of a
// watched process. Handles LCM on its own thread.
class BusWatcher {
 public:
  BusWatcher(std::set<std::string> watched, const LoadPlan& plan)
      : watched_(std::move(watched)), lcm_(WithRecvBufSize(DefaultLcmUrl(), kWatcherRecvBufBytes)) {
    if (!lcm_.good()) throw std::runtime_error("orbed-load: cannot open LCM (is there a multicast route?)");
    for (const StreamSpec& stream : plan.streams) {
      if (stream.has_seq) seq_channels_.insert(stream.channel);
      if (stream.latency) latencies_[stream.channel];
    }
    lcm::Subscription* all = lcm_.subscribe(".*", &BusWatcher::OnMessage, this);
    all->setQueueCapacity(kWatcherQueueCapacity);
    thread_ = std::thread([this] {
      while (!stop_) lcm_.handleTimeout(20);
    });
  }
  ~BusWatcher() {
    stop_ = true;
    thread_.join();
  }

  struct Beat {
    orbed::process_status_t status;
    Snapshot snapshot;
  };
  std::vector<Beat> Beats(const std::string& name) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = beats_.find(name);
    return it == beats_.end() ? std::vector<Beat>{} : it->second;
  }
  /// A latency stream's (receive utime, capture-to-receive latency [ms]) per frame.
  std::vector<std::pair<int64_t, double>> Latencies(const std::string& channel) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = latencies_.find(channel);
    return it == latencies_.end() ? std::vector<std::pair<int64_t, double>>{} : it->second;
  }
  int64_t self_tests() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return self_tests_;
  }

 private:
  void OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (channel == kLcmSelfTest) {
      // LCM's start-up probe of each new instance. The logger takes (and counts in messages_in)
      // those sent after it subscribed, i.e. after its first heartbeat: count the same ones.
      if (beats_.count(kLoggerName) > 0) ++self_tests_;
      return;
    }
    ChannelCount& count = counts_[channel];
    ++count.received;
    if (seq_channels_.count(channel) > 0) {
      orbed::hmd_pose_t pose;
      if (DecodeBounded(rbuf->data, rbuf->data_size, &pose).ok()) count.last_seq = pose.seq;
    } else if (const auto latency = latencies_.find(channel); latency != latencies_.end()) {
      orbed::image_t image;
      if (DecodeBounded(rbuf->data, rbuf->data_size, &image).ok()) {
        latency->second.emplace_back(rbuf->recv_utime,
                                     static_cast<double>(rbuf->recv_utime - image.utime) / 1e3);
      }
    } else if (channel == channels::kProcessStatus) {
      orbed::process_status_t status;
      if (!DecodeBounded(rbuf->data, rbuf->data_size, &status).ok() || watched_.count(status.name) == 0)
        return;
      Snapshot snapshot;
      snapshot.utime_us = status.utime;
      for (int i = 0; i < status.num_drop_reasons; ++i)
        snapshot.drops[status.drop_reason[i]] = status.drop_count[i];
      snapshot.counts = counts_;
      beats_[status.name].push_back({status, std::move(snapshot)});
    }
  }

  const std::set<std::string> watched_;
  lcm::LCM lcm_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  mutable std::mutex mutex_;
  std::map<std::string, ChannelCount> counts_;      // guarded by mutex_
  std::map<std::string, std::vector<Beat>> beats_;  // guarded by mutex_
  std::set<std::string> seq_channels_;              // const after construction
  // Keys const after construction; the frames guarded by mutex_.
  std::map<std::string, std::vector<std::pair<int64_t, double>>> latencies_;
  int64_t self_tests_{0};  // guarded by mutex_
};

Clock::time_point After(Clock::time_point t, double seconds) {
  return t + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

// Polls `condition` every 20 ms (draining the launcher's output) until true or `deadline`.
bool PollUntil(launcher::Child& launcher, const std::function<bool()>& condition,
               Clock::time_point deadline) {
  for (;;) {
    launcher.Drain("");
    if (condition()) return true;
    if (Clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

std::string DefaultBinDir() {
  std::error_code ec;
  return fs::read_symlink("/proc/self/exe", ec).parent_path().string();
}

}  // namespace

LoadReport RunLoad(const LoadOptions& options, std::ostream& log) {
  const bool scale = options.arms > 0 || options.headsets > 0;
  const LoadPlan plan =
      scale ? MakeScalePlan(options.arms, options.headsets, options.factor) : MakeLoadPlan(options.factor);
  if (scale && !options.launch_file.empty())
    throw std::invalid_argument(
        "the scale launch is written by orbed-load: no --launch-file with --arms/--headsets");
  if (!(options.duration_s > 0)) throw std::invalid_argument("--duration-s must be > 0");
  if (!(options.rss_early_s > 0 && options.rss_early_s < options.duration_s))
    throw std::invalid_argument("--rss-early-s must be > 0 and less than --duration-s");
  if (!(options.warmup_s >= 0 && options.warmup_s < options.duration_s))
    throw std::invalid_argument("--warmup-s must be >= 0 and less than --duration-s");
  if (options.log_dir.empty()) throw std::invalid_argument("a log folder is needed (--log-dir)");
  fs::create_directories(options.log_dir);
  std::string launch_file =
      options.launch_file.empty() ? SourceTreePath("scripts/launch/load.yaml") : options.launch_file;
  if (scale) {
    launch_file = (fs::path(options.log_dir) / "scale.yaml").string();
    std::ofstream out(launch_file);
    out << plan.ScaleLaunchYaml();
    if (!out) throw std::runtime_error("cannot write " + launch_file);
  }
  const std::string bin_dir = options.bin_dir.empty() ? DefaultBinDir() : options.bin_dir;

  const std::string hmd_config = (fs::path(options.log_dir) / "load_hmd.yaml").string();
  {
    std::ofstream out(hmd_config);
    out << plan.HmdConfigYaml();
    if (!out) throw std::runtime_error("cannot write " + hmd_config);
  }
  std::map<std::string, std::string> env = plan.LaunchEnvironment(hmd_config);
  env["ORBED_LOG_DIR"] = options.log_dir;
  env["ORBED_SOURCE_DIR"] = SourceDir();
  std::map<std::string, std::string> expand = launcher::CurrentEnvironment();
  for (const auto& [key, value] : env) expand[key] = value;
  const launcher::LaunchSpec spec = launcher::LoadLaunchFile(launch_file, expand);
  std::vector<std::string> names;
  for (const auto& group : spec.groups) {
    for (const auto& process : group.processes) names.push_back(process.name);
  }

  BusWatcher watcher(std::set<std::string>(names.begin(), names.end()), plan);
  const int64_t watcher_drops_before = UdpReceiveDrops(getpid());
  launcher::Child launcher;
  std::string error;
  if (!launcher.Start({bin_dir + "/orbed-launch", launch_file}, env, bin_dir, &error)) {
    throw std::runtime_error("cannot start orbed-launch: " + error);
  }
  log << "load: " << spec.name << " (" << launch_file << ") at " << plan.factor
      << " x nominal rates; logs in " << options.log_dir << "\n";

  // Ready: every process heartbeats RUNNING from the pid the launcher started it with.
  std::map<std::string, pid_t> children;
  auto running_from = [&](const std::string& name, pid_t pid) {
    for (const auto& beat : watcher.Beats(name)) {
      if (beat.status.pid == pid && beat.status.state == orbed::process_status_t::STATE_RUNNING) return true;
    }
    return false;
  };
  const bool ready = PollUntil(
      launcher,
      [&] {
        if (!launcher.running() || launcher.Poll()) return true;
        children = ChildrenByName(launcher.pid());
        for (const auto& name : names) {
          if (children.count(name) == 0 || !running_from(name, children[name])) return false;
        }
        return true;
      },
      After(Clock::now(), options.ready_timeout_s));
  if (!ready || !launcher.running()) {
    launcher.Signal(SIGINT);
    PollUntil(
        launcher, [&] { return launcher.Poll(); }, After(Clock::now(), 30));
    if (launcher.running()) launcher.Signal(SIGKILL);
    throw std::runtime_error(
        ready ? "orbed-launch ended before the testbed was ready: " + launcher.DescribeExit()
              : "the testbed was not ready within " + std::to_string(options.ready_timeout_s) + " s");
  }
  const Clock::time_point start = Clock::now();
  // Heartbeat utimes are wall-clock: the window's bounds on that clock.
  const int64_t warm_utime = NowMicros() + std::llround(options.warmup_s * 1e6);
  log << "load: every process is ready; running for " << options.duration_s << " s\n";

  LoadReport report;
  report.factor = plan.factor;
  report.duration_s = options.duration_s;
  report.rss_early_s = options.rss_early_s;
  report.arms = plan.arms;
  report.headsets = plan.headsets;
  std::map<std::string, ProcessRow> rows;
  for (const auto& name : names) rows[name].name = name;
  // The run: deadlines only; the early sample, then the end (or orbed-launch ending by itself).
  PollUntil(
      launcher, [&] { return !launcher.running() || launcher.Poll(); }, After(start, options.rss_early_s));
  std::map<std::string, double> cpu_early_s;
  for (auto& [name, row] : rows) {
    row.rss_early_kb = ProcStatusKb(children[name], "VmRSS");
    cpu_early_s[name] = ProcCpuSeconds(children[name]);
  }
  const double watcher_cpu_early_s = ProcCpuSeconds(getpid());
  const Clock::time_point early = Clock::now();
  log << "load: resident memory sampled at " << options.rss_early_s << " s\n";
  PollUntil(
      launcher, [&] { return !launcher.running() || launcher.Poll(); }, After(start, options.duration_s));
  const Clock::time_point end = Clock::now();
  const int64_t end_utime = NowMicros();
  const std::map<std::string, pid_t> children_at_end =
      launcher.running() ? ChildrenByName(launcher.pid()) : std::map<std::string, pid_t>{};
  for (auto& [name, row] : rows) {
    const pid_t pid = children[name];
    const auto it = children_at_end.find(name);
    row.alive_at_end = it != children_at_end.end() && it->second == pid;
    row.rss_end_kb = row.alive_at_end ? ProcStatusKb(pid, "VmRSS") : -1;
    row.socket_drops = row.alive_at_end ? UdpReceiveDrops(pid) : -1;
    const double cpu_end_s = row.alive_at_end ? ProcCpuSeconds(pid) : -1;
    if (cpu_end_s >= 0 && cpu_early_s[name] >= 0 && end > early)
      row.cpu_percent =
          100 * (cpu_end_s - cpu_early_s[name]) / std::chrono::duration<double>(end - early).count();
  }
  if (end > early && watcher_cpu_early_s >= 0) {
    report.watcher_cpu_percent = 100 * (ProcCpuSeconds(getpid()) - watcher_cpu_early_s) /
                                 std::chrono::duration<double>(end - early).count();
  }
  report.watcher_socket_drops = UdpReceiveDrops(getpid()) - watcher_drops_before;
  log << "load: " << std::chrono::duration<double>(end - start).count() << " s done; stopping the testbed\n";

  launcher.Signal(SIGINT);
  if (!PollUntil(
          launcher, [&] { return launcher.Poll(); }, After(Clock::now(), 90))) {
    launcher.Signal(SIGKILL);
    PollUntil(
        launcher, [&] { return launcher.Poll(); }, After(Clock::now(), 10));
  }
  launcher.Drain("", true);
  report.launcher_exit_code = launcher.exit_code() != 0 ? launcher.exit_code() : launcher.term_signal();
  report.launcher_exit = launcher.DescribeExit();

  // The logger's final heartbeat (STOPPING) precedes its exit, which precedes orbed-launch's: it is
  // on its way to the watcher or there already.
  auto final_beat = [&](const std::string& name) -> std::optional<orbed::process_status_t> {
    const auto beats = watcher.Beats(name);
    for (auto it = beats.rbegin(); it != beats.rend(); ++it) {
      if (it->status.pid == children[name] && it->status.state != orbed::process_status_t::STATE_RUNNING)
        return it->status;
    }
    return std::nullopt;
  };
  if (rows.count(kLoggerName) > 0) {
    PollUntil(
        launcher, [&] { return final_beat(kLoggerName).has_value(); }, After(Clock::now(), 5));
    const auto beat = final_beat(kLoggerName);
    const fs::path manifest_path = fs::path(options.log_dir) / "manifest.json";
    if (beat && fs::exists(manifest_path)) {
      const logger::Manifest manifest = logger::ReadManifestFile(manifest_path.string());
      report.logger.known = manifest.parts.size() == 1;  // a respawned logger's parts overlap its restart
      report.logger.messages_in = beat->messages_in;
      report.logger.events_written = manifest.events();
      report.logger.drops = manifest.drops();
      report.logger.self_tests = watcher.self_tests();
    }
  }

  // Per process: respawns (distinct pids on the heartbeats) and the last drop counters; per stream:
  // the window from its publisher's first heartbeat after the warm-up to its last RUNNING one
  // before the end.
  for (auto& [name, row] : rows) {
    const auto beats = watcher.Beats(name);
    std::set<int32_t> pids;
    for (const auto& beat : beats) pids.insert(beat.status.pid);
    row.respawns = pids.empty() ? 0 : static_cast<int>(pids.size()) - 1;
    for (auto it = beats.rbegin(); it != beats.rend(); ++it) {
      if (it->status.pid != children[name]) continue;
      row.dropped = it->status.dropped;
      row.drop_counts = it->snapshot.drops;
      break;
    }
  }
  for (const StreamSpec& stream : plan.streams) {
    const auto beats = watcher.Beats(stream.publisher);
    const pid_t pid = children[stream.publisher];
    const Snapshot* first = nullptr;
    const Snapshot* last = nullptr;
    for (const auto& beat : beats) {
      if (beat.status.pid != pid || beat.status.state != orbed::process_status_t::STATE_RUNNING) continue;
      if (beat.status.utime > end_utime) break;
      if (!first && beat.status.utime >= warm_utime) first = &beat.snapshot;
      if (first) last = &beat.snapshot;
    }
    if (first && last && last->utime_us > first->utime_us)
      report.streams.push_back(AccountStream(stream, *first, *last));
  }
  for (const StreamSpec& stream : plan.streams) {
    if (!stream.latency) continue;
    std::vector<double> in_window;
    for (const auto& [recv_utime, latency_ms] : watcher.Latencies(stream.channel)) {
      if (recv_utime >= warm_utime && recv_utime <= end_utime) in_window.push_back(latency_ms);
    }
    report.latencies.push_back(SummarizeLatency(stream.channel, in_window));
  }
  for (const auto& name : names) report.processes.push_back(rows[name]);
  return report;
}

}  // namespace orbed::load
