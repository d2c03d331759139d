#pragma once
/// @file
/// The LCM and /proc shell of orbed-load: runs the testbed at a load plan's rates and measures it.
///
/// RunLoad writes the headset's rate override into the log folder, starts orbed-launch on the
/// launch file (default scripts/launch/load.yaml, whose ${ORBED_LOAD_*} take the plan's rates) and
/// listens to every channel: it counts the messages per channel, reads hmd_pose_t's seq, and at every
/// heartbeat (PROCESS_STATUS) of a launched process takes a Snapshot (load_report.h). Once every
/// process has a RUNNING heartbeat from the pid the launcher started (ChildrenByName, base/
/// proc_stats.h), the run begins: VmRSS of each process at rss_early_s and at duration_s, the kernel's
/// UDP drops of each at the end; then orbed-launch is stopped with SIGINT, and the logger's account
/// is read from its last heartbeat and manifest.json. The streams are accounted between the first
/// heartbeat of their publisher after warmup_s and its last RUNNING one (load_report.h).
///
/// Must run inside a private network namespace (scripts/netns-exec) like every testbed run; the
/// /proc/net/udp drop counts are those of the caller's namespace.
/// Threading: RunLoad blocks; the LCM handling runs on a thread it owns and joins.
/// Each camera stream's latency: the watcher's receive stamp (LCM's recv_utime) minus the image's
/// sample stamp, over the same window as the rates; CPU from /proc between the early sample and
/// the end.
/// Clock: the steady clock paces the run (deadlines only; nothing waits as synchronisation).

#include <ostream>
#include <string>

#include "tests/load/load_report.h"

namespace orbed::load {

struct LoadOptions {
  double factor{10};
  /// > 0 both: the scale launch with that many arms and headsets (MakeScalePlan), written into
  /// log_dir as scale.yaml; 0 both: the single testbed of launch_file.
  int arms{0};
  int headsets{0};
  double duration_s{60};   ///< from the moment every process is ready
  double rss_early_s{10};  ///< the early resident-memory sample, after ready
  double warmup_s{5};      ///< rates are accounted from the first heartbeat after this
  double ready_timeout_s{120};
  std::string launch_file;  ///< "" = scripts/launch/load.yaml in the source tree
  std::string log_dir;      ///< the testbed's ORBED_LOG_DIR; required, created if missing
  std::string bin_dir;      ///< where orbed-launch is; "" = beside this executable
};

/// Runs the load. std::invalid_argument for bad options; std::runtime_error when orbed-launch
/// cannot start or the testbed does not come up within ready_timeout_s. A process that dies during
/// the run is not an exception: it is in the report (Failures()).
LoadReport RunLoad(const LoadOptions& options, std::ostream& log);

}  // namespace orbed::load
