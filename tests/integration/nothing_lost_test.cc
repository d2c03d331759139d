// Nothing lost on the way down: what is left after the logger or the launcher is killed outright,
// and after the log's disk fills up. Real processes over real LCM (scripts/netns-exec); the full
// disk is a 256 KiB tmpfs mounted in a mount namespace of the test's own (root only).
//   - the logger SIGKILLed mid-recording: part 1 reads, with LCM's own C reader
//     (lcm_eventlog_read_next_event, what lcm-logplayer uses) and with `orbed-log check`, to its
//     last whole event, exactly as the manifest lists it; the respawned logger records part 2;
//     the run ends cleanly;
//   - the logger on a full disk: exit code 74 (kExitCannotWrite), a last line naming the file,
//     ENOSPC, the file's size on disk and its whole events; under orbed-launch it is not respawned
//     and the launch fails with that line;
//   - orbed-launch SIGKILLed: none of its processes is left (read from /proc), not even one that
//     ignores SIGINT and SIGTERM. (The same across hosts, through a deputy's orphan timeout:
//     hosts_integration_test.)
#include <sched.h>
#include <signal.h>
#include <sys/mount.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/eventlog.h>
#include <lcm/lcm-cpp.hpp>

#include "procs/logger/manifest.h"
#include "runtime/process.h"
#include "tests/integration/testbed_util.h"

namespace orbed::testing {
namespace {

namespace fs = std::filesystem;

// What LCM's own reader finds in a log: its whole events (each payload's first 8 bytes are the
// publisher's sequence number) and their bytes (header, channel, data).
struct LcmRead {
  int64_t events = 0;
  int64_t bytes = 0;
  std::vector<int64_t> sequence;
};

LcmRead ReadWithLcm(const std::string& path) {
  LcmRead read;
  lcm_eventlog_t* log = lcm_eventlog_create(path.c_str(), "r");
  EXPECT_NE(log, nullptr) << path;
  if (log == nullptr) return read;
  while (lcm_eventlog_event_t* event = lcm_eventlog_read_next_event(log)) {
    ++read.events;
    read.bytes += 4 + 8 + 8 + 4 + 4 + event->channellen + event->datalen;
    int64_t sequence = -1;
    if (event->datalen >= 8) std::memcpy(&sequence, event->data, 8);
    read.sequence.push_back(sequence);
    lcm_eventlog_free_event(event);
  }
  lcm_eventlog_destroy(log);
  return read;
}

// Publishes BLOB messages numbered 0, 1, ... (200 to 2200 bytes) every millisecond on its own
// thread until destroyed.
class Publisher {
 public:
  Publisher()
      : thread_([this] {
          lcm::LCM lcm("");
          for (int64_t i = 0; !stop_; ++i) {
            std::string payload(200 + static_cast<size_t>(i % 2000), static_cast<char>('a' + i % 26));
            std::memcpy(payload.data(), &i, 8);
            lcm.publish("BLOB", payload.data(), static_cast<unsigned>(payload.size()));
            std::this_thread::sleep_for(std::chrono::milliseconds(1));  // a rate, not a wait
          }
        }) {}
  ~Publisher() {
    stop_ = true;
    thread_.join();
  }

 private:
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// `orbed-log check PATH`: its exit code and its summary line.
std::pair<int, std::string> OrbedLogCheck(const std::string& path) {
  RunningProcess check({BinPath("orbed-log"), "check", path});
  EXPECT_TRUE(check.Wait(60));
  return {check.exit_code(), check.lines().empty() ? "" : check.lines().back()};
}

// What `orbed-log check` says of a log of `events` whole events and `damaged` other bytes.
std::string CheckSummary(const std::string& path, int64_t events, int64_t damaged) {
  return path + ": " + std::to_string(events) + " events read, " + std::to_string(damaged) + " of " +
         std::to_string(fs::file_size(path)) + " bytes damaged in " + (damaged > 0 ? "1" : "0") + " range(s)";
}

// A 256 KiB tmpfs at `dir`, in a mount namespace of this thread's own (the processes it starts
// inherit it; nothing outside sees it). Unmounted when destroyed.
class SmallDisk {
 public:
  explicit SmallDisk(const std::string& dir) : dir_(dir) {
    fs::create_directories(dir);
    ok_ = unshare(CLONE_NEWNS) == 0 && mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) == 0 &&
          mount("tmpfs", dir.c_str(), "tmpfs", 0, "size=256k") == 0;
    if (!ok_) error_ = std::strerror(errno);
  }
  ~SmallDisk() {
    if (ok_) umount2(dir_.c_str(), MNT_DETACH);
  }
  bool ok() const { return ok_; }
  const std::string& error() const { return error_; }

 private:
  std::string dir_;
  bool ok_ = false;
  std::string error_;
};

constexpr char kNeedsRoot[] = "mounting a tmpfs needs root (CAP_SYS_ADMIN)";

// The last line of `lines` that contains `text`, or "".
std::string LineWith(const std::vector<std::string>& lines, const std::string& text) {
  for (auto it = lines.rbegin(); it != lines.rend(); ++it) {
    if (it->find(text) != std::string::npos) return *it;
  }
  return "";
}

// The pids of the live processes (not zombies) whose environment holds `entry` ("KEY=value").
std::vector<int> PidsWithEnv(const std::string& entry) {
  std::vector<int> pids;
  for (const auto& dir : fs::directory_iterator("/proc")) {
    const std::string name = dir.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream environ(dir.path() / "environ", std::ios::binary);  // empty for a zombie
    for (std::string variable; std::getline(environ, variable, '\0');) {
      if (variable == entry) {
        pids.push_back(std::stoi(name));
        break;
      }
    }
  }
  return pids;
}

TEST(NothingLost, ASigkilledLoggersPartReadsToItsLastEventAndTheRecordingGoesOnInPart2) {
  const std::string dir = MakeTempDir("logger_sigkill");
  const std::string log_dir = dir + "/log";
  std::ofstream(dir + "/launch.yaml") << "name: logger_sigkill\n"
                                         "groups:\n"
                                         "  - name: recording\n"
                                         "    processes:\n"
                                         "      - {name: logger, command: orbed-logger, respawn: true,\n"
                                         "         args: [--log-dir, \""
                                      << log_dir << "\", --channels, BLOB, --flush-interval-s, \"0.05\"]}\n";
  BusWatcher bus;
  bus.Start();
  RunningProcess launcher({BinPath("orbed-launch"), dir + "/launch.yaml"});
  ASSERT_TRUE(WaitFor([&] { return !bus.Heartbeats("logger").empty(); }, 30)) << "no logger";
  const int first_pid = bus.Heartbeats("logger").front().status.pid;
  std::string first_file;
  {
    Publisher publisher;
    // Killed mid-recording: once its part holds 256 KiB, while messages keep coming.
    ASSERT_TRUE(WaitFor(
        [&] {
          for (const auto& entry : fs::directory_iterator(log_dir)) {
            if (entry.path().extension() == ".lcmlog" && entry.file_size() > (256 << 10)) {
              first_file = entry.path().filename().string();
              return true;
            }
          }
          return false;
        },
        60))
        << "the logger did not record";
    ASSERT_EQ(kill(first_pid, SIGKILL), 0);
    ASSERT_TRUE(WaitFor(
        [&] {
          const auto beats = bus.Heartbeats("logger");
          return beats.back().status.pid != first_pid;
        },
        30))
        << "the logger was not respawned";
    const std::string second = log_dir + "/" + logger::PartFileName(first_file, 2);
    ASSERT_TRUE(WaitFor([&] { return fs::exists(second) && fs::file_size(second) > (64 << 10); }, 60))
        << "the respawned logger did not record part 2";
  }
  launcher.Signal(SIGINT);
  ASSERT_TRUE(launcher.Wait(30));
  EXPECT_EQ(launcher.exit_code(), 0) << "the run did not end cleanly";

  const logger::Manifest manifest = logger::ReadManifestFile(log_dir + "/manifest.json");
  EXPECT_TRUE(manifest.complete);
  ASSERT_EQ(manifest.parts.size(), 2u);
  EXPECT_EQ(manifest.parts[0].file, first_file);
  EXPECT_EQ(manifest.parts[1].file, logger::PartFileName(first_file, 2));
  EXPECT_FALSE(manifest.parts[0].complete);
  EXPECT_TRUE(manifest.parts[1].complete);
  std::vector<LcmRead> parts;
  for (const logger::ManifestPart& part : manifest.parts) {
    const std::string path = log_dir + "/" + part.file;
    const LcmRead read = ReadWithLcm(path);
    // LCM's reader stops at the last whole event; the manifest lists exactly what it reads.
    EXPECT_GT(read.events, 0) << part.file;
    EXPECT_EQ(read.events, part.events) << part.file;
    EXPECT_EQ(read.bytes, part.bytes) << part.file;
    EXPECT_EQ(static_cast<int64_t>(fs::file_size(path)) - read.bytes, part.damaged_bytes) << part.file;
    // orbed-log's scanner, the other reader, agrees: at most a torn tail, and only in part 1.
    const auto [code, summary] = OrbedLogCheck(path);
    EXPECT_EQ(summary, CheckSummary(path, read.events, part.damaged_bytes));
    EXPECT_EQ(code, part.damaged_bytes > 0 ? 1 : 0);
    if (&part != &manifest.parts.front()) EXPECT_EQ(part.damaged_bytes, 0);
    // In the order sent.
    EXPECT_TRUE(std::is_sorted(read.sequence.begin(), read.sequence.end())) << part.file;
    EXPECT_EQ(std::set<int64_t>(read.sequence.begin(), read.sequence.end()).size(), read.sequence.size());
    parts.push_back(read);
  }
  EXPECT_LT(parts[0].sequence.back(), parts[1].sequence.front()) << "part 2 repeats part 1";
}

TEST(NothingLost, OnAFullDiskTheLoggerSaysENOSPCWithTheFilesSizeAndExits74) {
  if (geteuid() != 0) GTEST_SKIP() << kNeedsRoot;
  const std::string dir = MakeTempDir("full_disk");
  const std::string log_dir = dir + "/log";
  SmallDisk disk(log_dir);
  ASSERT_TRUE(disk.ok()) << "cannot mount a tmpfs at " << log_dir << ": " << disk.error();
  const std::string path = log_dir + "/run.lcmlog";
  BusWatcher bus;
  bus.Start();
  RunningProcess logger({BinPath("orbed-logger"), "--file", path, "--channels", "BLOB", "--flush-interval-s",
                         "0.05", "--name", "full-logger"});
  ASSERT_TRUE(WaitFor([&] { return !bus.Heartbeats("full-logger").empty(); }, 30));
  {
    Publisher publisher;
    ASSERT_TRUE(logger.Wait(120)) << "the logger went on recording on a full disk";
  }
  EXPECT_EQ(logger.exit_code(), kExitCannotWrite);

  // Its last line: the file, ENOSPC, the bytes and events in the file.
  ASSERT_FALSE(logger.lines().empty());
  const std::string said = logger.lines().back();
  std::smatch match;
  ASSERT_TRUE(std::regex_search(said, match,
                                std::regex("ERROR cannot write " + path +
                                           ": No space left on device \\(ENOSPC\\) after ([0-9]+) bytes, "
                                           "([0-9]+) events")))
      << said;
  const int64_t bytes = std::stoll(match[1]);
  const int64_t events = std::stoll(match[2]);
  EXPECT_EQ(bytes, static_cast<int64_t>(fs::file_size(path)));
  EXPECT_GT(bytes, 200 << 10) << "the disk was not full";
  const LcmRead read = ReadWithLcm(path);
  EXPECT_EQ(read.events, events);
  EXPECT_TRUE(std::is_sorted(read.sequence.begin(), read.sequence.end()));
  const auto [code, summary] = OrbedLogCheck(path);
  EXPECT_EQ(summary, CheckSummary(path, events, bytes - read.bytes));

  // The manifest reads back and says the recording is unfinished; when it could be written, its
  // part says why, with the file's counts.
  const std::string manifest_path = log_dir + "/manifest.json";
  const logger::Manifest manifest = logger::ReadManifestFile(manifest_path);
  EXPECT_FALSE(manifest.complete);
  if (said.find("; recorded in " + manifest_path) != std::string::npos) {
    EXPECT_NE(manifest.parts.back().error.find("(ENOSPC) after " + std::to_string(bytes) + " bytes"),
              std::string::npos);
    EXPECT_EQ(manifest.parts.back().events, events);
  } else {
    EXPECT_NE(said.find("; " + manifest_path + " not updated: cannot write " + manifest_path +
                        ".tmp: No space left on device (ENOSPC)"),
              std::string::npos)
        << said;
  }
}

TEST(NothingLost, ALaunchWhoseLoggerFillsTheDiskFailsWithItsLineAndDoesNotRespawnIt) {
  if (geteuid() != 0) GTEST_SKIP() << kNeedsRoot;
  const std::string dir = MakeTempDir("full_disk_launch");
  const std::string log_dir = dir + "/log";
  SmallDisk disk(log_dir);
  ASSERT_TRUE(disk.ok()) << "cannot mount a tmpfs at " << log_dir << ": " << disk.error();
  std::ofstream(dir + "/launch.yaml") << "name: full_disk\n"
                                         "groups:\n"
                                         "  - name: recording\n"
                                         "    processes:\n"
                                         "      - {name: logger, command: orbed-logger, respawn: true,\n"
                                         "         args: [--log-dir, \""
                                      << log_dir << "\", --channels, BLOB]}\n";
  BusWatcher bus;
  bus.Start();
  RunningProcess launcher({BinPath("orbed-launch"), dir + "/launch.yaml"});
  ASSERT_TRUE(WaitFor([&] { return !bus.Heartbeats("logger").empty(); }, 30)) << "no logger";
  {
    Publisher publisher;
    ASSERT_TRUE(launcher.Wait(120)) << "the launch went on with a full disk";
  }
  EXPECT_EQ(launcher.exit_code(), 1);
  const std::string reason = LineWith(launcher.lines(), "required process 'logger'");
  EXPECT_NE(reason.find("required process 'logger' exited with code 74: it cannot write its output, not "
                        "respawned (it said: ERROR cannot write " +
                        log_dir + "/"),
            std::string::npos)
      << reason;
  EXPECT_NE(reason.find("No space left on device (ENOSPC) after "), std::string::npos) << reason;
  EXPECT_EQ(LineWith(launcher.lines(), "respawning"), "");
  std::set<int> pids;
  for (const auto& beat : bus.Heartbeats("logger")) pids.insert(beat.status.pid);
  EXPECT_EQ(pids.size(), 1u) << "the logger was respawned";
  EXPECT_EQ(logger::ReadManifestFile(log_dir + "/manifest.json").parts.size(), 1u);
}

TEST(NothingLost, ASigkilledLauncherTakesItsProcessesWithIt) {
  const std::string dir = MakeTempDir("launcher_sigkill");
  const std::string mark = "ORBED_RUN_MARK=" + dir;
  // The monitor, and a shell that ignores SIGINT and SIGTERM (as a hung process would) sleeping.
  std::ofstream(dir + "/launch.yaml")
      << "name: launcher_sigkill\n"
         "groups:\n"
         "  - name: g\n"
         "    processes:\n"
         "      - {name: monitor, command: orbed-monitor, env: {ORBED_RUN_MARK: \""
      << dir
      << "\"}}\n"
         "      - {name: deaf, command: sh, args: [-c, 'trap \"\" INT TERM; exec sleep 600'], ready: none,\n"
         "         env: {ORBED_RUN_MARK: \""
      << dir << "\"}}\n";
  BusWatcher bus;
  bus.Start();
  RunningProcess launcher({BinPath("orbed-launch"), dir + "/launch.yaml"});
  ASSERT_TRUE(
      WaitFor([&] { return !bus.Heartbeats("monitor").empty() && PidsWithEnv(mark).size() == 2; }, 30))
      << "the run did not start";
  const std::vector<int> run = PidsWithEnv(mark);
  launcher.Signal(SIGKILL);
  ASSERT_TRUE(launcher.Wait(10));
  EXPECT_EQ(launcher.term_signal(), SIGKILL);
  // At once: PR_SET_PDEATHSIG; the deadline only bounds the wait for the kernel to deliver it.
  EXPECT_TRUE(WaitFor([&] { return PidsWithEnv(mark).empty(); }, 10));
  for (const int pid : run) {
    std::ifstream status("/proc/" + std::to_string(pid) + "/status");
    std::string line;
    while (std::getline(status, line) && line.rfind("State:", 0) != 0) {
    }
    EXPECT_TRUE(line.empty() || line.find("Z (zombie)") != std::string::npos) << pid << ": " << line;
  }
}

}  // namespace
}  // namespace orbed::testing
