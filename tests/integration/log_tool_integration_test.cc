// orbed-log reads what LCM's own lcm-logger writes: in this test's private network namespace,
// lcm-logger records 50 messages on LOG_TOOL_A and 5 on LOG_TOOL_B published here; the
// recording is cut short of a clean end by appending half an event (a logger killed mid-write).
// `orbed-log info` counts both channels exactly and reports the torn tail as damage; `check` exits 1
// naming its offset; `cut --channels LOG_TOOL_B` keeps the 5. Five encoded iiwa_status_t messages on
// LOG_TOOL_STATUS come back from `export --csv` with the values published; the zero payloads of A and
// B have no known fingerprint and are listed as not exported.
#include <csignal>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <orbed/iiwa_status_t.hpp>

#include "base/test_command.h"
#include "procs/logger/event_log_reader.h"
#include "procs/logger/log_tool.h"
#include "tests/integration/testbed_util.h"

namespace orbed::testing {
namespace {

TEST(LogTool, ReadsWhatLcmLoggerWrites) {
  const std::string dir = MakeTempDir("log_tool");
  const std::string log = dir + "/lcm_logger.lcmlog";
  RunningProcess logger({"/usr/bin/lcm-logger", "-c", "LOG_TOOL_.*", "--flush-interval=10", "-f", log});
  ASSERT_TRUE(WaitFor([&] { return std::ifstream(log).good(); }, 20)) << "lcm-logger did not open its log";
  lcm::LCM lcm;
  ASSERT_TRUE(lcm.good());
  const uint8_t payload[16] = {};
  const auto on_disk = [&log](const std::string& channel) {
    const logger::MappedLog mapped(log);
    if (!mapped.ok()) return 0;
    logger::EventLogScanner scanner = mapped.Scanner();
    logger::LogEvent e;
    int n = 0;
    while (scanner.Next(&e)) n += e.channel == channel;
    return n;
  };
  // lcm-logger writes an event out when the next one arrives after its flush interval. First, until a
  // probe is on disk (the logger is listening).
  ASSERT_TRUE(WaitFor(
      [&] {
        lcm.publish("LOG_TOOL_PROBE", payload, 1);
        return on_disk("LOG_TOOL_PROBE") > 0;
      },
      20));
  // In bursts of 11 (lcm-logger's subscription queue, LCM's default, holds 30 messages): 10 on A and
  // 1 on B, then LOG_TOOL_END until the burst is on disk.
  for (int burst = 1; burst <= 5; ++burst) {
    for (int i = 0; i < 10; ++i) lcm.publish("LOG_TOOL_A", payload, sizeof(payload));
    lcm.publish("LOG_TOOL_B", payload, 3);
    orbed::iiwa_status_t status{};
    status.utime = burst;
    status.num_joints = 2;
    for (std::vector<double>* v :
         {&status.joint_position_measured, &status.joint_velocity_estimated, &status.joint_position_commanded,
          &status.joint_position_ipo, &status.joint_torque_measured, &status.joint_torque_commanded,
          &status.joint_torque_external})
      *v = {0.25 * burst, -1.0 / burst};
    lcm.publish("LOG_TOOL_STATUS", &status);
    ASSERT_TRUE(WaitFor(
        [&] {
          lcm.publish("LOG_TOOL_END", payload, 1);
          return on_disk("LOG_TOOL_A") == 10 * burst && on_disk("LOG_TOOL_B") == burst &&
                 on_disk("LOG_TOOL_STATUS") == burst;
        },
        20))
        << "burst " << burst << ", on disk: " << on_disk("LOG_TOOL_A") << " A, " << on_disk("LOG_TOOL_B")
        << " B";
  }
  logger.Signal(SIGINT);
  ASSERT_TRUE(logger.Wait(20));

  test::CommandRun r = test::RunCommand(logger::RunLogTool, "orbed-log", {"info", log});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("LOG_TOOL_A                           50          800"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("LOG_TOOL_B                            5           15"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("0 damaged range(s)"), std::string::npos) << r.out;
  long long total = 0;
  ASSERT_EQ(std::sscanf(r.out.substr(r.out.find(": ") + 2).c_str(), "%lld events", &total), 1) << r.out;

  // A torn last event: its header and half its channel name.
  std::ifstream in(log, std::ios::binary | std::ios::ate);
  const auto clean_size = static_cast<uint64_t>(in.tellg());
  {
    std::ofstream torn(log, std::ios::binary | std::ios::app);
    const unsigned char header[] = {0xED, 0xA1, 0xDA, 0x01, 0, 0, 0, 0, 0,  0, 0, 99, 0,  0,   0,
                                    0,    0,    0,    0,    1, 0, 0, 0, 10, 0, 0, 0,  16, 'L', 'O'};
    torn.write(reinterpret_cast<const char*>(header), sizeof(header));
  }
  r = test::RunCommand(logger::RunLogTool, "orbed-log", {"check", log});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("damaged bytes " + std::to_string(clean_size) + ".."), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(": " + std::to_string(total) + " events read"), std::string::npos) << r.out;

  const std::string cut = dir + "/b.lcmlog";
  r = test::RunCommand(logger::RunLogTool, "orbed-log", {"cut", log, cut, "--channels", "LOG_TOOL_B"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("5 events written"), std::string::npos) << r.out;

  const std::string csv_dir = dir + "/csv";
  r = test::RunCommand(logger::RunLogTool, "orbed-log", {"export", log, csv_dir, "--csv"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("LOG_TOOL_A: not exported, no orbed or Drake fingerprint (50 events)"),
            std::string::npos)
      << r.out;
  std::ifstream csv(csv_dir + "/LOG_TOOL_STATUS.csv");
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  const std::string header_start =
      "log_utime (us),utime (us),num_joints,joint_position_measured[0] (rad),joint_position_measured[1] "
      "(rad),"
      "joint_velocity_estimated[0] (rad/s),";
  EXPECT_EQ(line.substr(0, header_start.size()), header_start);
  for (int burst = 1; burst <= 5; ++burst) {
    ASSERT_TRUE(std::getline(csv, line)) << "row " << burst;
    std::vector<std::string> cells;
    for (size_t start = 0, end = 0; end != std::string::npos; start = end + 1) {
      end = line.find(',', start);
      cells.push_back(line.substr(start, end == std::string::npos ? end : end - start));
    }
    ASSERT_EQ(cells.size(), 17u) << line;  // log time, utime, count, 7 arrays of 2
    EXPECT_EQ(cells[1], std::to_string(burst));
    EXPECT_EQ(cells[2], "2");
    // Read back exactly (shortest round-trip decimals): the first and the last array.
    EXPECT_EQ(std::stod(cells[3]), 0.25 * burst) << line;
    EXPECT_EQ(std::stod(cells[4]), -1.0 / burst) << line;
    EXPECT_EQ(std::stod(cells[16]), -1.0 / burst) << line;
  }
  EXPECT_FALSE(std::getline(csv, line));
}

}  // namespace
}  // namespace orbed::testing
