// The ViRAAl run of scripts/launch/viraal.yaml over a lossy bus. The launch runs with ORBED_CHAOS
// set, so every participant (sim, registration server, headset, conductor; the logger records the
// bus unharmed) loses 10 % of the datagrams it receives on every control channel, receives 5 %
// twice, 5 % after the next one, and every one up to 30 ms late (runtime/chaos.h). The
// conductor's retries and the receivers' idempotent answers must carry the run to exactly the
// results of a clean run with the same run id: testdata/viraal_pinned_results.json, number for
// number, including rejected_inputs = 0 (no duplicate was refused).
//
// Beside the run a watcher hears the bus as sent (it injects nothing) and checks that the faults
// did force retries, and that no retried REQUEST_TRIAL produced a second, different trial: every
// copy of a trial is byte for byte the first.
//
// No sleeps synchronise anything: the test waits for the launcher to exit (deadline 240 s; a run
// takes about 10 s).
#include <atomic>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <lcm/lcm-cpp.hpp>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/session_control_t.hpp>

#include "lcmtypes/bounded_decode.h"
#include "tests/integration/testbed_util.h"
#include "tests/same_tree.h"

namespace orbed::testing {
namespace {

constexpr char kChaos[] =
    "drop=0.1,dup=0.05,delay_ms=30,reorder=0.05,seed=1,"
    "channels=SESSION_CONTROL|ALIGNMENT_TRIAL|REGISTRATION|PLAN_CHECK_REQUEST|PLAN_CHECK_REPLY|"
    "MISALIGNMENT_REQUEST|MISALIGNMENT|LANDMARK_REQUEST|LANDMARK|IIWA_COMMAND";

// Every ALIGNMENT_TRIAL and SESSION_CONTROL on the bus, as sent, on its own thread. An 8 MB receive
// buffer, like the processes', so that the images on the group do not crowd them out.
class Watcher {
 public:
  Watcher() : lcm_("udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608") {
    if (!lcm_.good()) throw std::runtime_error("LCM not available (multicast route?)");
    lcm_.subscribe("ALIGNMENT_TRIAL", &Watcher::OnTrial, this);
    lcm_.subscribe("SESSION_CONTROL", &Watcher::OnControl, this);
    thread_ = std::thread([this] {
      while (!stop_) lcm_.handleTimeout(20);
    });
  }
  ~Watcher() {
    stop_ = true;
    thread_.join();
  }
  // Copies of each trial, by (session, index).
  std::map<std::pair<std::string, int>, std::vector<std::vector<uint8_t>>> Trials() {
    std::lock_guard<std::mutex> lock(mutex_);
    return trials_;
  }
  // SESSION_CONTROL datagrams, and their distinct request ids.
  std::pair<int, int> Controls() {
    std::lock_guard<std::mutex> lock(mutex_);
    return {controls_, static_cast<int>(control_ids_.size())};
  }

 private:
  void OnTrial(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    orbed::alignment_trial_t trial;
    if (!DecodeBounded(rbuf->data, rbuf->data_size, &trial).ok()) return;
    const auto* bytes = static_cast<const uint8_t*>(rbuf->data);
    std::lock_guard<std::mutex> lock(mutex_);
    trials_[{trial.session_id, trial.trial_index}].emplace_back(bytes, bytes + rbuf->data_size);
  }
  void OnControl(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    orbed::session_control_t control;
    if (!DecodeBounded(rbuf->data, rbuf->data_size, &control).ok()) return;
    std::lock_guard<std::mutex> lock(mutex_);
    ++controls_;
    control_ids_.insert(control.request_id);
  }

  lcm::LCM lcm_;
  std::mutex mutex_;
  std::map<std::pair<std::string, int>, std::vector<std::vector<uint8_t>>> trials_;
  int controls_ = 0;
  std::set<int64_t> control_ids_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

TEST(ViraalChaos, ALossyBusGivesTheCleanRunsResults) {
  Watcher watcher;
  const std::string log_dir = MakeTempDir("viraal_chaos");
  RunningProcess launcher({BinPath("orbed-launch"), SourcePath("scripts/launch/viraal.yaml"), "--duration-s",
                           "240", "--arg", "run_id=pinned"},
                          {{"ORBED_LOG_DIR", log_dir}, {"ORBED_CHAOS", kChaos}});
  ASSERT_TRUE(launcher.Wait(240)) << "the run did not finish";
  EXPECT_EQ(launcher.term_signal(), 0);
  ASSERT_EQ(launcher.exit_code(), 0);

  // The clean run's numbers, exactly (results.json is JSON, which YAML reads).
  const YAML::Node results = YAML::LoadFile(log_dir + "/results.json");
  EXPECT_EQ(results["status"].as<std::string>(), "ok") << results["error"].as<std::string>();
  const YAML::Node pinned =
      YAML::LoadFile(SourcePath("tests/integration/testdata/viraal_pinned_results.json"));
  ExpectSameTree(pinned, results, "results", {"started_utime", "duration_s"});

  // The faults forced retries: a clean run sends 12 SESSION_CONTROLs (per session START, 3
  // REQUEST_TRIAL, COMPUTE, STOP), each with its own request id; here some went out again.
  const auto [controls, control_ids] = watcher.Controls();
  EXPECT_EQ(control_ids, 12);
  EXPECT_GT(controls, control_ids) << "no request was re-sent: was the chaos spec applied?";
  // Six trials, however often each was asked for: every copy is the first, byte for byte.
  const auto trials = watcher.Trials();
  EXPECT_EQ(trials.size(), 6u);
  for (const auto& [key, copies] : trials) {
    for (const std::vector<uint8_t>& copy : copies) {
      EXPECT_EQ(copy, copies.front())
          << key.first << " trial " << key.second << " has two different versions";
    }
  }

  // The logger (no fault injection of its own) recorded the bus whole: at least what the watcher
  // heard.
  const YAML::Node manifest = YAML::LoadFile(log_dir + "/manifest.json");
  EXPECT_TRUE(manifest["complete"].as<bool>());
  EXPECT_EQ(manifest["drops"].as<int>(), 0);
  EXPECT_GE(manifest["channels"]["SESSION_CONTROL"]["events"].as<int>(), controls);
}

}  // namespace
}  // namespace orbed::testing
