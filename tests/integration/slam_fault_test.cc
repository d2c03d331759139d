// SLAM faults during a run: the ViRAAl run of scripts/launch/viraal.yaml, with
// the headset given a config (--arg hmd_config=FILE, orbed-hmd --config) that forces tracking faults while
// the person aligns in two trials (slam.faults, hmd_emulator/slam_model.h):
//   ar_reflective trial 1: LOST for 2 s, 1 s into the alignment, then a 3 cm relocalization jump;
//   ar trial 2:            LIMITED for 0.5 s at 0.5 s (no jump), then LOST for 1 s at 2 s with a
//                          2 cm jump.
// The drawn tracking losses are turned off in that config (rate_per_min: 0), so every fault on
// the bus is a forced one. The run must complete (status ok, 2 sessions × 3 trials, the launcher
// exits 0); the faulted trials must carry the forced counts on ALIGNMENT_TRIAL and in results.json
// (the others none); and between each faulted trial's REQUEST_TRIAL and its ALIGNMENT_TRIAL,
// HMD_POSE on the bus must show the forced states in order, each fault ending in RELOCALIZED.
//
// No sleeps synchronise anything: the test waits for the launcher to exit (deadline 240 s).
#include <atomic>
#include <fstream>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <lcm/lcm-cpp.hpp>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/hmd_pose_t.hpp>
#include <orbed/session_control_t.hpp>

#include "lcmtypes/bounded_decode.h"
#include "tests/integration/testbed_util.h"

namespace orbed::testing {
namespace {

using HP = orbed::hmd_pose_t;

constexpr char kFaults[] = R"(slam:
  tracking_loss: {rate_per_min: 0}
  faults:
    - {session: slamfault-ar_reflective, trial: 1, at_s: 1.0, state: lost, duration_s: 2.0,
       jump: {position_m: [0.03, 0, 0]}}
    - {session: slamfault-ar, trial: 2, at_s: 0.5, state: limited, duration_s: 0.5}
    - {session: slamfault-ar, trial: 2, at_s: 2.0, state: lost, duration_s: 1.0,
       jump: {position_m: [0, 0.02, 0], yaw_deg: 0.5}}
)";

// The bus in the order heard, on its own thread: REQUEST_TRIALs, ALIGNMENT_TRIALs and the tracking
// state of every HMD_POSE. An 8 MB receive buffer, like the processes', so that the images on the
// group do not crowd them out.
class Watcher {
 public:
  struct Event {
    enum Kind { kRequest, kTrial, kPose } kind;
    int64_t request_id{0};
    int tracking_state{0};
    orbed::alignment_trial_t trial;
  };
  Watcher() : lcm_("udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608") {
    if (!lcm_.good()) throw std::runtime_error("LCM not available (multicast route?)");
    lcm_.subscribe("SESSION_CONTROL", &Watcher::OnControl, this);
    lcm_.subscribe("ALIGNMENT_TRIAL", &Watcher::OnTrial, this);
    lcm_.subscribe("HMD_POSE", &Watcher::OnPose, this);
    thread_ = std::thread([this] {
      while (!stop_) lcm_.handleTimeout(20);
    });
  }
  ~Watcher() {
    stop_ = true;
    thread_.join();
  }
  std::vector<Event> Events() {
    std::lock_guard<std::mutex> lock(mutex_);
    return events_;
  }

 private:
  void OnControl(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    orbed::session_control_t msg;
    if (!DecodeBounded(rbuf->data, rbuf->data_size, &msg).ok()) return;
    if (msg.command != orbed::session_control_t::REQUEST_TRIAL) return;
    Add({Event::kRequest, msg.request_id, 0, {}});
  }
  void OnTrial(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    orbed::alignment_trial_t msg;
    if (!DecodeBounded(rbuf->data, rbuf->data_size, &msg).ok()) return;
    Add({Event::kTrial, msg.request_id, 0, msg});
  }
  void OnPose(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    HP msg;
    if (!DecodeBounded(rbuf->data, rbuf->data_size, &msg).ok()) return;
    Add({Event::kPose, 0, msg.tracking_state, {}});
  }
  void Add(Event e) {
    std::lock_guard<std::mutex> lock(mutex_);
    events_.push_back(std::move(e));
  }

  lcm::LCM lcm_;
  std::mutex mutex_;
  std::vector<Event> events_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// The tracking states of the HMD_POSEs heard while the trial answering `request_id` was under way
// (from the first REQUEST_TRIAL with that id to its ALIGNMENT_TRIAL), consecutive repeats folded:
// e.g. {LOST, RELOCALIZED} for 120 LOST samples and one RELOCALIZED.
std::vector<int> StatesWhileAligning(const std::vector<Watcher::Event>& events, int64_t request_id) {
  std::vector<int> states;
  bool open = false;
  for (const Watcher::Event& e : events) {
    if (e.kind == Watcher::Event::kRequest && e.request_id == request_id) open = true;
    if (e.kind == Watcher::Event::kTrial && e.request_id == request_id && open) break;
    if (open && e.kind == Watcher::Event::kPose && e.tracking_state != HP::TRACKING &&
        (states.empty() || states.back() != e.tracking_state)) {
      states.push_back(e.tracking_state);
    }
  }
  return states;
}

TEST(SlamFaults, TheRunCompletesAndTheTrialsRecordTheForcedFaults) {
  Watcher watcher;
  const std::string dir = MakeTempDir("slam_fault");
  const std::string config = dir + "/faults.yaml";
  std::ofstream(config) << kFaults;
  RunningProcess launcher({BinPath("orbed-launch"), SourcePath("scripts/launch/viraal.yaml"), "--duration-s",
                           "240", "--arg", "run_id=slamfault", "--arg", "hmd_config=" + config},
                          {{"ORBED_LOG_DIR", dir}});
  ASSERT_TRUE(launcher.Wait(240)) << "the run did not finish";
  EXPECT_EQ(launcher.term_signal(), 0);
  ASSERT_EQ(launcher.exit_code(), 0);

  // The run completed.
  const YAML::Node results = YAML::LoadFile(dir + "/results.json");
  ASSERT_EQ(results["status"].as<std::string>(), "ok") << results["error"].as<std::string>();
  ASSERT_EQ(results["sessions"].size(), 2u);
  EXPECT_EQ(results["sessions"][0]["session_id"].as<std::string>(), "slamfault-ar_reflective");
  EXPECT_EQ(results["sessions"][1]["session_id"].as<std::string>(), "slamfault-ar");

  struct Forced {
    std::string session;
    int index;
    int losses;
    double wait_s;
    std::vector<int> states;  // on HMD_POSE while aligning, repeats folded
  };
  const std::vector<Forced> forced = {
      {"slamfault-ar_reflective", 1, 1, 2.0, {HP::LOST, HP::RELOCALIZED}},
      {"slamfault-ar", 2, 2, 1.5, {HP::LIMITED, HP::RELOCALIZED, HP::LOST, HP::RELOCALIZED}}};
  const std::vector<Watcher::Event> events = watcher.Events();
  for (size_t s = 0; s < 2; ++s) {
    const YAML::Node session = results["sessions"][s];
    ASSERT_EQ(session["trials"].size(), 3u);
    for (int i = 0; i < 3; ++i) {
      const std::string where = session["session_id"].as<std::string>() + " trial " + std::to_string(i);
      const YAML::Node row = session["trials"][i];
      const Forced* f = nullptr;
      for (const Forced& x : forced) {
        if (x.session == session["session_id"].as<std::string>() && x.index == i) f = &x;
      }
      // The trial as the headset published it (the last copy: all copies are the same trial).
      const orbed::alignment_trial_t* trial = nullptr;
      for (const Watcher::Event& e : events) {
        if (e.kind == Watcher::Event::kTrial &&
            e.trial.session_id == session["session_id"].as<std::string>() && e.trial.trial_index == i) {
          trial = &e.trial;
        }
      }
      ASSERT_NE(trial, nullptr) << where << ": no ALIGNMENT_TRIAL heard";
      if (f == nullptr) {
        EXPECT_FALSE(row["tracking_faults"]) << where;
        EXPECT_EQ(trial->tracking_losses, 0) << where;
        EXPECT_EQ(trial->alignment_repeats, 0) << where;
        EXPECT_TRUE(StatesWhileAligning(events, trial->request_id).empty()) << where;
        continue;
      }
      // On the bus: the forced counts; the jump made the person re-align at least once, within the
      // shipped hmd.max_repeats (2).
      EXPECT_EQ(trial->tracking_losses, f->losses) << where;
      EXPECT_EQ(trial->relocalizations, f->losses) << where;
      EXPECT_NEAR(trial->tracking_wait_s, f->wait_s, 1e-9) << where;
      EXPECT_GE(trial->alignment_repeats, 1) << where;
      EXPECT_LE(trial->alignment_repeats, 2) << where;
      EXPECT_GT(trial->duration_s, f->wait_s) << where;
      // In results.json: the same record.
      ASSERT_TRUE(row["tracking_faults"]) << where;
      EXPECT_EQ(row["tracking_faults"]["losses"].as<int>(), f->losses) << where;
      EXPECT_EQ(row["tracking_faults"]["relocalizations"].as<int>(), f->losses) << where;
      EXPECT_NEAR(row["tracking_faults"]["wait_s"].as<double>(), f->wait_s, 1e-9) << where;
      EXPECT_EQ(row["tracking_faults"]["repeats"].as<int>(), trial->alignment_repeats) << where;
      EXPECT_NEAR(row["user_duration_s"].as<double>(), trial->duration_s, 1e-9) << where;
      // HMD_POSE while the person aligned: the forced states, in order.
      EXPECT_EQ(StatesWhileAligning(events, trial->request_id), f->states) << where;
    }
  }
}

}  // namespace
}  // namespace orbed::testing
