// Crash recovery end to end (state files, journal, respawn): scripts/launch/viraal.yaml through
// orbed-launch with run id "pinned", in a private network namespace, while the test SIGKILLs
// processes at moments it picks from what it sees on the bus (no sleeps):
//   - the registration server after trial 0 of session 0 (its journal holds the session), and the
//     logger after trial 1 of session 1 (the recording goes on in a second part), each while the
//     test holds the arm (SIGSTOP of the sim from the moment the trial arrives, SIGCONT once the
//     respawned process has sent its first heartbeat): the server so that the conductor's 5 s
//     reply timeout does not race a respawn on a busy machine, the logger so that nothing is sent
//     while nobody records;
//   - the headset the moment the REQUEST_TRIAL for trial 1 of session 1 arrives, with no hold: the
//     request is in flight to a process that is dying (or has just answered it). The conductor
//     re-sends it (every request is retried, every answer idempotent) until the respawned
//     headset, restored from its state file, answers; the trial is the one the first headset would have made;
//   - the sim while the arm moves from configuration 1 to 2 in session 0: it comes back at the
//     last configuration it saved, and the conductor's re-sent IIWA_COMMAND takes it on.
// The run must complete with results.json equal, number for number, to the pinned uninterrupted
// run; the respawned sim must start at a configuration the old one published in its last 150 ms of
// sim time (not at zero); the manifest must list both log parts with what is really in them, and
// the parts together must hold every protocol message of the run exactly once, in order.
//
// Then the conductor: SIGKILLed after the first trial of session 1, the launch ends with exit
// code 1 and a results.json marked "partial"; a second launch with --arg resume= the first
// run's folder completes it, and its results.json equals the pinned run's.
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <lcm/lcm-cpp.hpp>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/logger_status_t.hpp>
#include <orbed/process_status_t.hpp>
#include <orbed/registration_t.hpp>
#include <orbed/robot_state_t.hpp>
#include <orbed/session_control_t.hpp>

#include "base/units.h"
#include "lcmtypes/bounded_decode.h"
#include "procs/logger/event_log_reader.h"
#include "procs/logger/manifest.h"
#include "runtime/flags.h"
#include "tests/integration/testbed_util.h"
#include "tests/same_tree.h"

namespace orbed::testing {
namespace {

namespace fs = std::filesystem;

// The protocol's messages: what the conductor, the server and the headset exchange. (IIWA_COMMAND
// is re-sent every 0.25 s and REGISTRATION also comes periodically: neither is in this list's
// check of the log, since some are sent while the logger is down.)
const std::set<std::string> kProtocolChannels = {
    "PLAN_CHECK_REQUEST",   "PLAN_CHECK_REPLY", "SESSION_CONTROL", "ALIGNMENT_TRIAL",
    "MISALIGNMENT_REQUEST", "MISALIGNMENT",     "REGISTRATION"};

// The pinned scenario's configurations [deg] (experiments/viraal/viraal.yaml).
const std::vector<std::vector<double>> kConfigurationsDeg = {
    {0, 30, 0, -60, 0, 45, 0}, {40, 20, -30, -80, 20, 50, 30}, {-35, 30, 20, -65, -15, 50, -40}};

int64_t WallMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Everything the test watches on the bus, recorded on LCM's thread; `on_trial` and `on_robot`
// run there too, so a hold or a kill follows the message that calls for it within microseconds.
class Recorder {
 public:
  struct Message {
    std::string channel;
    std::string bytes;
  };
  struct Robot {
    int64_t utime;
    int64_t received_wall;
    std::vector<double> q;
    int8_t motion;
  };

  std::function<void(const orbed::alignment_trial_t&)> on_trial;
  // Called with the number of REQUEST_TRIALs seen so far, on each new request id.
  std::function<void(int)> on_trial_request;
  std::function<void(const Robot&)> on_robot;

  Recorder() : lcm_(WithRecvBufSize(DefaultLcmUrl(), 8 << 20)) {
    if (!lcm_.good()) throw std::runtime_error("LCM not available (multicast route?)");
    // Not the images: only what the test looks at, with a queue that holds a busy moment's worth.
    lcm_.subscribe(
            "ROBOT_STATE|LOGGER_STATUS|PROCESS_STATUS|PLAN_CHECK_REQUEST|PLAN_CHECK_REPLY|SESSION_CONTROL|"
            "ALIGNMENT_TRIAL|MISALIGNMENT_REQUEST|MISALIGNMENT|REGISTRATION",
            &Recorder::OnMessage, this)
        ->setQueueCapacity(100000);
    thread_ = std::thread([this] {
      while (!stop_) lcm_.handleTimeout(20);
    });
  }
  ~Recorder() {
    stop_ = true;
    thread_.join();
  }

  std::vector<Message> Protocol() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return protocol_;
  }
  int Count(const std::string& channel) const {
    std::lock_guard<std::mutex> lock(mutex_);
    return static_cast<int>(std::count_if(protocol_.begin(), protocol_.end(),
                                          [&](const Message& m) { return m.channel == channel; }));
  }
  int RequestedTrials() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return requested_trials_;
  }
  std::vector<Robot> RobotStates() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return robot_;
  }
  // The pids `name` has heartbeated from, in order of their first heartbeat.
  std::vector<int> Pids(const std::string& name) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = pids_.find(name);
    return it == pids_.end() ? std::vector<int>{} : it->second;
  }
  int64_t LastFlushUtime() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_flush_utime_;
  }

 private:
  void OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    if (channel == "PROCESS_STATUS") {
      orbed::process_status_t status;
      if (!DecodeBounded(rbuf->data, rbuf->data_size, &status).ok()) return;
      std::lock_guard<std::mutex> lock(mutex_);
      std::vector<int>& pids = pids_[status.name];
      if (status.state <= orbed::process_status_t::STATE_RUNNING &&
          std::find(pids.begin(), pids.end(), status.pid) == pids.end()) {
        pids.push_back(status.pid);
      }
    } else if (channel == "LOGGER_STATUS") {
      orbed::logger_status_t status;
      if (!DecodeBounded(rbuf->data, rbuf->data_size, &status).ok()) return;
      std::lock_guard<std::mutex> lock(mutex_);
      last_flush_utime_ = std::max(last_flush_utime_, status.last_flush_utime);
    } else if (channel == "ROBOT_STATE") {
      orbed::robot_state_t state;
      if (!DecodeBounded(rbuf->data, rbuf->data_size, &state).ok()) return;
      const Robot robot{state.utime, WallMicros(), state.joint_position, state.motion_state};
      {
        std::lock_guard<std::mutex> lock(mutex_);
        robot_.push_back(robot);
      }
      if (on_robot) on_robot(robot);
    } else if (kProtocolChannels.count(channel)) {
      const std::string bytes(static_cast<const char*>(rbuf->data), rbuf->data_size);
      if (channel == "REGISTRATION") {
        orbed::registration_t registration;
        if (!DecodeBounded(rbuf->data, rbuf->data_size, &registration).ok() ||
            registration.reason == orbed::registration_t::REASON_PERIODIC) {
          return;
        }
      }
      orbed::alignment_trial_t trial;
      const bool is_trial =
          channel == "ALIGNMENT_TRIAL" && DecodeBounded(rbuf->data, rbuf->data_size, &trial).ok();
      int new_request = 0;  // the count, when this is a REQUEST_TRIAL with a new id
      {
        std::lock_guard<std::mutex> lock(mutex_);
        protocol_.push_back({channel, bytes});
        orbed::session_control_t control;
        if (channel == "SESSION_CONTROL" && DecodeBounded(rbuf->data, rbuf->data_size, &control).ok() &&
            control.command == orbed::session_control_t::REQUEST_TRIAL &&
            trial_request_ids_.insert(control.request_id).second) {
          new_request = ++requested_trials_;
        }
      }
      if (is_trial && on_trial) on_trial(trial);
      if (new_request > 0 && on_trial_request) on_trial_request(new_request);
    }
  }

  lcm::LCM lcm_;
  mutable std::mutex mutex_;
  std::vector<Message> protocol_;
  std::vector<Robot> robot_;
  std::map<std::string, std::vector<int>> pids_;
  int64_t last_flush_utime_ = 0;
  int requested_trials_ = 0;
  std::set<int64_t> trial_request_ids_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// SIGSTOP of a process for as long as it lives (SIGCONT at the latest at destruction, so that a
// failing test never leaves a stopped process behind).
class Hold {
 public:
  void Start(int pid) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (pid_ != 0 || pid <= 0) return;
    pid_ = pid;
    kill(pid, SIGSTOP);
  }
  bool held() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return pid_ != 0;
  }
  void Release() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (pid_ != 0) kill(pid_, SIGCONT);
    pid_ = 0;
  }
  ~Hold() { Release(); }

 private:
  mutable std::mutex mutex_;
  int pid_ = 0;
};

int LatestPid(const Recorder& bus, const std::string& name) {
  const std::vector<int> pids = bus.Pids(name);
  return pids.empty() ? 0 : pids.back();
}

// SIGKILLs `name`'s current instance and waits for the launcher's new one to heartbeat.
void KillAndWaitForRespawn(const Recorder& bus, const std::string& name) {
  const int pid = LatestPid(bus, name);
  ASSERT_GT(pid, 0) << name;
  ASSERT_EQ(kill(pid, SIGKILL), 0) << name;
  ASSERT_TRUE(WaitFor([&] { return bus.Pids(name).size() >= 2 && LatestPid(bus, name) != pid; }, 30))
      << name << " was not respawned";
}

TEST(CrashRecovery, KilledProcessesComeBackAndTheRunEndsWithTheUninterruptedResults) {
  const std::string dir = MakeTempDir("crash_recovery");
  Recorder bus;
  Hold hold;
  // The holds, in order of the trials that call for them: session 0 trial 0 (registration), session
  // 1 trial 1 (logger).
  const std::vector<std::pair<std::string, int>> hold_after = {{"pinned-ar_reflective", 0}, {"pinned-ar", 1}};
  bus.on_trial = [&](const orbed::alignment_trial_t& trial) {
    for (const auto& [session, index] : hold_after) {
      if (trial.session_id == session && trial.trial_index == index) hold.Start(LatestPid(bus, "sim"));
    }
  };
  // The sim killed on the way from configuration 1 to 2 in session 0, 20 % to 80 % of the way.
  std::atomic<bool> sim_killed{false};
  std::atomic<int64_t> sim_killed_wall{0};
  bus.on_robot = [&](const Recorder::Robot& robot) {
    if (sim_killed || bus.Count("MISALIGNMENT") != 2 || robot.motion != orbed::robot_state_t::MOTION_MOVING)
      return;
    const double s = (robot.q[0] * kRadToDeg - 40.0) / (-35.0 - 40.0);
    if (s < 0.2 || s > 0.8) return;
    const int pid = LatestPid(bus, "sim");
    sim_killed_wall = WallMicros();
    sim_killed = kill(pid, SIGKILL) == 0;
  };

  // The headset, the moment the request for trial 1 of session 1 (the fifth) arrives.
  std::atomic<bool> hmd_killed{false};
  bus.on_trial_request = [&](int requests) {
    if (requests == 5 && !hmd_killed) hmd_killed = kill(LatestPid(bus, "hmd"), SIGKILL) == 0;
  };

  RunningProcess launcher({BinPath("orbed-launch"), SourcePath("scripts/launch/viraal.yaml"), "--duration-s",
                           "240", "--arg", "run_id=pinned"},
                          {{"ORBED_LOG_DIR", dir}});

  // 1. The registration server, after trial 0 of session 0 is registered (MISALIGNMENT 1).
  ASSERT_TRUE(WaitFor([&] { return hold.held() && bus.Count("MISALIGNMENT") >= 1; }, 120)) << "no trial 0";
  ASSERT_EQ(bus.RequestedTrials(), 1);
  KillAndWaitForRespawn(bus, "registration");
  ASSERT_EQ(bus.RequestedTrials(), 1) << "a trial was requested while the server was down";
  hold.Release();

  // 2. The sim, mid-move (bus.on_robot).
  ASSERT_TRUE(WaitFor([&] { return sim_killed.load(); }, 60)) << "the sim was not killed mid-move";
  ASSERT_TRUE(WaitFor([&] { return bus.Pids("sim").size() >= 2; }, 30)) << "the sim was not respawned";

  // 3. The headset, killed by bus.on_trial_request as the request for trial 1 of session 1 (the
  // fifth) arrives; the conductor's retries reach the respawned one.
  ASSERT_TRUE(WaitFor([&] { return hmd_killed.load(); }, 60)) << "no fifth REQUEST_TRIAL";
  ASSERT_TRUE(WaitFor([&] { return bus.Pids("hmd").size() >= 2; }, 30)) << "the headset was not respawned";

  // 4. The logger, after trial 1 of session 1, once it has flushed a second after the trial's
  // MISALIGNMENT (everything before it is then in its part).
  ASSERT_TRUE(WaitFor([&] { return hold.held() && bus.Count("MISALIGNMENT") >= 6; }, 60)) << "no trial 1";
  const int64_t flushed_after = WallMicros() + 1'000'000;
  ASSERT_TRUE(WaitFor([&] { return bus.LastFlushUtime() > flushed_after; }, 30))
      << "the logger did not flush";
  const size_t protocol_before_logger_kill = bus.Protocol().size();
  KillAndWaitForRespawn(bus, "logger");
  ASSERT_EQ(bus.Protocol().size(), protocol_before_logger_kill)
      << "protocol traffic while the logger was down";
  hold.Release();

  ASSERT_TRUE(launcher.Wait(180)) << "the run did not finish";
  ASSERT_EQ(launcher.exit_code(), 0);

  // The results of the run that was never interrupted.
  const YAML::Node results = YAML::LoadFile(dir + "/results.json");
  EXPECT_EQ(results["status"].as<std::string>(), "ok");
  ExpectSameTree(YAML::LoadFile(SourcePath("tests/integration/testdata/viraal_pinned_results.json")), results,
                 "results", {"started_utime", "duration_s"});

  // The respawned sim started where the arm was: a configuration the old sim published within its
  // last 150 ms, and not zero.
  const std::vector<Recorder::Robot> robot = bus.RobotStates();
  const auto first_new = std::find_if(robot.begin(), robot.end(), [&](const Recorder::Robot& r) {
    return r.utime > sim_killed_wall.load();  // stamped by the new sim's clock
  });
  ASSERT_NE(first_new, robot.end());
  int64_t last_old_utime = 0;
  for (auto it = robot.begin(); it != first_new; ++it) last_old_utime = std::max(last_old_utime, it->utime);
  const auto same_q = std::find_if(robot.begin(), first_new, [&](const Recorder::Robot& r) {
    return r.q == first_new->q && r.utime >= last_old_utime - 150'000;
  });
  EXPECT_NE(same_q, first_new)
      << "the respawned sim's first configuration is not one the old sim published last";
  EXPECT_GT(std::abs(first_new->q[0]), 10 * kDegToRad) << "the respawned sim started at zero";

  // Every respawned process heartbeated from two pids.
  for (const char* name : {"registration", "sim", "hmd", "logger"})
    EXPECT_EQ(bus.Pids(name).size(), 2u) << name;
  EXPECT_TRUE(fs::exists(dir + "/sim.state") && fs::exists(dir + "/hmd.state") &&
              fs::exists(dir + "/registration.journal"));

  // The recording: two parts, listed with what is really in them; together they hold every
  // protocol message of the run once, in order.
  const logger::Manifest manifest = logger::ReadManifestFile(dir + "/manifest.json");
  EXPECT_TRUE(manifest.complete);
  ASSERT_EQ(manifest.parts.size(), 2u);
  EXPECT_FALSE(manifest.parts[0].complete);
  EXPECT_TRUE(manifest.parts[1].complete);
  EXPECT_EQ(manifest.parts[1].file, logger::PartFileName(manifest.parts[0].file, 2));
  std::vector<Recorder::Message> logged;
  for (const logger::ManifestPart& part : manifest.parts) {
    const logger::MappedLog log(dir + "/" + part.file);
    ASSERT_TRUE(log.ok()) << log.error();
    logger::EventLogScanner scanner = log.Scanner();
    logger::LogEvent event;
    int64_t events = 0;
    while (scanner.Next(&event)) {
      ++events;
      if (!kProtocolChannels.count(event.channel)) continue;
      orbed::registration_t registration;
      if (event.channel == "REGISTRATION" && DecodeBounded(event.data, event.size, &registration).ok() &&
          registration.reason == orbed::registration_t::REASON_PERIODIC) {
        continue;
      }
      logged.push_back({event.channel, std::string(reinterpret_cast<const char*>(event.data), event.size)});
    }
    EXPECT_EQ(events, part.events) << part.file;
    EXPECT_EQ(static_cast<int64_t>(scanner.damaged_bytes()), part.damaged_bytes) << part.file;
    // Damage only as a torn tail of the part whose logger was killed.
    for (const logger::LogDamage& damage : scanner.damage()) {
      EXPECT_EQ(damage.offset + damage.bytes, log.size()) << part.file << ": damage inside the part";
    }
  }
  // Per channel in the same order (two senders' datagrams may reach two sockets in either order).
  const std::vector<Recorder::Message> sent = bus.Protocol();
  ASSERT_EQ(logged.size(), sent.size()) << "the log parts do not hold every protocol message once";
  for (const std::string& channel : kProtocolChannels) {
    std::vector<std::string> in_log, on_bus;
    for (const auto& m : logged) {
      if (m.channel == channel) in_log.push_back(m.bytes);
    }
    for (const auto& m : sent) {
      if (m.channel == channel) on_bus.push_back(m.bytes);
    }
    EXPECT_TRUE(in_log == on_bus) << channel << ": " << in_log.size() << " in the log, " << on_bus.size()
                                  << " on the bus";
  }
}

TEST(CrashRecovery, AKilledConductorLeavesPartialResultsAndResumeCompletesTheRun) {
  const std::string first = MakeTempDir("conductor_killed");
  {
    Recorder bus;
    std::atomic<bool> killed{false};
    bus.on_trial = [&](const orbed::alignment_trial_t& trial) {
      if (trial.session_id == "pinned-ar" && trial.trial_index == 0)
        killed = kill(LatestPid(bus, "scenario"), SIGKILL) == 0;
    };
    RunningProcess launcher({BinPath("orbed-launch"), SourcePath("scripts/launch/viraal.yaml"),
                             "--duration-s", "240", "--arg", "run_id=pinned"},
                            {{"ORBED_LOG_DIR", first}});
    ASSERT_TRUE(launcher.Wait(180)) << "the launch did not end";
    ASSERT_TRUE(killed.load());
    EXPECT_EQ(launcher.exit_code(), 1);
  }
  const YAML::Node partial = YAML::LoadFile(first + "/results.json");
  EXPECT_EQ(partial["status"].as<std::string>(), "partial");
  ASSERT_EQ(partial["sessions"].size(), 2u);
  EXPECT_EQ(partial["sessions"][0]["trials"].size(), 3u);
  EXPECT_TRUE(partial["sessions"][0]["mean"].IsMap());
  EXPECT_TRUE(partial["sessions"][1]["mean"].IsNull());
  EXPECT_LE(partial["sessions"][1]["trials"].size(), 1u);

  const std::string second = MakeTempDir("conductor_resumed");
  RunningProcess launcher({BinPath("orbed-launch"), SourcePath("scripts/launch/viraal.yaml"), "--duration-s",
                           "240", "--arg", "resume=" + first},
                          {{"ORBED_LOG_DIR", second}});
  ASSERT_TRUE(launcher.Wait(180)) << "the resumed run did not finish";
  ASSERT_EQ(launcher.exit_code(), 0);
  const YAML::Node results = YAML::LoadFile(second + "/results.json");
  EXPECT_EQ(results["status"].as<std::string>(), "ok");
  EXPECT_EQ(results["resumed_from"].as<std::string>(), first);
  ExpectSameTree(YAML::LoadFile(SourcePath("tests/integration/testdata/viraal_pinned_results.json")), results,
                 "results", {"started_utime", "duration_s", "resumed_from"});
}

// A required process that is respawned but never heartbeats again (it exits at once from its
// second start on) stops the launch with exit code 1 after its ready_timeout_s, rather than being
// respawned for ever.
TEST(CrashRecovery, ARespawnedProcessThatNeverGetsReadyAgainStopsTheLaunch) {
  const std::string dir = MakeTempDir("crash_loop");
  const std::string launch_file = dir + "/launch.yaml";
  std::ofstream(launch_file)
      << "name: crash_loop\n"
         "groups:\n"
         "  - name: g\n"
         "    processes:\n"
         "      - name: flaky\n"
         "        command: sh\n"
         "        args: [-c, 'if [ -e \"$0\" ]; then exit 3; fi; touch \"$0\"; exec \"$1\" \"$2\" \"$3\"', \""
      << dir << "/started\", \"" << BinPath("orbed-monitor")
      << "\"]\n"
         "        respawn: true\n"
         "        ready_timeout_s: 2\n";
  Recorder bus;
  RunningProcess launcher({BinPath("orbed-launch"), launch_file});
  ASSERT_TRUE(WaitFor([&] { return LatestPid(bus, "flaky") > 0; }, 30)) << "no first heartbeat";
  ASSERT_EQ(kill(LatestPid(bus, "flaky"), SIGKILL), 0);
  ASSERT_TRUE(launcher.Wait(30)) << "the launcher kept respawning";
  EXPECT_EQ(launcher.exit_code(), 1);
}

}  // namespace
}  // namespace orbed::testing
