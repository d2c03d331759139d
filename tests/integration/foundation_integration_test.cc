// Multi-process tests of the foundation over real LCM, each run in a private network namespace
// (ctest wraps this binary in scripts/netns-exec): orbed-launch readiness, respawn and ordered
// stop; orbed-logger's log played by lcm-logplayer into lcm-logger; a SIGKILLed logger's file.
#include <signal.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <orbed/all_types.hpp>

#include "tests/integration/testbed_util.h"

namespace orbed::testing {
namespace {

namespace fs = std::filesystem;

struct LogEvent {
  std::string channel;
  std::string data;
  int64_t timestamp;
};

std::vector<LogEvent> ReadLog(const std::string& path) {
  std::vector<LogEvent> events;
  lcm::LogFile log(path, "r");
  if (!log.good()) return events;
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    events.push_back({e->channel, std::string(static_cast<const char*>(e->data), e->datalen), e->timestamp});
  }
  return events;
}

std::string FindLog(const std::string& dir) {
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() == ".lcmlog") return entry.path().string();
  }
  return "";
}

bool Alive(pid_t pid) { return kill(pid, 0) == 0; }

// Launch logger + monitor (respawn: true); both heartbeat; SIGKILL the monitor → a new monitor
// heartbeats within 1 s; SIGINT the launcher → every child gone, exit 0.
TEST(Launcher, StartsRespawnsAndStopsInOrder) {
  const std::string dir = MakeTempDir("launch");
  const std::string launch_file = dir + "/launch.yaml";
  std::ofstream(launch_file) << "name: it\n"
                                "groups:\n"
                                "  - name: recording\n"
                                "    processes:\n"
                                "      - {name: logger, command: orbed-logger, args: [--log-dir, \""
                             << dir
                             << "/logs\"]}\n"
                                "  - name: health\n"
                                "    processes:\n"
                                "      - {name: monitor, command: orbed-monitor, respawn: true}\n";
  BusWatcher bus;
  bus.Start();
  RunningProcess launcher({BinPath("orbed-launch"), launch_file});
  ASSERT_TRUE(
      WaitFor([&] { return !bus.Heartbeats("logger").empty() && !bus.Heartbeats("monitor").empty(); }, 15))
      << "no heartbeat from logger and monitor";
  const pid_t logger_pid = bus.Heartbeats("logger").front().status.pid;
  const pid_t monitor_pid = bus.Heartbeats("monitor").front().status.pid;
  ASSERT_TRUE(Alive(logger_pid));
  ASSERT_TRUE(Alive(monitor_pid));

  const auto killed_at = std::chrono::steady_clock::now();
  ASSERT_EQ(kill(monitor_pid, SIGKILL), 0);
  pid_t new_pid = 0;
  std::chrono::steady_clock::time_point respawned_at;
  ASSERT_TRUE(WaitFor(
      [&] {
        for (const auto& beat : bus.Heartbeats("monitor")) {
          if (beat.status.pid != monitor_pid) {
            new_pid = beat.status.pid;
            respawned_at = beat.received;
            return true;
          }
        }
        return false;
      },
      5))
      << "monitor was not respawned";
  const double respawn_s = std::chrono::duration<double>(respawned_at - killed_at).count();
  EXPECT_LT(respawn_s, 1.0) << "respawn took " << respawn_s << " s";

  launcher.Signal(SIGINT);
  ASSERT_TRUE(launcher.Wait(15)) << "launcher did not stop";
  EXPECT_EQ(launcher.term_signal(), 0);
  EXPECT_EQ(launcher.exit_code(), 0);
  EXPECT_FALSE(Alive(logger_pid));
  EXPECT_FALSE(Alive(new_pid));
  // The logger stopped cleanly: its manifest says complete.
  std::ifstream manifest(dir + "/logs/manifest.json");
  std::stringstream text;
  text << manifest.rdbuf();
  EXPECT_NE(text.str().find("\"complete\": true"), std::string::npos);

  // What lcm-spy would show: every recorded message decodes as one of the contract's types
  // (lcm-spy matches the same 8-byte fingerprint); LCM's own self-test probe is not recorded.
  std::map<int64_t, std::string> fingerprints;
#define ORBED_FINGERPRINT(type) fingerprints[orbed::type::getHash()] = #type;
  ORBED_FOR_EACH_LCM_TYPE(ORBED_FINGERPRINT)
#undef ORBED_FINGERPRINT
  const std::vector<LogEvent> events = ReadLog(FindLog(dir + "/logs"));
  ASSERT_FALSE(events.empty());
  int undecodable = 0;
  for (const LogEvent& e : events) {
    int64_t hash = 0;
    for (int i = 0; i < 8 && i < static_cast<int>(e.data.size()); ++i) {
      hash = (hash << 8) | static_cast<uint8_t>(e.data[i]);
    }
    if (fingerprints.count(hash) == 0) {
      ++undecodable;
      ADD_FAILURE() << "undecodable message on " << e.channel;
    }
  }
  EXPECT_EQ(undecodable, 0);
}

// A required process that cannot become ready stops the testbed with a non-zero exit.
TEST(Launcher, RequiredProcessWithoutHeartbeatFailsTheLaunch) {
  const std::string dir = MakeTempDir("launch_fail");
  const std::string launch_file = dir + "/launch.yaml";
  std::ofstream(launch_file) << "groups:\n"
                                "  - name: g\n"
                                "    processes:\n"
                                "      - {name: mute, command: sh, args: [-c, 'sleep 30'], "
                                "ready_timeout_s: 1, stop_signal: SIGTERM}\n";
  const auto begin = std::chrono::steady_clock::now();
  RunningProcess launcher({BinPath("orbed-launch"), launch_file});
  ASSERT_TRUE(launcher.Wait(15));
  EXPECT_EQ(launcher.exit_code(), 1);
  // It waited for the heartbeat (1 s), then gave up and stopped the silent child.
  EXPECT_GE(std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count(), 1.0);
}

// A required child that keeps dying before its first heartbeat, with respawn on, must still hit
// its readiness timeout (measured from the group's start, not from each respawn): exit 1.
TEST(Launcher, CrashLoopingChildFailsReadinessDespiteRespawn) {
  const std::string dir = MakeTempDir("launch_crashloop");
  const std::string launch_file = dir + "/launch.yaml";
  std::ofstream(launch_file) << "groups:\n"
                                "  - name: g\n"
                                "    processes:\n"
                                "      - {name: crashy, command: sh, args: [-c, 'sleep 0.3; exit 3'], "
                                "respawn: true, ready_timeout_s: 2}\n";
  RunningProcess launcher({BinPath("orbed-launch"), launch_file, "--duration-s", "30"});
  ASSERT_TRUE(launcher.Wait(20)) << "the launcher hung on a crash-looping child";
  EXPECT_EQ(launcher.exit_code(), 1);
}

// An optional process that ends before its first heartbeat does not hold up the later groups.
TEST(Launcher, OptionalProcessThatEndsEarlyDoesNotBlockTheLaunch) {
  const std::string dir = MakeTempDir("launch_optional");
  const std::string launch_file = dir + "/launch.yaml";
  std::ofstream(launch_file) << "groups:\n"
                                "  - name: first\n"
                                "    processes:\n"
                                "      - {name: quick, command: sh, args: [-c, 'exit 0'], "
                                "required: false, ready_timeout_s: 5}\n"
                                "  - name: second\n"
                                "    processes:\n"
                                "      - {name: monitor, command: orbed-monitor}\n";
  BusWatcher bus;
  bus.Start();
  RunningProcess launcher({BinPath("orbed-launch"), launch_file, "--duration-s", "4"});
  EXPECT_TRUE(WaitFor([&] { return !bus.Heartbeats("monitor").empty(); }, 4))
      << "the second group never started";
  ASSERT_TRUE(launcher.Wait(15));
  EXPECT_EQ(launcher.exit_code(), 0);
}

std::vector<orbed::iiwa_status_t> PublishTraffic(lcm::LCM* lcm, int count, double rate_hz) {
  std::vector<orbed::iiwa_status_t> sent;
  for (int i = 0; i < count; ++i) {
    orbed::iiwa_status_t status{};
    status.utime = i;
    status.num_joints = 7;
    for (auto* v :
         {&status.joint_position_measured, &status.joint_velocity_estimated, &status.joint_position_commanded,
          &status.joint_position_ipo, &status.joint_torque_measured, &status.joint_torque_commanded,
          &status.joint_torque_external}) {
      v->assign(7, 0.001 * i);
    }
    lcm->publish("IIWA_STATUS", &status);
    const std::string blob(1000 + i, static_cast<char>(i));
    lcm->publish("BLOB", blob.data(), static_cast<int>(blob.size()));
    sent.push_back(status);
    std::this_thread::sleep_for(std::chrono::duration<double>(1.0 / rate_hz));
  }
  return sent;
}

// orbed-logger's log, played by lcm-logplayer into lcm-logger: same channels and payloads, same
// order. lcm-logger is the independent oracle.
TEST(Logger, LogPlaysBackIntoLcmLoggerUnchanged) {
  const std::string dir = MakeTempDir("replay");
  const std::string original = dir + "/orbed.lcmlog";
  BusWatcher bus;
  bus.Start();
  {
    RunningProcess logger({BinPath("orbed-logger"), "--file", original, "--channels", "IIWA_STATUS|BLOB",
                           "--name", "replay-logger"});
    lcm::LCM lcm("");
    // Its first heartbeat is published after it subscribed.
    ASSERT_TRUE(WaitFor([&] { return !bus.Heartbeats("replay-logger").empty(); }, 10));
    PublishTraffic(&lcm, 100, 200.0);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    logger.Signal(SIGINT);
    ASSERT_TRUE(logger.Wait(10));
    EXPECT_EQ(logger.exit_code(), 0);
  }
  const std::vector<LogEvent> recorded = ReadLog(original);
  ASSERT_EQ(recorded.size(), 200u) << "orbed-logger missed messages on loopback";

  const std::string copy = dir + "/copy.lcmlog";
  {
    RunningProcess lcm_logger({"/usr/bin/lcm-logger", "-q", "-f", copy});
    // lcm-logger opens its file once it is set up; then give it a moment to subscribe.
    ASSERT_TRUE(WaitFor([&] { return fs::exists(copy); }, 10));
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    RunningProcess player({"/usr/bin/lcm-logplayer", "-s", "2", original});
    ASSERT_TRUE(player.Wait(30));
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    lcm_logger.Signal(SIGINT);
    ASSERT_TRUE(lcm_logger.Wait(10));
  }
  const std::vector<LogEvent> replayed = ReadLog(copy);
  ASSERT_EQ(replayed.size(), recorded.size());
  for (size_t i = 0; i < recorded.size(); ++i) {
    EXPECT_EQ(replayed[i].channel, recorded[i].channel) << "event " << i;
    EXPECT_EQ(replayed[i].data, recorded[i].data) << "event " << i;
  }
}

// SIGKILL during recording: the file is valid up to the last flush; cutting it mid-event in
// addition still reads up to the last whole event.
TEST(Logger, SigkilledLoggerLeavesAReadableLog) {
  const std::string dir = MakeTempDir("sigkill");
  const std::string path = dir + "/killed.lcmlog";
  BusWatcher bus;
  bus.Start();
  RunningProcess logger({BinPath("orbed-logger"), "--file", path, "--channels", "IIWA_STATUS|BLOB",
                         "--flush-interval-s", "0.1", "--name", "killed-logger"});
  lcm::LCM lcm("");
  ASSERT_TRUE(WaitFor([&] { return !bus.Heartbeats("killed-logger").empty(); }, 10));
  PublishTraffic(&lcm, 60, 200.0);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // several flushes
  logger.Signal(SIGKILL);
  ASSERT_TRUE(logger.Wait(5));
  EXPECT_EQ(logger.term_signal(), SIGKILL);

  std::vector<LogEvent> events = ReadLog(path);
  EXPECT_EQ(events.size(), 120u);  // everything was flushed before the kill
  for (const LogEvent& e : events) {
    if (e.channel != "IIWA_STATUS") continue;
    orbed::iiwa_status_t status;
    EXPECT_EQ(status.decode(e.data.data(), 0, e.data.size()), static_cast<int>(e.data.size()));
  }
  // Cut in the middle of the last event's payload.
  const auto size = fs::file_size(path);
  fs::resize_file(path, size - events.back().data.size() / 2);
  events = ReadLog(path);
  EXPECT_EQ(events.size(), 119u);
}

}  // namespace
}  // namespace orbed::testing
