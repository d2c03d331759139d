// The short form of `scripts/orbed load`: the testbed (scripts/launch/load.yaml
// through orbed-launch, in this test's private network namespace) at 10 x its nominal rates for
// 18 s, measured by orbed-load's RunLoad (tests/load/load_run.h). What it holds, as mechanisms
// rather than rates (the machine may be busy):
//   - no process died or was respawned, and orbed-launch exited 0;
//   - drops are counted, and the counts account for what was wanted: for the poses (whose seq says
//     how many were sent) sent + skipped deadlines = deadlines in the window, up to the timers'
//     catch-up backlog at its two ends; for every stream, received + counted drops never exceed
//     what was wanted; the camera's and the sim's received + drops + the watcher's own socket drops
//     reach what was wanted (nothing vanished uncounted);
//   - the logger's account is exact: every message it took was written, dropped (queue full,
//     counted) or an LCM start-up probe;
//   - resident memory from 8 s to the end grew by less than 25 % (release build only: the
//     sanitizers' allocator quarantine grows by design; the rate-dependent lower bounds are skipped
//     there too).
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>

#include <gtest/gtest.h>

#include "tests/integration/testbed_util.h"
#include "tests/load/load_run.h"

namespace orbed::testing {
namespace {

// Deadlines a timer may be behind at each end of a window (Process catches up at most 5 back to
// back), the heartbeat's own lateness, both ends; plus 2 % for the wall clock against the monotonic one.
int64_t Tolerance(int64_t wanted) { return 20 + wanted / 50; }

TEST(Load, TenTimesTheNominalRatesWithoutCrashesWithDropsCounted) {
  const bool sanitized = std::getenv("ORBED_SANITIZED") != nullptr;
  load::LoadOptions options;
  options.factor = 10;
  options.duration_s = 18;
  options.rss_early_s = 8;
  options.warmup_s = 3;
  options.launch_file = SourcePath("scripts/launch/load.yaml");
  options.log_dir = MakeTempDir("load");
  options.bin_dir = std::filesystem::path(BinPath("orbed-launch")).parent_path().string();
  const load::LoadReport report = load::RunLoad(options, std::cout);
  load::PrintReport(report, std::cout);

  EXPECT_EQ(report.launcher_exit_code, 0) << report.launcher_exit;
  ASSERT_EQ(report.processes.size(), 5u);
  for (const load::ProcessRow& p : report.processes) {
    EXPECT_TRUE(p.alive_at_end) << p.name << " died";
    EXPECT_EQ(p.respawns, 0) << p.name;
    EXPECT_GE(p.socket_drops, 0) << p.name << ": its sockets were not found";
    const auto growth = p.rss_growth_percent();
    ASSERT_TRUE(growth.has_value()) << p.name;
    // Bounded: under 25 % or under 4 MiB. The logger is 8 MB at the early sample, so 2 MB of buffers
    // settling is 26 % (seen once); a per-event leak over the ~75 000 events it records after the
    // sample would be 4 MiB at 56 bytes an event.
    const int64_t growth_kb = p.rss_end_kb - p.rss_early_kb;
    EXPECT_TRUE(sanitized || *growth < 25 || growth_kb < 4096)
        << p.name << " grew " << *growth << " %, " << growth_kb << " kB";
  }

  ASSERT_EQ(report.streams.size(), 9u) << "a publisher had no two heartbeats in the window";
  for (const load::StreamRow& s : report.streams) {
    SCOPED_TRACE(s.spec.channel);
    EXPECT_GT(s.window_s, 5);
    EXPECT_LE(s.received + s.drops, s.wanted + Tolerance(s.wanted));
    if (s.sent) {
      EXPECT_LE(s.received, *s.sent);
      EXPECT_NEAR(static_cast<double>(*s.sent + s.drops), static_cast<double>(s.wanted),
                  static_cast<double>(Tolerance(s.wanted)));
    }
    const bool always_published = s.spec.channel == "HMD_CAMERA" || s.spec.publisher == "sim";
    if (always_published && !sanitized) {
      EXPECT_GE(s.received + s.drops + report.watcher_socket_drops, s.wanted - Tolerance(s.wanted));
    }
  }

  ASSERT_TRUE(report.logger.known) << "no logger account (its last heartbeat or manifest is missing)";
  EXPECT_GT(report.logger.events_written, 0);
  EXPECT_EQ(report.logger.unaccounted(), 0);
}

}  // namespace
}  // namespace orbed::testing
