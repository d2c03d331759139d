// orbed-monitor on memq://: heartbeats in, a table out; stale heartbeats shown as SILENT.
#include <gtest/gtest.h>

#include "base/test_command.h"
#include "lcmtypes/contract/channels.h"
#include "lcmtypes/contract/conversions.h"
#include "procs/monitor/monitor.h"
#include "procs/monitor/monitor_cli.h"

namespace orbed::monitor {
namespace {

TEST(Monitor, TabulatesHeartbeatsAndFlagsSilentProcesses) {
  CommonFlags flags("orbed-monitor");
  flags.lcm_url = "memq://";
  flags.duration_s = 0.2;
  MonitorOptions options;
  options.print_period_s = 10;
  options.silent_after_s = 3;
  Monitor monitor(flags, options);
  orbed::process_status_t status{};
  status.name = "sim";
  status.host = "hostB";  // contract change 9
  status.state = orbed::process_status_t::STATE_RUNNING;
  status.uptime_s = 42.25;
  status.messages_in = 12;
  status.messages_out = 345;
  status.rejected_inputs = 2;
  status.dropped = 7;  // work skipped under load (contract change 3), by reason
  status.num_drop_reasons = 1;
  status.drop_reason = {"timer/tick"};
  status.drop_count = {7};
  status.last_error = "IIWA_COMMAND/num_joints: num_joints is 6, expected 7";
  monitor.process().lcm().publish(channels::kProcessStatus, &status);
  orbed::process_status_t bad = status;
  bad.name = "liar";
  bad.state = 9;
  monitor.process().lcm().publish(channels::kProcessStatus, &bad);
  // A flood of made-up names: the table stops growing at its bound.
  for (int i = 0; i < 300; ++i) {
    orbed::process_status_t fake = status;
    fake.name = "fake-" + std::to_string(i);
    monitor.process().lcm().publish(channels::kProcessStatus, &fake);
  }
  monitor.Run();
  const int64_t now = NowMicros();
  const std::string table = monitor.Table(now);
  // The sim's row, field by field: name, host, state, uptime [s] to 0.1, messages in and out,
  // rejected inputs, dropped work, the last error (cut at 60 characters).
  const std::string sim_row =
      "sim                   hostB         running       42.2       12       345         2         7  "
      "IIWA_COMMAND/num_joints: num_joints is 6, expected 7\n";
  EXPECT_NE(table.find(sim_row), std::string::npos) << table;
  EXPECT_EQ(table.find("liar"), std::string::npos);  // rejected: state out of range
  // "liar" (state 9); beyond the bound of 256 names (sim + 255 fakes): 45 fakes and the monitor's
  // own heartbeat, which is published after them.
  EXPECT_EQ(monitor.process().rejections().counts().at("PROCESS_STATUS/field"), 1);
  EXPECT_EQ(monitor.process().rejections().counts().at("PROCESS_STATUS/too_many"), 46);
  // 10 s later, past silent_after_s = 3 s, the same row says SILENT.
  EXPECT_NE(monitor.Table(now + 10'000'000)
                .find("sim                   hostB         SILENT        42.2       12       345"),
            std::string::npos);
  // ... and the moment it fell silent is said once, naming its host.
  EXPECT_EQ(monitor.NewlySilent(now + 1'000'000).find("sim on"), std::string::npos);  // 1 s: not yet
  const std::string said = monitor.NewlySilent(now + 10'000'000);
  EXPECT_NE(said.find("sim on hostB: SILENT (no heartbeat for 10."), std::string::npos) << said;
  EXPECT_EQ(monitor.NewlySilent(now + 11'000'000), "");
}

// The command line, in-process.
TEST(MonitorCli, HelpGoesToOutAndExitsZero) {
  const test::CommandRun r = test::RunCommand(RunMonitor, "orbed-monitor", {"--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("--silent-after-s"), std::string::npos) << r.out;
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST(MonitorCli, RefusesAnUnknownFlagAndABadValue) {
  test::CommandRun r = test::RunCommand(RunMonitor, "orbed-monitor", {"--no-such-flag"});
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("--no-such-flag"), std::string::npos) << r.err;
  r = test::RunCommand(RunMonitor, "orbed-monitor", {"--print-period-s", "-1"});
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("--print-period-s"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

// The table goes to the command line's `out` (a 10 ms period inside a 1 s run: printed at least once,
// with the monitor's own heartbeat in it).
TEST(MonitorCli, RunsForTheDurationAndPrintsTheTableOnOut) {
  const test::CommandRun r = test::RunCommand(
      RunMonitor, "orbed-monitor", {"--lcm-url", "memq://", "--duration-s", "1", "--print-period-s", "0.01"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("process               host          state     uptime_s"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace orbed::monitor
