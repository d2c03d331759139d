// The robot set-up study's processes over real LCM, in a private network namespace.
//  1. orbed-assistant --once beside the real sim and orbed-guidance, with a near-perfect person
//     (tests' own config): the arm ends on the target (each joint within 0.5 deg: the grid is
//     0.25 deg), the result file's joints are the sim's IIWA_STATUS, and the twisting joints the
//     straight arm hides (1 and 3: nothing downstream is bent) were left where they were.
//  2. The same person, the target the iiwa reaches with joint 2 bent the other way than the arm's
//     start: joint 1 ends half a turn from its target (the q1 + 180 deg, -q2 ambiguity), seen over
//     the bus, not in the core.
//  4. A set-up whose assistant and guidance are SIGKILLed while the assistant moves the arm: the
//     launcher brings both back, the conductor's re-sent SETUP_TASK reaches them, the set-up is done
//     from where the arm was, and the run ends with exit 0 and a consistent record.
//  5. The registration's share over the bus: setup.yaml with --arg setup_registration=truth, one AR
//     set-up: no alignment, REGISTRATION carries exactly ROBOT_STATE's true base pose, the assistant
//     finishes with it, and the record has the clearance the sim's COLLISION_STATUS gave.
//  6. A resumed run (--arg setup_resume=...): a finished run's file cut back to its first set-up and
//     marked partial; the launch keeps that set-up as it was, sends SETUP_TASK for the second only,
//     and ends with both, the first exactly as the file had it.
//  7. The sim clock (SIM_CLOCK, --sim-time): setup.yaml for one user, two fixed-monitor set-ups, on the
//     sim's clock at 8 times real time (every process following it, the sim held until the
//     conductor runs): the run ends with exit 0 and both set-ups recorded as the assistant read
//     them; SIM_CLOCK carries rate 8 and stamps every IIWA_STATUS; and every GUIDANCE is stamped at
//     a deadline of its 30 Hz timer on the sim clock, start + round(k x 33 333.333 us), which the
//     wall clock would not give. (Without lockstep the set-ups are not compared with a run at
//     R = 1: the sim does not wait for its followers, so under load a look moves in sim time by R
//     times its wall latency, and in the sanitizer build joints ended 17-90 deg apart; case 8.)
//  8. Lockstep (SIM_CLOCK_ACK rounds): the same user, a fixed and an AR set-up (with its
//     three alignments through the headset and the registration server), run in lockstep with 8
//     steps per tick at real time and at 8 times real time: the two runs are the same run, every
//     message stamped on the sim clock equal field for field at the same sim time (IIWA_STATUS,
//     HMD_POSE, ALIGNMENT_TRIAL, SETUP_RESULT) and the recorded joints equal to the bit, although
//     the wall time each process took differs by a factor of 8 (and more under load); every
//     follower of the clock answered its rounds on SIM_CLOCK_ACK.
//  3. scripts/launch/setup.yaml for one user and one target per mode through orbed-launch: the run
//     ends with exit 0; setup_results.json has the three set-ups in the order the user seed draws,
//     each reached_deg equal to the assistant's (the sim's measured joints, twice read), an
//     alignment of 3 trials before each headset set-up and none before the fixed one.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <lcm/lcm-cpp.hpp>
#include <opencv2/imgcodecs.hpp>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/guidance_t.hpp>
#include <orbed/hmd_pose_t.hpp>
#include <orbed/iiwa_status_t.hpp>
#include <orbed/image_t.hpp>
#include <orbed/registration_t.hpp>
#include <orbed/robot_state_t.hpp>
#include <orbed/setup_result_t.hpp>
#include <orbed/setup_task_t.hpp>
#include <orbed/sim_clock_ack_t.hpp>
#include <orbed/sim_clock_t.hpp>

#include "base/units.h"
#include "experiments/setup/setup_conductor.h"
#include "procs/setup/setup_process.h"
#include "sim/guidance_messages.h"
#include "tests/integration/logged.h"
#include "tests/integration/testbed_util.h"

namespace orbed::testing {
namespace {

constexpr char kPerfectConfig[] = R"(assistant:
  user_scale_log_sigma: 0
  headset: {lateral_noise_arcmin: 0.001, depth_noise_fraction_std: 0.00001}
  reflective: {noise_arcmin: 0.001, depth_fraction_std: 0.00001}
  monitor: {rotation_error_base_deg: 0, rotation_error_per_deg: 0, picture_scale_log_sigma: 0,
            picture_noise_arcmin: 0.001, picture_depth_fraction_std: 0.00001}
  acting: {placement_noise_deg: 0}
)";

class StatusWatcher {
 public:
  explicit StatusWatcher(BusWatcher* bus) { bus->lcm().subscribe("IIWA_STATUS", &StatusWatcher::On, this); }
  bool Latest(orbed::iiwa_status_t* out) const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!have_) return false;
    *out = status_;
    return true;
  }

 private:
  void On(const lcm::ReceiveBuffer*, const std::string&, const orbed::iiwa_status_t* msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    status_ = *msg;
    have_ = true;
  }
  mutable std::mutex mutex_;
  orbed::iiwa_status_t status_{};
  bool have_{false};
};

std::string WriteFile(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  return path;
}

std::string Join(const std::vector<double>& q) {
  std::string out;
  for (double x : q) out += (out.empty() ? "" : ",") + std::to_string(x);
  return out;
}

// Runs sim + guidance (fixed display, `target_deg`) + assistant --once; returns the result file.
YAML::Node RunOnce(const std::vector<double>& target_deg, const std::vector<double>& start_deg,
                   orbed::iiwa_status_t* final_status) {
  const std::string dir = MakeTempDir("setup_once");
  const std::string config = WriteFile(dir, "perfect.yaml", kPerfectConfig);
  BusWatcher bus;
  StatusWatcher status(&bus);
  bus.Start();
  RunningProcess sim({BinPath("orbed-iiwa-sim"), "--initial-q-deg", Join(start_deg)});
  RunningProcess guidance({BinPath("orbed-guidance"), "--target-deg", Join(target_deg), "--mode", "fixed"});
  RunningProcess assistant(
      {BinPath("orbed-assistant"), "--once", "--config", config, "--result", dir + "/result.json"});
  EXPECT_TRUE(assistant.Wait(240)) << "the assistant did not finish";
  EXPECT_EQ(assistant.exit_code(), 0);
  EXPECT_TRUE(status.Latest(final_status));
  return YAML::LoadFile(dir + "/result.json");
}

TEST(Assistant, APerfectPersonSetsTheArmUpOverTheBus) {
  const std::vector<double> target = {0, 35, 0, -50, 0, 40, 20};
  orbed::iiwa_status_t status{};
  const YAML::Node result = RunOnce(target, {0, 0, 0, 0, 0, 0, 0}, &status);
  ASSERT_EQ(result["q_reached_deg"].size(), 7u);
  ASSERT_EQ(status.joint_position_measured.size(), 7u);
  for (int i = 0; i < 7; ++i) {
    EXPECT_NEAR(result["q_reached_deg"][i].as<double>(), target[i], 0.5) << "joint " << i + 1;
    EXPECT_NEAR(result["q_reached_deg"][i].as<double>(), status.joint_position_measured[i] * kRadToDeg, 0.05)
        << "joint " << i + 1;
    EXPECT_NEAR(result["error_deg"][i].as<double>(),
                std::abs(result["q_reached_deg"][i].as<double>() - target[i]), 1e-9);
  }
  EXPECT_EQ(result["mode"].as<std::string>(), "fixed");
  EXPECT_EQ(result["twisting"][0].as<int>(), 1);
  EXPECT_EQ(result["twisting"][1].as<int>(), 0);
  // Joint 1 at its first look: the arm straight up, nothing off its axis: one range, everything.
  EXPECT_EQ(result["ranges"][0].as<int>(), 1);
  EXPECT_GT(result["execution_s"].as<double>(), 0);
}

TEST(Assistant, TheOtherElbowSendsJointOneHalfATurnAway) {
  const std::vector<double> target = {60, -30, 0, -50, 0, 40, 0};
  orbed::iiwa_status_t status{};
  const YAML::Node result = RunOnce(target, {0, 30, 0, -50, 0, 40, 0}, &status);
  ASSERT_EQ(result["q_reached_deg"].size(), 7u);
  EXPECT_NEAR(result["q_reached_deg"][0].as<double>(), 60.0 - 180.0, 1.0);
  // Then joint 2 matches the elbow from the other side: +30, not the target's -30.
  EXPECT_NEAR(result["q_reached_deg"][1].as<double>(), 30.0, 1.0);
}

TEST(SetupStudy, OneUserThroughTheLaunchFile) {
  const std::string log_dir = MakeTempDir("setup_e2e");
  constexpr uint64_t kSeed = 4;
  RunningProcess launcher({BinPath("orbed-launch"), SourcePath("scripts/launch/setup.yaml"), "--duration-s",
                           "400", "--arg", "run_id=setup-e2e", "--arg", "user=u7", "--arg",
                           "user_seed=" + std::to_string(kSeed), "--arg", "setup_targets=1"},
                          {{"ORBED_LOG_DIR", log_dir}});
  ASSERT_TRUE(launcher.Wait(400)) << "the run did not finish";
  ASSERT_EQ(launcher.exit_code(), 0);
  const YAML::Node results = YAML::LoadFile(log_dir + "/setup_results.json");
  EXPECT_EQ(results["status"].as<std::string>(), "ok");
  EXPECT_EQ(results["user"].as<std::string>(), "u7");
  const std::vector<int8_t> order = setup::ModeOrderForSeed(kSeed);
  const YAML::Node setups = results["setups"];
  ASSERT_EQ(setups.size(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    const YAML::Node s = setups[k];
    const std::string mode = guidance::GuidanceModeName(order[k]);
    EXPECT_EQ(s["mode"].as<std::string>(), mode);
    EXPECT_EQ(s["order"].as<int>(), static_cast<int>(k) + 1);
    EXPECT_EQ(s["task_id"].as<std::string>(), "u7-" + mode + "-1");
    ASSERT_EQ(s["reached_deg"].size(), 7u);
    for (int i = 0; i < 7; ++i) {
      EXPECT_NEAR(s["reached_deg"][i].as<double>(), s["assistant_reached_deg"][i].as<double>(), 0.05) << mode;
    }
    if (mode == "fixed") {
      EXPECT_TRUE(s["alignment"].IsNull());
      EXPECT_TRUE(s["alignment_s"].IsNull());
    } else {
      ASSERT_TRUE(s["alignment"].IsMap()) << mode;
      EXPECT_EQ(s["alignment"]["trials"].as<int>(), 3);
      EXPECT_GT(s["alignment_s"].as<double>(), 0);
      EXPECT_LT(s["alignment"]["translation_error_mm"].as<double>(), 200.0);
    }
  }
  const YAML::Node manifest = YAML::LoadFile(log_dir + "/manifest.json");
  EXPECT_TRUE(manifest["complete"].as<bool>());
  for (const char* channel :
       {"SETUP_TASK", "SETUP_RESULT", "GUIDANCE", "IIWA_COMMAND", "ALIGNMENT_TRIAL", "FIXED_VIEW"}) {
    EXPECT_TRUE(manifest["channels"][channel]) << channel << " missing from the log";
  }
  // The fixed mode's monitor: pictures from the assistant's monitor camera (assistant.yaml's
  // monitor.camera_m, orbed-fixed-display's home view), each a whole JPEG of the announced size.
  const std::vector<orbed::image_t> pictures = Logged<orbed::image_t>(log_dir, "FIXED_VIEW");
  for (const orbed::image_t& image : pictures) {
    EXPECT_NEAR(image.X_WC.position_m[0], 1.5, 1e-9);
    EXPECT_NEAR(image.X_WC.position_m[1], 0.3, 1e-9);
    EXPECT_NEAR(image.X_WC.position_m[2], 1.8, 1e-9);
    const cv::Mat picture = cv::imdecode(image.data, cv::IMREAD_COLOR);
    EXPECT_EQ(picture.cols, image.width);
    EXPECT_EQ(picture.rows, image.height);
  }
  EXPECT_GT(pictures.size(), 0u);
}

int LatestPid(const BusWatcher& bus, const std::string& name) {
  const auto beats = bus.Heartbeats(name);
  return beats.empty() ? 0 : beats.back().status.pid;
}

class CommandCounter {
 public:
  explicit CommandCounter(BusWatcher* bus) {
    bus->lcm().subscribe("SETUP_TASK", &CommandCounter::OnTask, this);
  }
  int tasks() const { return tasks_.load(); }

 private:
  void OnTask(const lcm::ReceiveBuffer*, const std::string&, const orbed::setup_task_t*) { ++tasks_; }
  std::atomic<int> tasks_{0};
};

TEST(SetupStudy, AKilledAssistantAndGuidanceComeBackAndTheSetUpFinishes) {
  const std::string log_dir = MakeTempDir("setup_crash");
  BusWatcher bus;
  CommandCounter tasks(&bus);
  bus.Start();
  RunningProcess launcher({BinPath("orbed-launch"), SourcePath("scripts/launch/setup.yaml"), "--duration-s",
                           "400", "--arg", "run_id=setup-crash", "--arg", "user=u2", "--arg", "user_seed=2",
                           "--arg", "setup_modes=fixed", "--arg", "setup_targets=1"},
                          {{"ORBED_LOG_DIR", log_dir}});
  // The task is out and the assistant has started moving (its IIWA_COMMANDs on its heartbeat).
  ASSERT_TRUE(WaitFor(
      [&] {
        const auto beats = bus.Heartbeats("assistant");
        return tasks.tasks() > 0 && !beats.empty() &&
               beats.back().status.messages_out > static_cast<int64_t>(beats.size()) + 2;
      },
      120))
      << "the set-up did not start";
  const int assistant = LatestPid(bus, "assistant"), guidance = LatestPid(bus, "guidance");
  ASSERT_GT(assistant, 0);
  ASSERT_GT(guidance, 0);
  ASSERT_EQ(kill(assistant, SIGKILL), 0);
  ASSERT_EQ(kill(guidance, SIGKILL), 0);
  const int tasks_at_kill = tasks.tasks();
  ASSERT_TRUE(launcher.Wait(400)) << "the run did not finish";
  ASSERT_EQ(launcher.exit_code(), 0);
  EXPECT_NE(LatestPid(bus, "assistant"), assistant) << "the assistant was not respawned";
  EXPECT_NE(LatestPid(bus, "guidance"), guidance) << "the guidance was not respawned";
  // The set-up was still waiting for its answer when they died: the task went out again.
  EXPECT_GT(tasks.tasks(), tasks_at_kill);
  const YAML::Node results = YAML::LoadFile(log_dir + "/setup_results.json");
  EXPECT_EQ(results["status"].as<std::string>(), "ok");
  ASSERT_EQ(results["setups"].size(), 1u);
  const YAML::Node s = results["setups"][0];
  EXPECT_EQ(s["mode"].as<std::string>(), "fixed");
  for (int i = 0; i < 7; ++i) {
    EXPECT_NEAR(s["reached_deg"][i].as<double>(), s["assistant_reached_deg"][i].as<double>(), 0.05);
  }
}

// The latest REGISTRATION and ROBOT_STATE on the bus.
class PoseWatcher {
 public:
  explicit PoseWatcher(BusWatcher* bus) {
    bus->lcm().subscribe("REGISTRATION", &PoseWatcher::OnRegistration, this);
    bus->lcm().subscribe("ROBOT_STATE", &PoseWatcher::OnState, this);
  }
  int registrations() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return registrations_;
  }
  orbed::registration_t registration() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return registration_;
  }
  orbed::pose_t X_WR() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return X_WR_;
  }

 private:
  void OnRegistration(const lcm::ReceiveBuffer*, const std::string&, const orbed::registration_t* msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++registrations_;
    registration_ = *msg;
  }
  void OnState(const lcm::ReceiveBuffer*, const std::string&, const orbed::robot_state_t* msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    X_WR_ = msg->X_WR;
  }
  mutable std::mutex mutex_;
  int registrations_{0};
  orbed::registration_t registration_{};
  orbed::pose_t X_WR_{};
};

TEST(SetupStudy, TheTrueRegistrationGoesOverTheBusInsteadOfAlignments) {
  const std::string log_dir = MakeTempDir("setup_truth");
  BusWatcher bus;
  PoseWatcher poses(&bus);
  bus.Start();
  RunningProcess launcher(
      {BinPath("orbed-launch"), SourcePath("scripts/launch/setup.yaml"), "--duration-s", "400", "--arg",
       "run_id=setup-truth", "--arg", "user=u3", "--arg", "user_seed=3", "--arg", "setup_modes=ar", "--arg",
       "setup_registration=truth", "--arg", "setup_targets=1"},
      {{"ORBED_LOG_DIR", log_dir}});
  ASSERT_TRUE(launcher.Wait(400)) << "the run did not finish";
  ASSERT_EQ(launcher.exit_code(), 0);
  const YAML::Node results = YAML::LoadFile(log_dir + "/setup_results.json");
  EXPECT_EQ(results["status"].as<std::string>(), "ok");
  ASSERT_EQ(results["setups"].size(), 1u);
  const YAML::Node s = results["setups"][0];
  EXPECT_EQ(s["registration"].as<std::string>(), "truth");
  EXPECT_TRUE(s["alignment"].IsNull());
  // The sim's COLLISION_STATUS reached the conductor: a clearance, and the arm touched nothing.
  ASSERT_FALSE(s["min_clearance_m"].IsNull());
  EXPECT_GT(s["min_clearance_m"].as<double>(), 0.0);
  EXPECT_FALSE(s["contact"].as<bool>());
  EXPECT_GE(s["docking_tip_mm"].as<double>(), 0.0);
  // The latest REGISTRATION (the conductor's: the server, with no session, sends none): the true
  // base pose, bit for bit.
  ASSERT_GT(poses.registrations(), 0);
  const orbed::registration_t truth = poses.registration();
  EXPECT_EQ(truth.session_id, "setup-truth-u3-ar-1-truth");
  EXPECT_TRUE(truth.valid);
  const orbed::pose_t X_WR = poses.X_WR();
  for (int i = 0; i < 3; ++i) EXPECT_EQ(truth.X_WV_mean.position_m[i], X_WR.position_m[i]);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(truth.X_WV_mean.quaternion_wxyz[i], X_WR.quaternion_wxyz[i]);
  const YAML::Node manifest = YAML::LoadFile(log_dir + "/manifest.json");
  EXPECT_FALSE(manifest["channels"]["ALIGNMENT_TRIAL"]) << "an alignment ran";
  EXPECT_TRUE(manifest["channels"]["REGISTRATION"]);
}

// The task ids of every SETUP_TASK in a run folder's log.
std::vector<std::string> LoggedTaskIds(const std::string& log_dir) {
  std::vector<std::string> ids;
  for (const orbed::setup_task_t& task : Logged<orbed::setup_task_t>(log_dir, "SETUP_TASK"))
    ids.push_back(task.task_id);
  return ids;
}

TEST(SetupStudy, AResumedRunKeepsTheFinishedSetUpAndRunsTheRest) {
  auto launch = [](const std::string& log_dir, const std::string& resume) {
    std::vector<std::string> argv = {BinPath("orbed-launch"),
                                     SourcePath("scripts/launch/setup.yaml"),
                                     "--duration-s",
                                     "400",
                                     "--arg",
                                     "run_id=setup-resume",
                                     "--arg",
                                     "user=u3",
                                     "--arg",
                                     "user_seed=5",
                                     "--arg",
                                     "setup_modes=fixed",
                                     "--arg",
                                     "setup_targets=2"};
    if (!resume.empty()) argv.insert(argv.end(), {"--arg", "setup_resume=" + resume});
    RunningProcess launcher(argv, {{"ORBED_LOG_DIR", log_dir}});
    EXPECT_TRUE(launcher.Wait(400)) << "the run did not finish";
    return launcher.exit_code();
  };
  const std::string first_dir = MakeTempDir("setup_resume_first");
  ASSERT_EQ(launch(first_dir, ""), 0);
  std::string status;
  setup::SetupRun first = setup::ReadSetupRunFile(first_dir + "/setup_results.json", &status);
  ASSERT_EQ(status, "ok");
  ASSERT_EQ(first.setups.size(), 2u);

  // What a run stopped after its first set-up leaves: that set-up, "partial".
  setup::SetupRun cut = first;
  cut.ok = false;
  cut.setups.resize(1);
  const std::string cut_dir = MakeTempDir("setup_resume_cut");
  std::ofstream(cut_dir + "/setup_results.json") << setup::SetupRunJson(cut, /*partial=*/true);

  const std::string resumed_dir = MakeTempDir("setup_resume_second");
  ASSERT_EQ(launch(resumed_dir, cut_dir), 0);
  const setup::SetupRun resumed = setup::ReadSetupRunFile(resumed_dir + "/setup_results.json", &status);
  ASSERT_EQ(status, "ok");
  ASSERT_EQ(resumed.setups.size(), 2u);
  // The kept set-up is the file's, to the last digit: the whole record written the same.
  setup::SetupRun kept_only = resumed, first_only = first;
  kept_only.setups.resize(1);
  first_only.setups.resize(1);
  EXPECT_EQ(setup::SetupRunJson(kept_only, false), setup::SetupRunJson(first_only, false));
  EXPECT_EQ(resumed.setups[1].task_id, "u3-fixed-2");
  // Only the second set-up went over the bus.
  const std::vector<std::string> tasks = LoggedTaskIds(resumed_dir);
  ASSERT_FALSE(tasks.empty());
  for (const std::string& id : tasks) EXPECT_EQ(id, "u3-fixed-2");
  const std::vector<std::string> first_tasks = LoggedTaskIds(first_dir);
  EXPECT_NE(std::find(first_tasks.begin(), first_tasks.end(), "u3-fixed-1"), first_tasks.end());
}

TEST(SetupStudy, EightTimesFasterEveryProcessFollowsTheSimClock) {
  const std::string log_dir = MakeTempDir("setup_sim_clock");
  RunningProcess launcher({BinPath("orbed-launch"),
                           SourcePath("scripts/launch/setup.yaml"),
                           "--duration-s",
                           "300",
                           "--arg",
                           "run_id=setup-sim-clock",
                           "--arg",
                           "user=u1",
                           "--arg",
                           "user_seed=1",
                           "--arg",
                           "setup_modes=fixed",
                           "--arg",
                           "setup_targets=2",
                           "--arg",
                           "sim_time=1",
                           "--arg",
                           "hold_for=setup",
                           "--arg",
                           "sim_rate=8"},
                          {{"ORBED_LOG_DIR", log_dir}});
  ASSERT_TRUE(launcher.Wait(300)) << "the run did not finish";
  ASSERT_EQ(launcher.exit_code(), 0);
  const YAML::Node setups = YAML::LoadFile(log_dir + "/setup_results.json")["setups"];
  ASSERT_EQ(setups.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    for (int i = 0; i < 7; ++i) {
      EXPECT_NEAR(setups[k]["reached_deg"][i].as<double>(),
                  setups[k]["assistant_reached_deg"][i].as<double>(), 0.05);
    }
  }
  // The clock: rate 8 on every SIM_CLOCK, one sim start, and each IIWA_STATUS stamped with one of them.
  const std::vector<orbed::sim_clock_t> clock = Logged<orbed::sim_clock_t>(log_dir, "SIM_CLOCK");
  const std::vector<orbed::iiwa_status_t> status = Logged<orbed::iiwa_status_t>(log_dir, "IIWA_STATUS");
  ASSERT_GT(clock.size(), 100u);
  ASSERT_GT(status.size(), 100u);
  const int64_t start = clock.front().start_utime;
  std::set<int64_t> stamps;
  for (const orbed::sim_clock_t& c : clock) {
    EXPECT_EQ(c.realtime_rate, 8);
    EXPECT_EQ(c.start_utime, start);
    stamps.insert(c.utime);
  }
  size_t stamped = 0;
  for (const orbed::iiwa_status_t& s : status) stamped += stamps.count(s.utime);
  EXPECT_EQ(stamped, status.size());
  // orbed-guidance started while the sim held its clock at `start`: its timer's k-th deadline is
  // k x 33 333 333 ns of sim time after it, stamped to the microsecond (rounded from the latest
  // SIM_CLOCK back, so within 1 us of start + k x 33 333.333 us). On the wall clock a stamp would
  // lie anywhere in the period.
  const std::vector<orbed::guidance_t> guidance = Logged<orbed::guidance_t>(log_dir, "GUIDANCE");
  ASSERT_GT(guidance.size(), 10u);
  for (const orbed::guidance_t& g : guidance) {
    const double k = std::round(static_cast<double>(g.utime - start) / 33333.333);
    EXPECT_NEAR(static_cast<double>(g.utime - start), k * 33333.333, 1.0) << "GUIDANCE stamp " << g.utime;
  }
}
// One lockstep launch of setup.yaml at realtime rate `rate`; returns its run folder.
std::string RunInLockstep(int rate) {
  const std::string log_dir = MakeTempDir("setup_lockstep_r" + std::to_string(rate));
  RunningProcess launcher({BinPath("orbed-launch"),
                           SourcePath("scripts/launch/setup.yaml"),
                           "--duration-s",
                           "400",
                           "--arg",
                           "run_id=setup-lockstep",
                           "--arg",
                           "user=u1",
                           "--arg",
                           "user_seed=1",
                           "--arg",
                           "setup_modes=fixed,ar",
                           "--arg",
                           "setup_targets=1",
                           "--arg",
                           "sim_time=1",
                           "--arg",
                           "lockstep=1",
                           "--arg",
                           "steps_per_tick=8",
                           "--arg",
                           "hold_for=setup",
                           "--arg",
                           "sim_rate=" + std::to_string(rate)},
                          {{"ORBED_LOG_DIR", log_dir}});
  EXPECT_TRUE(launcher.Wait(400)) << "the run at rate " << rate << " did not finish";
  EXPECT_EQ(launcher.exit_code(), 0) << "rate " << rate;
  return log_dir;
}

// The sim's start stamp of a run (every stamp below is compared as the time since it).
int64_t SimStart(const std::string& log_dir) {
  const std::vector<orbed::sim_clock_t> clock = Logged<orbed::sim_clock_t>(log_dir, "SIM_CLOCK");
  EXPECT_FALSE(clock.empty());
  return clock.empty() ? 0 : clock.front().start_utime;
}

TEST(SetupStudy, InLockstepARunAtEightTimesRealTimeIsTheRunAtRealTime) {
  const std::string slow = RunInLockstep(1);
  const std::string fast = RunInLockstep(8);
  ASSERT_FALSE(::testing::Test::HasFailure());
  const int64_t start_slow = SimStart(slow);
  const int64_t start_fast = SimStart(fast);

  // The records: the same joints, to the bit.
  const YAML::Node a = YAML::LoadFile(slow + "/setup_results.json")["setups"];
  const YAML::Node b = YAML::LoadFile(fast + "/setup_results.json")["setups"];
  ASSERT_EQ(a.size(), 2u);
  ASSERT_EQ(b.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(a[k]["task_id"].as<std::string>(), b[k]["task_id"].as<std::string>());
    for (int i = 0; i < 7; ++i) {
      EXPECT_EQ(a[k]["reached_deg"][i].as<double>(), b[k]["reached_deg"][i].as<double>())
          << k << " q" << i + 1;
    }
  }
  // Up to the last answer (the launch's teardown after it is not part of the run).
  const auto result_a = Logged<orbed::setup_result_t>(slow, "SETUP_RESULT");
  const auto result_b = Logged<orbed::setup_result_t>(fast, "SETUP_RESULT");
  ASSERT_FALSE(result_a.empty());
  ASSERT_EQ(result_a.size(), result_b.size());
  for (size_t k = 0; k < result_a.size(); ++k) {
    EXPECT_EQ(result_a[k].utime - start_slow, result_b[k].utime - start_fast) << k;
    EXPECT_EQ(result_a[k].reached_position, result_b[k].reached_position) << k;
  }
  const int64_t end_us = result_a.back().utime - start_slow;
  auto until_end = [end_us](auto messages, int64_t start) {
    messages.erase(std::remove_if(messages.begin(), messages.end(),
                                  [&](const auto& m) { return m.utime - start > end_us; }),
                   messages.end());
    return messages;
  };
  // The arm, tick by tick.
  const auto status_a = until_end(Logged<orbed::iiwa_status_t>(slow, "IIWA_STATUS"), start_slow);
  const auto status_b = until_end(Logged<orbed::iiwa_status_t>(fast, "IIWA_STATUS"), start_fast);
  ASSERT_GT(status_a.size(), 100u);
  ASSERT_EQ(status_a.size(), status_b.size());
  for (size_t k = 0; k < status_a.size(); ++k) {
    ASSERT_EQ(status_a[k].utime - start_slow, status_b[k].utime - start_fast) << k;
    ASSERT_EQ(status_a[k].joint_position_measured, status_b[k].joint_position_measured) << k;
  }
  // The person's head, on its 60 Hz sim timer, through the set-ups and the alignments.
  const auto pose_a = until_end(Logged<orbed::hmd_pose_t>(slow, "HMD_POSE"), start_slow);
  const auto pose_b = until_end(Logged<orbed::hmd_pose_t>(fast, "HMD_POSE"), start_fast);
  ASSERT_GT(pose_a.size(), 100u);
  ASSERT_EQ(pose_a.size(), pose_b.size());
  for (size_t k = 0; k < pose_a.size(); ++k) {
    ASSERT_EQ(pose_a[k].utime - start_slow, pose_b[k].utime - start_fast) << k;
    for (int i = 0; i < 3; ++i) ASSERT_EQ(pose_a[k].X_WH.position_m[i], pose_b[k].X_WH.position_m[i]) << k;
    for (int i = 0; i < 4; ++i) {
      ASSERT_EQ(pose_a[k].X_WH.quaternion_wxyz[i], pose_b[k].X_WH.quaternion_wxyz[i]) << k;
    }
  }
  // The three alignments before the AR set-up.
  const auto trial_a = Logged<orbed::alignment_trial_t>(slow, "ALIGNMENT_TRIAL");
  const auto trial_b = Logged<orbed::alignment_trial_t>(fast, "ALIGNMENT_TRIAL");
  ASSERT_GE(trial_a.size(), 3u);
  ASSERT_EQ(trial_a.size(), trial_b.size());
  for (size_t k = 0; k < trial_a.size(); ++k) {
    EXPECT_EQ(trial_a[k].utime - start_slow, trial_b[k].utime - start_fast) << k;
    EXPECT_EQ(trial_a[k].duration_s, trial_b[k].duration_s) << k;
    for (int i = 0; i < 3; ++i) EXPECT_EQ(trial_a[k].X_WV.position_m[i], trial_b[k].X_WV.position_m[i]) << k;
  }
  // The clock: lockstep rounds at each rate, answered by every process that follows it.
  for (const auto& [dir, rate] : {std::make_pair(slow, 1), std::make_pair(fast, 8)}) {
    for (const orbed::sim_clock_t& c : Logged<orbed::sim_clock_t>(dir, "SIM_CLOCK")) {
      ASSERT_EQ(c.realtime_rate, rate);
      ASSERT_GE(c.lockstep_round, 1);
    }
    std::set<std::string> answered;
    for (const auto& ack : Logged<orbed::sim_clock_ack_t>(dir, "SIM_CLOCK_ACK")) answered.insert(ack.process);
    EXPECT_EQ(answered, (std::set<std::string>{"assistant", "fixed_display", "guidance", "hmd",
                                               "registration", "setup"}))
        << "rate " << rate;
  }
}

}  // namespace
}  // namespace orbed::testing
