#include "tests/load/load_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "base/format.h"
#include "base/json.h"
#include "base/stats.h"
#include "lcmtypes/contract/channels.h"

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

// The plan's rates at `factor` (checked), no streams yet.
LoadPlan ScaledRates(double factor) {
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
  return plan;
}

// The streams of the arm `arm` ("" = the single arm), published by `process`.
void AddArmStreams(LoadPlan* plan, const std::string& arm, const std::string& process) {
  const double sim_hz = 1.0 / plan->sim_period_s;
  for (const char* channel : {channels::kIiwaStatus, channels::kRobotState, channels::kCollisionStatus}) {
    plan->streams.push_back({channels::ForArm(channel, arm), process, kSimHz, sim_hz, {"timer/tick"}, false});
  }
}

// The streams of the headset `headset` ("" = the single one), published by `process`; its timers'
// drop keys carry the channels' names (HmdProcess names each timer by its channel).
void AddHeadsetStreams(LoadPlan* plan, const std::string& headset, const std::string& process) {
  const std::string pose = channels::ForHeadset(channels::kHmdPose, headset);
  for (const char* channel : {channels::kHmdPose, channels::kHmdPoseTruth}) {
    plan->streams.push_back(
        {channels::ForHeadset(channel, headset), process, kPoseHz, plan->pose_hz, {"timer/" + pose}, true});
  }
  auto image = [&](const char* base, double nominal, double wanted, bool latency) {
    const std::string channel = channels::ForHeadset(base, headset);
    plan->streams.push_back(
        {channel, process, nominal, wanted, {"timer/" + channel, channel + "/busy"}, false, latency});
  };
  image(channels::kHmdCamera, kCameraHz, plan->camera_hz, true);
  image(channels::kReflectiveView, kReflectiveHz, plan->reflective_hz, false);
  image(channels::kArView, kArViewHz, plan->ar_view_hz, false);
  const std::string gaze = channels::ForHeadset(channels::kGazeRay, headset);
  plan->streams.push_back({gaze, process, kGazeHz, plan->gaze_hz, {"timer/" + gaze}, false});
}

std::string ArmName(int i) { return "a" + std::to_string(i); }
std::string HeadsetName(int j) { return "h" + std::to_string(j); }

}  // namespace

LoadPlan MakeLoadPlan(double factor) {
  LoadPlan plan = ScaledRates(factor);
  AddArmStreams(&plan, "", "sim");
  AddHeadsetStreams(&plan, "", "hmd");
  return plan;
}

LoadPlan MakeScalePlan(int arms, int headsets, double factor) {
  if (arms < 1 || arms > kMaxScaleArms || headsets < 1 || headsets > kMaxScaleHeadsets) {
    throw std::invalid_argument("the scale launch has 1.." + std::to_string(kMaxScaleArms) + " arms and 1.." +
                                std::to_string(kMaxScaleHeadsets) + " headsets, not " + std::to_string(arms) +
                                " x " + std::to_string(headsets));
  }
  LoadPlan plan = ScaledRates(factor);
  plan.arms = arms;
  plan.headsets = headsets;
  for (int i = 0; i < arms; ++i) AddArmStreams(&plan, ArmName(i), "sim_" + ArmName(i));
  for (int j = 0; j < headsets; ++j) AddHeadsetStreams(&plan, HeadsetName(j), "hmd_" + HeadsetName(j));
  return plan;
}

std::string LoadPlan::ScaleLaunchYaml() const {
  if (arms < 1 || headsets < 1) throw std::logic_error("ScaleLaunchYaml: not a scale plan");
  std::ostringstream y;
  y << "# Written by orbed-load: " << arms << " arm(s) x " << headsets << " headset(s) at " << Number(factor)
    << " x nominal rates (tests/load/load_report.h, MakeScalePlan).\n"
    << "name: scale_" << arms << "x" << headsets << "\n"
    << "groups:\n"
    << "  - name: recording\n"
    << "    processes:\n"
    << "      - name: logger\n"
    << "        command: orbed-logger\n"
    << "        args: [--log-dir, \"${ORBED_LOG_DIR}\"]\n"
    << "        env: {ORBED_CHAOS: \"\"}\n"
    << "        stop_signal: SIGINT\n"
    << "        stop_timeout_s: 10\n"
    << "        respawn: true\n"
    << "  - name: robot\n"
    << "    processes:\n";
  const std::string scene = "\"${ORBED_SOURCE_DIR}/sim/models/scenes/four_arms_or.yaml\"";
  for (int i = 0; i < arms; ++i) {
    y << "      - name: sim_" << ArmName(i) << "\n"
      << "        command: orbed-iiwa-sim\n"
      << "        args: [--scene, " << scene << ", --arm, " << ArmName(i) << ",\n"
      << "               --state-file, \"${ORBED_LOG_DIR}/sim_" << ArmName(i) << ".state\",\n"
      << "               --period-s, \"${ORBED_LOAD_SIM_PERIOD_S}\"]\n"
      << "        stop_signal: SIGINT\n"
      << "        stop_timeout_s: 5\n"
      << "        respawn: true\n";
  }
  y << "  - name: hmd\n"
    << "    processes:\n";
  for (int j = 0; j < headsets; ++j) {
    y << "      - name: hmd_" << HeadsetName(j) << "\n"
      << "        command: orbed-hmd\n"
      << "        args: [--scene, " << scene << ", --headset, " << HeadsetName(j) << ", --arm, "
      << ArmName(j % arms) << ", --user-seed, \"" << j + 1 << "\",\n"
      << "               --state-file, \"${ORBED_LOG_DIR}/hmd_" << HeadsetName(j) << ".state\",\n"
      << "               --pose-hz, \"${ORBED_LOAD_POSE_HZ}\", --camera-hz, \"${ORBED_LOAD_CAMERA_HZ}\",\n"
      << "               --config, \"${ORBED_LOAD_HMD_CONFIG}\"]\n"
      << "        required: true\n"
      << "        stop_signal: SIGINT\n"
      << "        ready_timeout_s: 60\n"
      << "        respawn: true\n";
  }
  y << "  - name: health\n"
    << "    processes:\n"
    << "      - name: monitor\n"
    << "        command: orbed-monitor\n"
    << "        args: [--print-period-s, \"10\"]\n"
    << "        required: false\n"
    << "        respawn: true\n";
  return y.str();
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

LatencyRow SummarizeLatency(const std::string& channel, const std::vector<double>& latencies_ms) {
  LatencyRow row;
  row.channel = channel;
  row.count = static_cast<int64_t>(latencies_ms.size());
  if (latencies_ms.empty()) return row;
  row.p50_ms = stats::Quantile(latencies_ms, 0.5);
  row.p99_ms = stats::Quantile(latencies_ms, 0.99);
  row.max_ms = *std::max_element(latencies_ms.begin(), latencies_ms.end());
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
  std::snprintf(line, sizeof(line), "%-13s %6s %12s %12s %8s %9s %13s %9s  %s\n", "process", "CPU %",
                "RSS@early kB", "RSS@end kB", "growth", "respawns", "socket drops", "dropped",
                "drops by reason (heartbeat)");
  out << line;
  for (const ProcessRow& p : report.processes) {
    const auto growth = p.rss_growth_percent();
    std::string reasons;
    for (const auto& [key, count] : p.drop_counts)
      reasons += (reasons.empty() ? "" : ", ") + key + " " + std::to_string(count);
    std::snprintf(line, sizeof(line), "%-13s %6s %12lld %12lld %7s%% %9d %13lld %9lld  %s\n", p.name.c_str(),
                  p.cpu_percent >= 0 ? Fixed(p.cpu_percent, 1).c_str() : "-",
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
  if (!report.latencies.empty()) {
    out << "\n";
    std::snprintf(line, sizeof(line), "%-17s %9s %9s %9s %9s\n", "capture->receive", "frames", "p50 ms",
                  "p99 ms", "max ms");
    out << line;
    for (const LatencyRow& l : report.latencies) {
      std::snprintf(line, sizeof(line), "%-17s %9lld %9.1f %9.1f %9.1f\n", l.channel.c_str(),
                    static_cast<long long>(l.count), l.p50_ms, l.p99_ms, l.max_ms);
      out << line;
    }
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
      << " datagrams dropped by the kernel, CPU "
      << (report.watcher_cpu_percent >= 0 ? Fixed(report.watcher_cpu_percent, 1) : "-") << " %\n";
}

std::string ReportJson(const LoadReport& report) {
  JsonWriter json(2);
  json.BeginObject();
  json.Key("arms").Int(report.arms);
  json.Key("headsets").Int(report.headsets);
  json.Key("factor").Number(report.factor);
  json.Key("duration_s").Number(report.duration_s);
  json.Key("processes").BeginArray();
  for (const ProcessRow& p : report.processes) {
    json.BeginObject();
    json.Key("name").String(p.name);
    json.Key("cpu_percent").Number(p.cpu_percent >= 0 ? std::optional<double>(p.cpu_percent) : std::nullopt);
    json.Key("rss_end_kb").Int(p.rss_end_kb);
    json.Key("respawns").Int(p.respawns);
    json.Key("alive_at_end").Bool(p.alive_at_end);
    json.Key("socket_drops").Int(p.socket_drops);
    json.Key("dropped").Int(p.dropped);
    json.EndObject();
  }
  json.EndArray();
  json.Key("streams").BeginArray();
  for (const StreamRow& s : report.streams) {
    json.BeginObject();
    json.Key("channel").String(s.spec.channel);
    json.Key("publisher").String(s.spec.publisher);
    json.Key("wanted_hz").Number(s.spec.wanted_hz);
    json.Key("achieved_hz").Number(s.achieved_hz());
    json.Key("wanted").Int(s.wanted);
    json.Key("received").Int(s.received);
    json.Key("drops").Int(s.drops);
    json.Key("lost");
    if (s.lost()) {
      json.Int(*s.lost());
    } else {
      json.Null();
    }
    json.EndObject();
  }
  json.EndArray();
  json.Key("latencies").BeginArray();
  for (const LatencyRow& l : report.latencies) {
    json.BeginObject();
    json.Key("channel").String(l.channel);
    json.Key("count").Int(l.count);
    json.Key("p50_ms").Number(l.p50_ms);
    json.Key("p99_ms").Number(l.p99_ms);
    json.Key("max_ms").Number(l.max_ms);
    json.EndObject();
  }
  json.EndArray();
  json.Key("logger").BeginObject();
  json.Key("known").Bool(report.logger.known);
  json.Key("events_written").Int(report.logger.events_written);
  json.Key("drops").Int(report.logger.drops);
  json.Key("unaccounted").Int(report.logger.unaccounted());
  json.EndObject();
  json.Key("watcher_socket_drops").Int(report.watcher_socket_drops);
  json.Key("watcher_cpu_percent")
      .Number(report.watcher_cpu_percent >= 0 ? std::optional<double>(report.watcher_cpu_percent)
                                              : std::nullopt);
  json.Key("launcher_exit").String(report.launcher_exit);
  json.EndObject();
  return json.str();
}

}  // namespace orbed::load
