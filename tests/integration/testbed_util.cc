#include "tests/integration/testbed_util.h"

#include "base/source_paths.h"

#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace orbed::testing {

std::string BinPath(const std::string& name) {
  const char* dir = std::getenv("ORBED_BIN_DIR");
  if (dir == nullptr) throw std::runtime_error("ORBED_BIN_DIR is not set (run through ctest)");
  return std::string(dir) + "/" + name;
}

std::string SourcePath(const std::string& relative) { return orbed::SourceTreePath(relative); }

namespace {

std::vector<std::filesystem::path>& TempDirs() {
  static std::vector<std::filesystem::path> dirs;
  return dirs;
}

// At exit: the folders go when every test passed; after a failure they stay for inspection.
void RemoveTempDirsIfPassed() {
  if (!::testing::UnitTest::GetInstance()->Passed()) return;
  std::error_code ec;
  for (const auto& dir : TempDirs()) std::filesystem::remove_all(dir, ec);
}

}  // namespace

std::string MakeTempDir(const std::string& tag) {
  const auto dir = std::filesystem::temp_directory_path() / ("orbed_" + tag + "_" + std::to_string(getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  if (TempDirs().empty()) std::atexit(RemoveTempDirsIfPassed);
  TempDirs().push_back(dir);
  return dir.string();
}

double TestTimeFactor() {
  const char* text = std::getenv("ORBED_TEST_TIME_FACTOR");
  const double factor = text == nullptr ? 1.0 : std::atof(text);
  return factor >= 1.0 && factor <= 100.0 ? factor : 1.0;
}

bool WaitFor(const std::function<bool()>& condition, double timeout_s) {
  timeout_s *= TestTimeFactor();
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                             std::chrono::duration<double>(timeout_s));
  while (std::chrono::steady_clock::now() < deadline) {
    if (condition()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return condition();
}

RunningProcess::RunningProcess(const std::vector<std::string>& argv,
                               const std::map<std::string, std::string>& env)
    : prefix_(std::filesystem::path(argv.at(0)).filename().string() + " | ") {
  std::string error;
  child_.CopyLinesTo(&lines_);
  if (!child_.Start(argv, env, "", &error)) throw std::runtime_error(error);
}

RunningProcess::~RunningProcess() {
  if (!child_.Poll()) {
    child_.Signal(SIGTERM);
    if (Wait(kStopTimeoutS)) {
      // Killed by the SIGTERM itself: it was still starting, before its handler was installed.
      const bool clean = child_.exit_code() == 0 || child_.term_signal() == SIGTERM;
      if (!clean) ADD_FAILURE() << prefix_ << child_.DescribeExit() << " on SIGTERM";
    } else {
      ADD_FAILURE() << prefix_ << "did not stop within " << kStopTimeoutS << " s of SIGTERM: SIGKILL";
      child_.Signal(SIGKILL);
      Wait(5);
    }
  }
  child_.Drain(prefix_, true);
}

bool RunningProcess::Wait(double timeout_s) {
  return WaitFor(
      [this] {
        child_.Drain(prefix_);
        return child_.Poll();
      },
      timeout_s);
}

bool RunningProcess::running() {
  child_.Drain(prefix_);
  return !child_.Poll();
}

BusWatcher::BusWatcher() : lcm_("") {
  if (!lcm_.good()) throw std::runtime_error("LCM not available (multicast route?)");
  // Decoded with DecodeBounded: tests publish hostile heartbeats too.
  lcm_.subscribe("PROCESS_STATUS", &BusWatcher::OnRaw, this);
}

void BusWatcher::Start() {
  thread_ = std::thread([this] {
    while (!stop_) lcm_.handleTimeout(20);
  });
}

BusWatcher::~BusWatcher() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void BusWatcher::OnRaw(const lcm::ReceiveBuffer* rbuf, const std::string&) {
  orbed::process_status_t msg;
  if (!DecodeBounded(rbuf->data, rbuf->data_size, &msg).ok()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  beats_[msg.name].push_back(Beat{msg, std::chrono::steady_clock::now()});
}

std::vector<BusWatcher::Beat> BusWatcher::Heartbeats(const std::string& name) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = beats_.find(name);
  return it == beats_.end() ? std::vector<Beat>{} : it->second;
}

}  // namespace orbed::testing
