// orbed-load's pure core (load_report.h): the plan at a factor, the accounting of a stream between
// two heartbeats, the verdict and the tables. The run itself is load_integration_test.
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "procs/launcher/launch_file.h"
#include "tests/load/load_report.h"

namespace orbed::load {
namespace {

const StreamSpec& Stream(const LoadPlan& plan, const std::string& channel) {
  for (const StreamSpec& s : plan.streams) {
    if (s.channel == channel) return s;
  }
  throw std::out_of_range(channel);
}

TEST(LoadPlan, TenTimesTheNominalRates) {
  const LoadPlan plan = MakeLoadPlan(10);
  EXPECT_DOUBLE_EQ(plan.sim_period_s, 0.0005);  // IIWA_STATUS at 2 kHz
  EXPECT_DOUBLE_EQ(plan.pose_hz, 600);
  EXPECT_DOUBLE_EQ(plan.camera_hz, 300);
  EXPECT_DOUBLE_EQ(plan.reflective_hz, 300);
  EXPECT_DOUBLE_EQ(plan.ar_view_hz, 50);
  EXPECT_DOUBLE_EQ(plan.gaze_hz, 100);
  EXPECT_DOUBLE_EQ(Stream(plan, "IIWA_STATUS").nominal_hz, 200);
  EXPECT_DOUBLE_EQ(Stream(plan, "IIWA_STATUS").wanted_hz, 2000);
  EXPECT_EQ(Stream(plan, "IIWA_STATUS").drop_keys, std::vector<std::string>{"timer/tick"});
  EXPECT_TRUE(Stream(plan, "HMD_POSE_TRUTH").has_seq);
  EXPECT_EQ(Stream(plan, "HMD_CAMERA").drop_keys,
            (std::vector<std::string>{"timer/HMD_CAMERA", "HMD_CAMERA/busy"}));
  EXPECT_EQ(plan.streams.size(), 9u);

  const auto env = plan.LaunchEnvironment("/x/load_hmd.yaml");
  EXPECT_EQ(env.at("ORBED_LOAD_SIM_PERIOD_S"), "0.0005");
  EXPECT_EQ(env.at("ORBED_LOAD_POSE_HZ"), "600");
  EXPECT_EQ(env.at("ORBED_LOAD_CAMERA_HZ"), "300");
  EXPECT_EQ(env.at("ORBED_LOAD_HMD_CONFIG"), "/x/load_hmd.yaml");
  const std::string yaml = plan.HmdConfigYaml();
  EXPECT_NE(yaml.find("gaze_hz: 100\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("reflective_hz: 300\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("ar_view_hz: 50\n"), std::string::npos) << yaml;
}

TEST(LoadPlan, FactorOneIsTheTestbedAndTheRangeIsChecked) {
  const LoadPlan plan = MakeLoadPlan(1);
  EXPECT_DOUBLE_EQ(plan.sim_period_s, 0.005);
  EXPECT_DOUBLE_EQ(plan.pose_hz, 60);
  // The sim's tick is whole microseconds: 200 Hz x 3 = 1666.67 us, rounded.
  EXPECT_DOUBLE_EQ(MakeLoadPlan(3).sim_period_s, 0.001667);
  EXPECT_THROW(MakeLoadPlan(0), std::invalid_argument);
  EXPECT_THROW(MakeLoadPlan(17), std::invalid_argument);
  EXPECT_THROW(MakeLoadPlan(std::nan("")), std::invalid_argument);
}

TEST(ScalePlan, EachArmAndHeadsetHasItsStreamsOnItsOwnChannels) {
  const LoadPlan plan = MakeScalePlan(2, 3);
  EXPECT_EQ(plan.arms, 2);
  EXPECT_EQ(plan.headsets, 3);
  EXPECT_EQ(plan.streams.size(), 2u * 3 + 3u * 6);
  EXPECT_EQ(Stream(plan, "IIWA_STATUS_A1").publisher, "sim_a1");
  EXPECT_DOUBLE_EQ(Stream(plan, "COLLISION_STATUS_A0").wanted_hz, 200);
  EXPECT_EQ(Stream(plan, "HMD_POSE_TRUTH_H2").publisher, "hmd_h2");
  EXPECT_TRUE(Stream(plan, "HMD_POSE_TRUTH_H2").has_seq);
  // The headset's timers are named by its own channels.
  EXPECT_EQ(Stream(plan, "HMD_POSE_TRUTH_H2").drop_keys, std::vector<std::string>{"timer/HMD_POSE_H2"});
  EXPECT_EQ(Stream(plan, "REFLECTIVE_VIEW_H0").drop_keys,
            (std::vector<std::string>{"timer/REFLECTIVE_VIEW_H0", "REFLECTIVE_VIEW_H0/busy"}));
  int latency_streams = 0;
  for (const StreamSpec& s : plan.streams) latency_streams += s.latency ? 1 : 0;
  EXPECT_EQ(latency_streams, 3);
  EXPECT_TRUE(Stream(plan, "HMD_CAMERA_H1").latency);
  for (const StreamSpec& s : MakeLoadPlan(1).streams) EXPECT_EQ(s.latency, s.channel == "HMD_CAMERA");
  EXPECT_THROW(MakeScalePlan(0, 1), std::invalid_argument);
  EXPECT_THROW(MakeScalePlan(5, 1), std::invalid_argument);
  EXPECT_THROW(MakeScalePlan(1, 9), std::invalid_argument);
  EXPECT_THROW(MakeScalePlan(1, 1, 20), std::invalid_argument);
  EXPECT_THROW(MakeLoadPlan(1).ScaleLaunchYaml(), std::logic_error);
}

TEST(ScalePlan, TheLaunchFileReadsBackWithEveryProcessAtItsArm) {
  // The launcher's own reader is the oracle for the file the plan writes.
  const LoadPlan plan = MakeScalePlan(2, 3, 2);
  const std::map<std::string, std::string> env = {{"ORBED_LOG_DIR", "/logs"},
                                                  {"ORBED_SOURCE_DIR", "/src"},
                                                  {"ORBED_LOAD_SIM_PERIOD_S", "0.0025"},
                                                  {"ORBED_LOAD_POSE_HZ", "120"},
                                                  {"ORBED_LOAD_CAMERA_HZ", "60"},
                                                  {"ORBED_LOAD_HMD_CONFIG", "/logs/load_hmd.yaml"}};
  const launcher::LaunchSpec spec = launcher::ParseLaunchYaml(plan.ScaleLaunchYaml(), "scale.yaml", env);
  EXPECT_EQ(spec.name, "scale_2x3");
  std::map<std::string, std::vector<std::string>> args;
  for (const auto& group : spec.groups) {
    for (const auto& process : group.processes) args[process.name] = process.args;
  }
  ASSERT_EQ(args.size(), 7u);  // logger, 2 sims, 3 headsets, monitor
  const std::string scene = "/src/sim/models/scenes/four_arms_or.yaml";
  EXPECT_EQ(args.at("sim_a1"), (std::vector<std::string>{"--scene", scene, "--arm", "a1", "--state-file",
                                                         "/logs/sim_a1.state", "--period-s", "0.0025"}));
  EXPECT_EQ(args.at("hmd_h2"),
            (std::vector<std::string>{"--scene", scene, "--headset", "h2", "--arm", "a0", "--user-seed", "3",
                                      "--state-file", "/logs/hmd_h2.state", "--pose-hz", "120", "--camera-hz",
                                      "60", "--config", "/logs/load_hmd.yaml"}));
  EXPECT_EQ(args.at("hmd_h1")[5], "a1");
  EXPECT_EQ(args.at("logger"), (std::vector<std::string>{"--log-dir", "/logs"}));
  EXPECT_EQ(args.count("monitor"), 1u);
}

TEST(SummarizeLatency, QuantilesByHand) {
  std::vector<double> ms;
  for (int i = 100; i >= 1; --i) ms.push_back(i);  // 1..100 ms, unsorted
  const LatencyRow row = SummarizeLatency("HMD_CAMERA_H0", ms);
  EXPECT_EQ(row.count, 100);
  EXPECT_DOUBLE_EQ(row.p50_ms, 50.5);    // between the 50th and 51st
  EXPECT_NEAR(row.p99_ms, 99.01, 1e-9);  // (n - 1) q = 98.01: x[98] + 0.01 (x[99] - x[98])
  EXPECT_DOUBLE_EQ(row.max_ms, 100);
  const LatencyRow none = SummarizeLatency("HMD_CAMERA_H1", {});
  EXPECT_EQ(none.count, 0);
  EXPECT_EQ(none.max_ms, 0);
}

TEST(ReportJson, ReadsBackWithNlohmann) {
  LoadReport report;
  report.arms = 2;
  report.headsets = 1;
  report.factor = 1;
  report.duration_s = 30;
  ProcessRow sim;
  sim.name = "sim_a0";
  sim.cpu_percent = 7.5;
  sim.rss_end_kb = 17000;
  sim.alive_at_end = true;
  ProcessRow gone;
  gone.name = "hmd_h0";
  report.processes = {sim, gone};
  StreamRow row;
  row.spec = {"HMD_POSE_H0", "hmd_h0", 60, 60, {"timer/HMD_POSE_H0"}, true};
  row.window_s = 10;
  row.wanted = 600;
  row.received = 598;
  row.sent = 599;
  report.streams = {row};
  report.latencies = {SummarizeLatency("HMD_CAMERA_H0", {1, 2, 3})};
  report.watcher_cpu_percent = 3;
  const nlohmann::json j = nlohmann::json::parse(ReportJson(report));
  EXPECT_EQ(j.at("arms"), 2);
  EXPECT_EQ(j.at("processes").size(), 2u);
  EXPECT_DOUBLE_EQ(j.at("processes")[0].at("cpu_percent").get<double>(), 7.5);
  EXPECT_TRUE(j.at("processes")[1].at("cpu_percent").is_null());  // gone: no CPU figure
  EXPECT_FALSE(j.at("processes")[1].at("alive_at_end").get<bool>());
  EXPECT_DOUBLE_EQ(j.at("streams")[0].at("achieved_hz").get<double>(), 59.8);
  EXPECT_EQ(j.at("streams")[0].at("lost"), 1);
  EXPECT_DOUBLE_EQ(j.at("latencies")[0].at("p50_ms").get<double>(), 2);
  EXPECT_DOUBLE_EQ(j.at("watcher_cpu_percent").get<double>(), 3);
}

TEST(AccountStream, CountsBetweenTwoHeartbeats) {
  const StreamSpec pose{"HMD_POSE", "hmd", 60, 600, {"timer/HMD_POSE"}, true};
  Snapshot h1, h2;
  h1.utime_us = 1'000'000'000;
  h2.utime_us = h1.utime_us + 10'000'000;  // 10 s: 6000 deadlines
  h1.drops = {{"timer/HMD_POSE", 100}, {"other", 5}};
  h2.drops = {{"timer/HMD_POSE", 400}, {"other", 50}};
  h1.counts["HMD_POSE"] = {2000, 2100};
  h2.counts["HMD_POSE"] = {7650, 7800};  // 5700 sent, 5650 received
  const StreamRow row = AccountStream(pose, h1, h2);
  EXPECT_DOUBLE_EQ(row.window_s, 10);
  EXPECT_EQ(row.wanted, 6000);
  EXPECT_EQ(row.received, 5650);
  EXPECT_EQ(row.drops, 300);
  ASSERT_TRUE(row.sent.has_value());
  EXPECT_EQ(*row.sent, 5700);
  EXPECT_EQ(*row.lost(), 50);
  EXPECT_EQ(*row.sent + row.drops, row.wanted);  // the identity of the file comment
  EXPECT_DOUBLE_EQ(row.achieved_hz(), 565);
}

TEST(AccountStream, ImagesSumTheirKeysAndAMissingChannelCountsZero) {
  const StreamSpec camera{"HMD_CAMERA", "hmd", 30, 300, {"timer/HMD_CAMERA", "HMD_CAMERA/busy"}, false};
  Snapshot h1, h2;
  h1.utime_us = 0;
  h2.utime_us = 2'000'000;
  h2.drops = {{"HMD_CAMERA/busy", 420}, {"timer/HMD_CAMERA", 3}};  // new keys: from 0
  h2.counts["HMD_CAMERA"] = {170, -1};
  const StreamRow row = AccountStream(camera, h1, h2);
  EXPECT_EQ(row.wanted, 600);
  EXPECT_EQ(row.drops, 423);
  EXPECT_EQ(row.received, 170);
  EXPECT_FALSE(row.sent.has_value());
  EXPECT_FALSE(row.lost().has_value());
  EXPECT_EQ(AccountStream(camera, h2, h2).received, 0);
}

ProcessRow Healthy(const std::string& name) {
  ProcessRow row;
  row.name = name;
  row.rss_early_kb = 100'000;
  row.rss_end_kb = 105'000;
  row.alive_at_end = true;
  row.socket_drops = 0;
  return row;
}

TEST(Failures, DeathsRespawnsMemoryAndTheLauncher) {
  LoadReport report;
  report.processes = {Healthy("sim"), Healthy("hmd")};
  EXPECT_TRUE(Failures(report, 10).empty());
  EXPECT_DOUBLE_EQ(*report.processes[0].rss_growth_percent(), 5);

  report.processes[1].rss_end_kb = 111'000;  // 11 %
  auto failures = Failures(report, 10);
  ASSERT_EQ(failures.size(), 1u);
  EXPECT_NE(failures[0].find("hmd resident memory grew 11.0 %"), std::string::npos) << failures[0];
  EXPECT_TRUE(Failures(report, 12).empty());

  report.processes[0].respawns = 1;
  report.processes[0].alive_at_end = false;
  report.processes[0].rss_end_kb = -1;
  report.launcher_exit_code = 1;
  report.launcher_exit = "exit code 1";
  failures = Failures(report, 12);
  ASSERT_EQ(failures.size(), 3u);
  EXPECT_EQ(failures[0], "sim died");
  EXPECT_EQ(failures[1], "sim was respawned 1 time(s)");
  EXPECT_EQ(failures[2], "orbed-launch: exit code 1");
}

TEST(Failures, ALiveProcessWithoutAMemorySampleFails) {
  LoadReport report;
  report.processes = {Healthy("logger")};
  report.processes[0].rss_early_kb = -1;
  EXPECT_EQ(Failures(report, 10), std::vector<std::string>{"logger: no resident memory sample"});
}

TEST(PrintReport, BothTablesAndTheLoggerAccount) {
  LoadReport report;
  report.factor = 10;
  report.duration_s = 60;
  report.rss_early_s = 10;
  report.processes = {Healthy("hmd")};
  report.processes[0].drop_counts = {{"HMD_CAMERA/busy", 12}};
  report.processes[0].dropped = 12;
  StreamRow row;
  row.spec = {"HMD_POSE", "hmd", 60, 600, {"timer/HMD_POSE"}, true};
  row.window_s = 50;
  row.wanted = 30000;
  row.received = 29990;
  row.sent = 30000;
  report.streams = {row};
  report.logger = {true, 1000, 990, 4, 6};
  report.watcher_socket_drops = 0;
  std::ostringstream out;
  PrintReport(report, out);
  const std::string text = out.str();
  EXPECT_NE(text.find("10.0 x nominal rates for 60 s"), std::string::npos) << text;
  EXPECT_NE(text.find("HMD_CAMERA/busy 12"), std::string::npos) << text;
  EXPECT_NE(text.find("    5.0%"), std::string::npos) << text;
  EXPECT_NE(text.find("HMD_POSE"), std::string::npos) << text;
  EXPECT_NE(text.find("599.8"), std::string::npos) << text;
  EXPECT_NE(text.find("1000 messages in = 990 written + 4 dropped (queue full) + 6 LCM start-up probes\n"),
            std::string::npos)
      << text;
  EXPECT_EQ(report.logger.unaccounted(), 0);
}

}  // namespace
}  // namespace orbed::load
