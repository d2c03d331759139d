// orbed-log export --mcap of a real run's log: orbed-logger records orbed-iiwa-sim and orbed-hmd
// (one reflective display) in this test's private network namespace until the log holds 10 camera
// frames and 10 reflective views; the export is read back under node by @mcap/core's
// McapIndexedReader and McapStreamReader (procs/logger/mcap/mcap_export.test.mjs): per LCM channel
// as many messages as the log has events (orbed-log info's counts: a real run's messages all
// decode), /hmd/camera and /reflective one per picture, /tf and /scene at least one; the first
// IIWA_STATUS's joints, HMD_POSE's X_WH and ROBOT_STATE's X_WR (the robot base on the first /tf)
// exactly, the first camera JPEG's bytes; every schema valid JSON Schema and every message valid
// against its own.
#include <csignal>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <orbed/hmd_pose_t.hpp>
#include <orbed/iiwa_status_t.hpp>
#include <orbed/image_t.hpp>
#include <orbed/robot_state_t.hpp>

#include "lcmtypes/bounded_decode.h"
#include "procs/logger/event_log_reader.h"
#include "procs/logger/log_tool.h"
#include "tests/integration/testbed_util.h"

namespace orbed::testing {
namespace {

using json = nlohmann::json;

std::map<std::string, int> EventsPerChannel(const std::string& path) {
  std::map<std::string, int> events;
  const logger::MappedLog log(path);
  if (!log.ok()) return events;
  logger::EventLogScanner scanner = log.Scanner();
  logger::LogEvent e;
  while (scanner.Next(&e)) ++events[e.channel];
  return events;
}

// The first message on `channel`, decoded.
template <class Msg>
bool First(const std::string& path, const std::string& channel, Msg* msg) {
  const logger::MappedLog log(path);
  logger::EventLogScanner scanner = log.Scanner();
  logger::LogEvent e;
  while (scanner.Next(&e))
    if (e.channel == channel) return DecodeBounded(e.data, e.size, msg).ok();
  return false;
}

json PoseJson(const orbed::pose_t& p) {
  return {{"position_m", std::vector<double>(p.position_m, p.position_m + 3)},
          {"quaternion_wxyz", std::vector<double>(p.quaternion_wxyz, p.quaternion_wxyz + 4)}};
}

TEST(McapExport, ARealRunReadBackByMcapCore) {
  const std::string dir = MakeTempDir("mcap");
  const std::string log = dir + "/orbed.lcmlog", mcap = dir + "/orbed.mcap";
  {
    RunningProcess logger({BinPath("orbed-logger"), "--file", log, "--name", "mcap-logger"});
    RunningProcess sim({BinPath("orbed-iiwa-sim"), "--name", "sim"});
    RunningProcess hmd({BinPath("orbed-hmd"), "--name", "hmd", "--displays", "1"});
    ASSERT_TRUE(WaitFor(
        [&] {
          logger.running();
          sim.running();
          hmd.running();
          const std::map<std::string, int> events = EventsPerChannel(log);
          const auto count = [&events](const char* c) { return events.count(c) ? events.at(c) : 0; };
          return count("HMD_CAMERA") >= 10 && count("REFLECTIVE_VIEW") >= 10 && count("HMD_POSE") >= 1;
        },
        60))
        << "the log did not get 10 camera frames and 10 reflective views within 60 s";
    logger.Signal(SIGINT);
    ASSERT_TRUE(logger.Wait(20));
    EXPECT_EQ(logger.exit_code(), 0);
  }
  std::ostringstream out, err;
  const char* argv[] = {"orbed-log", "export", log.c_str(), mcap.c_str(), "--mcap"};
  ASSERT_EQ(logger::RunLogTool(5, argv, out, err), 0) << err.str();
  std::printf("%s", out.str().c_str());

  json expect;
  for (const auto& [channel, n] : EventsPerChannel(log)) expect["counts"][channel] = n;
  expect["counts"]["/hmd/camera"] = expect["counts"]["HMD_CAMERA"];
  expect["counts"]["/reflective"] = expect["counts"]["REFLECTIVE_VIEW"];
  expect["min_counts"] = {{"/tf", 1}, {"/scene", 1}};
  orbed::iiwa_status_t status;
  orbed::hmd_pose_t pose;
  orbed::robot_state_t state;
  orbed::image_t camera;
  ASSERT_TRUE(First(log, "IIWA_STATUS", &status));
  ASSERT_TRUE(First(log, "HMD_POSE", &pose));
  ASSERT_TRUE(First(log, "ROBOT_STATE", &state));
  ASSERT_TRUE(First(log, "HMD_CAMERA", &camera));
  expect["iiwa_positions"] = {status.joint_position_measured};
  expect["X_WH"] = PoseJson(pose.X_WH);
  expect["X_WR"] = PoseJson(state.X_WR);
  expect["jpeg_path"] = dir + "/camera.jpg";
  std::ofstream(dir + "/camera.jpg", std::ios::binary)
      .write(reinterpret_cast<const char*>(camera.data.data()),
             static_cast<std::streamsize>(camera.data.size()));
  std::ofstream(dir + "/expect.json") << expect.dump(2);

  RunningProcess reader({ORBED_NODE, "--test", std::string(ORBED_MCAP_WRITER_DIR) + "/mcap_export.test.mjs"},
                        {{"ORBED_MCAP_FILE", mcap}, {"ORBED_EXPECT_JSON", dir + "/expect.json"}});
  ASSERT_TRUE(reader.Wait(120)) << "the MCAP reader did not finish";
  EXPECT_EQ(reader.exit_code(), 0) << "see the reader's output above";
}

}  // namespace
}  // namespace orbed::testing
