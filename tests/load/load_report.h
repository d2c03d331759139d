#pragma once
/// @file
/// The pure core of orbed-load (the load test): what the testbed is asked to do at F times its
/// nominal rates (LoadPlan), how the messages counted on the bus and the heartbeats' drop counters
/// account for what was wanted (StreamRow), the per-process memory and restart figures
/// (ProcessRow), the verdict and the printed table. No bus, no clock, no /proc: load_run.h feeds it.
///
/// Accounting of a stream, between two heartbeats H1 and H2 of its publisher (utimes u1 < u2 on the
/// publisher's wall clock). The publisher's Process loop runs every periodic task in order with its
/// heartbeat, and one socket delivers them to the watcher in order, so the messages the watcher
/// receives between H1 and H2 are those published between them, less any lost on the way:
///   wanted    = wanted_hz * (u2 - u1)            deadlines of the publisher's timer in the window
///   drops     = sum over the stream's drop keys of (count at H2 - count at H1)
///               (timer deadlines skipped; image requests replaced while the renderer was busy)
///   sent      = seq at H2 - seq at H1            only for streams with a sequence number (hmd_pose_t)
///   received  = watcher's count at H2 - at H1,   achieved_hz = received / (u2 - u1)
///   lost      = sent - received                  lost between publisher and watcher (kernel or LCM)
/// For a timer-driven stream with a sequence, sent + timer drops = wanted up to the timer's catch-up
/// backlog at the two ends (at most 6 deadlines each: Process runs up to 5 late ticks back to back).
/// Image streams are requested by a timer and made by the renderer: their drops are the requests
/// never made, and sent + drops = wanted the same way.
///
/// Scale (the arms x headsets benchmark): MakeScalePlan(A, H) is the testbed with A arms (the
/// scene sim/models/scenes/four_arms_or.yaml, one orbed-iiwa-sim --arm a<i> each, process sim_a<i>)
/// and H headsets (orbed-hmd --headset h<j> --arm a<j mod A>, each a different person, --user-seed
/// j + 1, process hmd_h<j>), every stream on its suffixed channel; ScaleLaunchYaml() is its launch
/// file. Beside rates and drops it measures each camera stream's capture-to-receive latency (the
/// watcher's receive stamp minus the image's sample stamp, both the wall clock of this host) and
/// each process's CPU time.
///
/// Units: rates Hz, times s (utime µs), latency ms, memory kB (/proc's), CPU in percent of one
/// core, counts in messages.

#include <cstdint>
#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace orbed::load {

inline constexpr double kMinFactor = 0.1;
/// HMD_POSE at 60 Hz is capped at 1000 Hz by orbed-hmd (--pose-hz): 16 x 60 = 960.
inline constexpr double kMaxFactor = 16;

/// One stream the load raises.
struct StreamSpec {
  std::string channel;
  std::string publisher;  ///< process name in the launch file
  double nominal_hz{0};   ///< the testbed's default rate
  double wanted_hz{0};    ///< nominal_hz * factor
  /// The publisher's drop keys (process_status_t drop_reason) that count this stream's losses.
  std::vector<std::string> drop_keys;
  bool has_seq{false};  ///< hmd_pose_t.seq: the number sent is known
  bool latency{false};  ///< image_t: its capture-to-receive latency is measured (camera streams)
};

/// The scale launch's limits: the arms of four_arms_or.yaml, and as many headsets as it has room for.
inline constexpr int kMaxScaleArms = 4;
inline constexpr int kMaxScaleHeadsets = 8;

struct LoadPlan {
  double factor{1};
  double sim_period_s{0.005};  ///< orbed-iiwa-sim --period-s (IIWA_STATUS, ROBOT_STATE, COLLISION_STATUS)
  double pose_hz{60};          ///< orbed-hmd --pose-hz
  double camera_hz{30};        ///< orbed-hmd --camera-hz
  double gaze_hz{10};          ///< hmd.gaze_hz
  double reflective_hz{30};    ///< hmd.reflective_hz (one display)
  double ar_view_hz{5};        ///< hmd.ar_view_hz
  std::vector<StreamSpec> streams;
  /// 0 and 0: the single testbed (scripts/launch/load.yaml, plain channel names); else the scale
  /// launch (ScaleLaunchYaml).
  int arms{0};
  int headsets{0};

  /// The variables scripts/launch/load.yaml expands (ORBED_LOAD_SIM_PERIOD_S, ORBED_LOAD_POSE_HZ,
  /// ORBED_LOAD_CAMERA_HZ, ORBED_LOAD_HMD_CONFIG = `hmd_config_path`).
  std::map<std::string, std::string> LaunchEnvironment(const std::string& hmd_config_path) const;
  /// The headset config override with the scaled gaze, reflective and AR view rates (orbed-hmd
  /// --config).
  std::string HmdConfigYaml() const;
  /// The scale launch (arms and headsets > 0): logger, the arms' sims, the headsets, the monitor,
  /// with the variables of load.yaml (std::logic_error for the single testbed's plan).
  std::string ScaleLaunchYaml() const;
};

/// The plan at `factor` times the nominal rates; std::invalid_argument outside
/// [kMinFactor, kMaxFactor].
LoadPlan MakeLoadPlan(double factor);
/// The testbed with `arms` arms and `headsets` headsets at `factor` times the nominal rates (see the
/// file comment); std::invalid_argument outside 1..kMaxScaleArms, 1..kMaxScaleHeadsets or the
/// factor's range.
LoadPlan MakeScalePlan(int arms, int headsets, double factor = 1);

/// What the watcher had counted on one channel at some moment.
struct ChannelCount {
  int64_t received{0};
  int64_t last_seq{-1};  ///< the last sequence number received (-1: none or no sequence)
};

/// A heartbeat of a publisher as the watcher saw it: its utime and drop counters, and the watcher's
/// channel counts when it arrived.
struct Snapshot {
  int64_t utime_us{0};
  std::map<std::string, int64_t> drops;
  std::map<std::string, ChannelCount> counts;
};

struct StreamRow {
  StreamSpec spec;
  double window_s{0};
  int64_t wanted{0};
  int64_t received{0};
  int64_t drops{0};
  std::optional<int64_t> sent;  ///< streams with a sequence number
  double achieved_hz() const { return window_s > 0 ? static_cast<double>(received) / window_s : 0; }
  /// sent - received, when sent is known.
  std::optional<int64_t> lost() const;
};

/// The stream between the heartbeats `first` and `last` of its publisher (see the file comment).
StreamRow AccountStream(const StreamSpec& spec, const Snapshot& first, const Snapshot& last);

/// A camera stream's capture-to-receive latency over the window.
struct LatencyRow {
  std::string channel;
  int64_t count{0};
  double p50_ms{0};
  double p99_ms{0};
  double max_ms{0};
};
/// The row of the latencies `latencies_ms` (count 0 and zeros for none).
LatencyRow SummarizeLatency(const std::string& channel, const std::vector<double>& latencies_ms);

struct ProcessRow {
  std::string name;
  /// CPU time used from the early sample to the end over that wall time [% of one core]; -1 when
  /// the process was gone.
  double cpu_percent{-1};
  int64_t rss_early_kb{-1};  ///< VmRSS at the early sample (-1: not taken)
  int64_t rss_end_kb{-1};    ///< VmRSS at the end (-1: the process was gone)
  int respawns{0};           ///< instances after the first (distinct pids seen)
  bool alive_at_end{false};  ///< the first instance still ran at the end
  int64_t socket_drops{-1};  ///< datagrams the kernel dropped on its UDP sockets (-1: unknown)
  int64_t dropped{0};        ///< its heartbeat's drop total at the end
  std::map<std::string, int64_t> drop_counts;
  /// (end - early) / early in percent; nullopt when either sample is missing.
  std::optional<double> rss_growth_percent() const;
};

/// The logger's own accounting at the end: every message its handler took (its last heartbeat's
/// messages_in, LCM's start-up probes included) was written, dropped (queue full) or was a probe.
struct LoggerAccount {
  bool known{false};
  int64_t messages_in{0};
  int64_t events_written{0};  ///< manifest.json, all parts
  int64_t drops{0};           ///< manifest.json (LOGGER_STATUS.drops)
  int64_t self_tests{0};      ///< LCM_SELF_TEST probes after the logger's first heartbeat (not logged)
  /// messages_in - written - drops - self tests (0 when every message is accounted for).
  int64_t unaccounted() const { return messages_in - events_written - drops - self_tests; }
};

struct LoadReport {
  double factor{1};
  double duration_s{0};
  double rss_early_s{0};
  std::vector<ProcessRow> processes;
  std::vector<StreamRow> streams;
  LoggerAccount logger;
  int arms{0};                        ///< the plan's (0: the single testbed)
  int headsets{0};                    ///< the plan's
  std::vector<LatencyRow> latencies;  ///< the plan's latency streams
  int64_t watcher_socket_drops{-1};   ///< the watcher's own kernel drops during the run
  double watcher_cpu_percent{-1};     ///< orbed-load's own CPU over the same window [% of one core]
  int launcher_exit_code{0};
  std::string launcher_exit;  ///< how orbed-launch ended ("exit code 0", "killed by signal ...")
};

/// What fails the run: a process that died or was respawned, resident memory that grew by more
/// than `max_rss_growth_percent` from the early sample to the end, an orbed-launch that did not
/// exit 0. Empty = passed.
std::vector<std::string> Failures(const LoadReport& report, double max_rss_growth_percent);

/// The two tables (processes, then streams), the latencies and the logger's account.
void PrintReport(const LoadReport& report, std::ostream& out);
/// The report as one JSON object (scripts/scale.py reads it): arms, headsets, factor, duration_s,
/// processes [{name, cpu_percent, rss_end_kb, respawns, alive_at_end, socket_drops, dropped}],
/// streams [{channel, publisher, wanted_hz, achieved_hz, wanted, received, drops, lost}],
/// latencies [{channel, count, p50_ms, p99_ms, max_ms}], logger {known, events_written, drops,
/// unaccounted}, watcher_socket_drops, watcher_cpu_percent, launcher_exit.
std::string ReportJson(const LoadReport& report);

}  // namespace orbed::load
