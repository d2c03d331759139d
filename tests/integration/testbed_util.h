#pragma once
/// @file
/// Helpers for multi-process integration tests: run real orbed executables (from ORBED_BIN_DIR)
/// and watch the real LCM bus. Tests using these run inside a private network namespace (ctest
/// wraps them in scripts/netns-exec), so the default udpm URL with ttl=0 is private to the test.
///
/// Threading: BusWatcher handles LCM on its own thread; its accessors lock.

#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>
#include <orbed/process_status_t.hpp>

#include "lcmtypes/bounded_decode.h"
#include "procs/launcher/child.h"

namespace orbed::testing {

/// build/bin/<name>, from ORBED_BIN_DIR (set by ctest).
std::string BinPath(const std::string& name);
/// The repository root, from ORBED_SOURCE_DIR (set by ctest).
std::string SourcePath(const std::string& relative);
/// A fresh empty temporary folder; removed at exit when every test passed.
std::string MakeTempDir(const std::string& tag);

/// How much slower than the release build this build runs, declared by the build
/// ($ORBED_TEST_TIME_FACTOR, set by tests/integration/CMakeLists.txt: 4 for the sanitizer build,
/// else 1). Every wall-clock wait below is multiplied by it; waits on the sim clock need none.
double TestTimeFactor();

/// Polls `condition` every 10 ms until true or TestTimeFactor() x `timeout_s` passes; returns its
/// last value.
bool WaitFor(const std::function<bool()>& condition, double timeout_s);

/// Runs a command as a child (own process group); its output goes to this test's stdout with a
/// prefix. Destruction stops it if still running as a user would, with SIGTERM, so that it runs
/// its exit path (and in a sanitizer build its leak check); an exit code other than 0 then, a
/// crash, or no exit within kStopTimeoutS (then SIGKILL) is a test failure.
class RunningProcess {
 public:
  static constexpr double kStopTimeoutS = 20;
  explicit RunningProcess(const std::vector<std::string>& argv,
                          const std::map<std::string, std::string>& env = {});
  ~RunningProcess();
  pid_t pid() const { return child_.pid(); }
  void Signal(int signal) { child_.Signal(signal); }
  /// Waits for exit; returns false on timeout.
  bool Wait(double timeout_s);
  bool running();
  int exit_code() const { return child_.exit_code(); }
  int term_signal() const { return child_.term_signal(); }
  /// Every line it printed so far (read while Wait() or running() drains its output).
  const std::vector<std::string>& lines() const { return lines_; }

 private:
  launcher::Child child_;
  std::string prefix_;
  std::vector<std::string> lines_;
};

/// Listens to PROCESS_STATUS (and anything else subscribed) on the default bus; heartbeats that are
/// not exactly one process_status_t are ignored.
class BusWatcher {
 public:
  BusWatcher();
  ~BusWatcher();
  lcm::LCM& lcm() { return lcm_; }
  struct Beat {
    orbed::process_status_t status;
    std::chrono::steady_clock::time_point received;
  };
  /// Every heartbeat of `name` seen so far.
  std::vector<Beat> Heartbeats(const std::string& name) const;
  /// Starts the handling thread; subscribe before calling this.
  void Start();

 private:
  void OnRaw(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  lcm::LCM lcm_;
  mutable std::mutex mutex_;
  std::map<std::string, std::vector<Beat>> beats_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace orbed::testing
