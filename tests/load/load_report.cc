#include "tests/load/load_report.h"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "base/format.h"
#include "procs/common/channels.h"

namespace orbed::load {
namespace {

// The testbed's nominal rates [Hz] (scripts/launch/testbed.yaml with the shipped configs).
constexpr double kSimHz = 200, kPoseHz = 60, kCameraHz = 30, kGazeHz = 10, kReflectiveHz = 30, kArViewHz = 5;

std::string Number(double value) {
  std::ostringstream text;
  text.precision(10);
  text << value;
  return text.str();
}

int64_t Delta(const std::map<std::string, int64_t>& first, const std::map<std::string, int64_t>& last,
              const std::string& key) {
  const auto a = first.find(key), b = last.find(key);
  return (b == last.end() ? 0 : b->second) - (a == first.end() ? 0 : a->second);
}

}  // namespace

LoadPlan MakeLoadPlan(double factor) {
  if (!(factor >= kMinFactor && factor <= kMaxFactor)) {
    throw std::invalid_argument("the load factor must be in [" + Number(kMinFactor) + ", " +
                                Number(kMaxFactor) + "], not " + Number(factor));
  }
  LoadPlan plan;
  plan.factor = factor;
  // The sim's tick is whole microseconds.
  plan.sim_period_s = std::round(1e6 / (kSimHz * factor)) / 1e6;
  plan.pose_hz = kPoseHz * factor;
  plan.camera_hz = kCameraHz * factor;
  plan.gaze_hz = kGazeHz * factor;
  plan.reflective_hz = kReflectiveHz * factor;
  plan.ar_view_hz = kArViewHz * factor;
  const double sim_hz = 1.0 / plan.sim_period_s;
  for (const char* channel : {channels::kIiwaStatus, channels::kRobotState, channels::kCollisionStatus}) {
    plan.streams.push_back({channel, "sim", kSimHz, sim_hz, {"timer/tick"}, false});
  }
  for (const char* channel : {channels::kHmdPose, channels::kHmdPoseTruth}) {
    plan.streams.push_back(
        {channel, "hmd", kPoseHz, plan.pose_hz, {"timer/" + std::string(channels::kHmdPose)}, true});
  }
  auto image = [&](const std::string& channel, double nominal, double wanted) {
    plan.streams.push_back({channel, "hmd", nominal, wanted, {"timer/" + channel, channel + "/busy"}, false});
  };
  image(channels::kHmdCamera, kCameraHz, plan.camera_hz);
  image(channels::kReflectiveView, kReflectiveHz, plan.reflective_hz);
  image(channels::kArView, kArViewHz, plan.ar_view_hz);
  plan.streams.push_back({channels::kGazeRay,
                          "hmd",
                          kGazeHz,
                          plan.gaze_hz,
                          {"timer/" + std::string(channels::kGazeRay)},
                          false});
  return plan;
}

std::map<std::string, std::string> LoadPlan::LaunchEnvironment(const std::string& hmd_config_path) const {
  return {{"ORBED_LOAD_SIM_PERIOD_S", Number(sim_period_s)},
          {"ORBED_LOAD_POSE_HZ", Number(pose_hz)},
          {"ORBED_LOAD_CAMERA_HZ", Number(camera_hz)},
          {"ORBED_LOAD_HMD_CONFIG", hmd_config_path}};
}

std::string LoadPlan::HmdConfigYaml() const {
  return "# Written by orbed-load: the headset's rates at " + Number(factor) +
         " x nominal (orbed-hmd --config).\n"
         "hmd:\n"
         "  gaze_hz: " +
         Number(gaze_hz) + "\n  reflective_hz: " + Number(reflective_hz) +
         "\n  ar_view_hz: " + Number(ar_view_hz) + "\n";
}

std::optional<int64_t> StreamRow::lost() const {
  if (!sent) return std::nullopt;
  return *sent - received;
}

StreamRow AccountStream(const StreamSpec& spec, const Snapshot& first, const Snapshot& last) {
  StreamRow row;
  row.spec = spec;
  row.window_s = static_cast<double>(last.utime_us - first.utime_us) / 1e6;
  row.wanted = std::llround(spec.wanted_hz * row.window_s);
  const auto a = first.counts.find(spec.channel), b = last.counts.find(spec.channel);
  const ChannelCount none;
  const ChannelCount& c1 = a == first.counts.end() ? none : a->second;
  const ChannelCount& c2 = b == last.counts.end() ? none : b->second;
  row.received = c2.received - c1.received;
  for (const std::string& key : spec.drop_keys) row.drops += Delta(first.drops, last.drops, key);
  if (spec.has_seq && c1.last_seq >= 0 && c2.last_seq >= 0) row.sent = c2.last_seq - c1.last_seq;
  return row;
}

std::optional<double> ProcessRow::rss_growth_percent() const {
  if (rss_early_kb <= 0 || rss_end_kb < 0) return std::nullopt;
  return 100.0 * static_cast<double>(rss_end_kb - rss_early_kb) / static_cast<double>(rss_early_kb);
}

std::vector<std::string> Failures(const LoadReport& report, double max_rss_growth_percent) {
  std::vector<std::string> failures;
  for (const ProcessRow& p : report.processes) {
    if (!p.alive_at_end) failures.push_back(p.name + " died");
    if (p.respawns > 0)
      failures.push_back(p.name + " was respawned " + std::to_string(p.respawns) + " time(s)");
    const auto growth = p.rss_growth_percent();
    if (growth && *growth > max_rss_growth_percent) {
      failures.push_back(p.name + " resident memory grew " + Fixed(*growth, 1) + " % (" +
                         std::to_string(p.rss_early_kb) + " -> " + std::to_string(p.rss_end_kb) +
                         " kB), more than " + Fixed(max_rss_growth_percent, 1) + " %");
    }
    if (p.alive_at_end && !growth) failures.push_back(p.name + ": no resident memory sample");
  }
  if (report.launcher_exit_code != 0) failures.push_back("orbed-launch: " + report.launcher_exit);
  return failures;
}

void PrintReport(const LoadReport& report, std::ostream& out) {
  char line[256];
  out << "load: " << Fixed(report.factor, 1) << " x nominal rates for " << Fixed(report.duration_s, 0)
      << " s; RSS sampled at " << Fixed(report.rss_early_s, 0) << " s and at the end\n";
  std::snprintf(line, sizeof(line), "%-13s %12s %12s %8s %9s %13s %9s  %s\n", "process", "RSS@early kB",
                "RSS@end kB", "growth", "respawns", "socket drops", "dropped", "drops by reason (heartbeat)");
  out << line;
  for (const ProcessRow& p : report.processes) {
    const auto growth = p.rss_growth_percent();
    std::string reasons;
    for (const auto& [key, count] : p.drop_counts)
      reasons += (reasons.empty() ? "" : ", ") + key + " " + std::to_string(count);
    std::snprintf(line, sizeof(line), "%-13s %12lld %12lld %7s%% %9d %13lld %9lld  %s\n", p.name.c_str(),
                  static_cast<long long>(p.rss_early_kb), static_cast<long long>(p.rss_end_kb),
                  growth ? Fixed(*growth, 1).c_str() : "-", p.respawns,
                  static_cast<long long>(p.socket_drops), static_cast<long long>(p.dropped),
                  (p.alive_at_end ? reasons : "DIED " + reasons).c_str());
    out << line;
  }
  out << "\n";
  std::snprintf(line, sizeof(line), "%-17s %8s %8s %10s %7s %9s %9s %9s %9s %7s\n", "channel", "nom Hz",
                "want Hz", "achieved", "window", "wanted", "received", "sent", "lost", "drops");
  out << line;
  for (const StreamRow& s : report.streams) {
    const auto lost = s.lost();
    std::snprintf(line, sizeof(line), "%-17s %8.0f %8.0f %10.1f %6.1fs %9lld %9lld %9s %9s %7lld\n",
                  s.spec.channel.c_str(), s.spec.nominal_hz, s.spec.wanted_hz, s.achieved_hz(), s.window_s,
                  static_cast<long long>(s.wanted), static_cast<long long>(s.received),
                  s.sent ? std::to_string(*s.sent).c_str() : "-", lost ? std::to_string(*lost).c_str() : "-",
                  static_cast<long long>(s.drops));
    out << line;
  }
  if (report.logger.known) {
    out << "\nlogger: " << report.logger.messages_in << " messages in = " << report.logger.events_written
        << " written + " << report.logger.drops << " dropped (queue full) + " << report.logger.self_tests
        << " LCM start-up probes"
        << (report.logger.unaccounted() == 0
                ? ""
                : " + " + std::to_string(report.logger.unaccounted()) + " unaccounted")
        << "\n";
  }
  out << "watcher (orbed-load's own socket): " << report.watcher_socket_drops
      << " datagrams dropped by the kernel\n";
}

}  // namespace orbed::load
