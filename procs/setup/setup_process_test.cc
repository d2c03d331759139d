// orbed-setup's shell (setup_process.h) in-process on memq:// (the process's own LCM instance
// delivers what the test publishes on it). The test plays orbed-iiwa-sim and orbed-assistant on the
// same instance: an IIWA_COMMAND is answered at once with a ROBOT_STATE at the commanded joints, at
// rest; a SETUP_TASK with a SETUP_RESULT and then a ROBOT_STATE at where the person put the arm.
// Checked: the run ends by itself (exit 0) with setup_results.json "ok" holding each set-up with the
// sim's joints; a run nobody answers fails after the start-up timeout (exit 1) with the file
// "failed" naming the missing process; the seeded mode orders and the --modes list.
#include "procs/setup/setup_process.h"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <orbed/guidance_t.hpp>
#include <orbed/iiwa_command_t.hpp>

#include "base/source_paths.h"
#include "base/units.h"
#include "lcmtypes/contract/conversions.h"

namespace orbed::setup {
namespace {

constexpr int8_t kFixed = orbed::guidance_t::MODE_FIXED_DISPLAY;

CommonFlags MemqFlags(double duration_s) {
  CommonFlags flags("orbed-setup-test");
  flags.lcm_url = "memq://";
  flags.duration_s = duration_s;  // a guard: the runs below end by themselves
  return flags;
}

std::string Urdf() { return SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath); }

// A fresh results folder per test.
std::string ResultsDir(const std::string& name) {
  const std::string dir = ::testing::TempDir() + "setup_process_test_" + name;
  std::filesystem::remove_all(dir);
  return dir;
}

SetupOptions FixedOnly() {
  SetupOptions o;
  o.user = "u2";
  o.run_id = "memq";
  o.modes = {kFixed};
  o.targets_deg = {{10, 20, 0, -60, 0, 40, 0}, {-10, 30, 5, -70, 0, 30, 20}};
  o.start_deg = {0, 20, 0, -60, 0, 40, 0};
  return o;
}

orbed::robot_state_t State(const std::vector<double>& q_rad) {
  orbed::robot_state_t s{};
  s.X_WR = ToPose(Eigen::Isometry3d::Identity());
  s.X_RF = ToPose(Eigen::Isometry3d::Identity());
  s.X_RT = ToPose(Eigen::Isometry3d::Identity());
  s.num_joints = static_cast<int32_t>(q_rad.size());
  s.joint_position = q_rad;
  s.joint_limit_hit.assign(q_rad.size(), 0);
  s.motion_state = orbed::robot_state_t::MOTION_IDLE;
  return s;
}

// The sim and the assistant. The person puts every joint 1 deg beyond the target.
struct Room {
  lcm::LCM* lcm;
  std::vector<orbed::setup_task_t> tasks;
  int commands{0};
  void OnCommand(const lcm::ReceiveBuffer*, const std::string&, const orbed::iiwa_command_t* msg) {
    ++commands;
    orbed::robot_state_t state = State(msg->joint_position);
    lcm->publish("ROBOT_STATE", &state);
  }
  void OnTask(const lcm::ReceiveBuffer*, const std::string&, const orbed::setup_task_t* msg) {
    if (!tasks.empty() && tasks.back().request_id == msg->request_id) return;  // a re-send
    tasks.push_back(*msg);
    orbed::setup_result_t r{};
    r.request_id = msg->request_id;
    r.task_id = msg->task_id;
    r.mode = msg->mode;
    r.num_joints = msg->num_joints;
    for (double q : msg->target_position) r.reached_position.push_back(q + kDegToRad);
    r.ranges.assign(msg->num_joints, 1);
    r.execution_s = 60.0 + static_cast<double>(tasks.size());
    r.person_scale = 1.0;
    lcm->publish("SETUP_RESULT", &r);
    orbed::robot_state_t state = State(r.reached_position);
    lcm->publish("ROBOT_STATE", &state);
  }
};

TEST(SetupProcess, RunsEachTargetAndWritesTheResults) {
  const std::string dir = ResultsDir("ok");
  SetupProcess setup(MemqFlags(30), FixedOnly(), Urdf(), dir, nullptr);
  lcm::LCM& lcm = setup.process().lcm();
  Room room{&lcm};
  lcm.subscribe("IIWA_COMMAND", &Room::OnCommand, &room);
  lcm.subscribe("SETUP_TASK", &Room::OnTask, &room);
  orbed::robot_state_t elsewhere = State(std::vector<double>{0, 0, 0, 0, 0, 0, 0});
  lcm.publish("ROBOT_STATE", &elsewhere);

  EXPECT_EQ(setup.Run(), 0);
  ASSERT_EQ(room.tasks.size(), 2u);
  EXPECT_EQ(room.tasks[0].task_id, "u2-fixed-1");
  EXPECT_EQ(room.tasks[1].task_id, "u2-fixed-2");
  EXPECT_GE(room.commands, 2);  // parked before each task

  std::string status;
  const SetupRun run = ReadSetupRunFile(dir + "/setup_results.json", &status);
  EXPECT_EQ(status, "ok");
  EXPECT_EQ(run.user, "u2");
  EXPECT_EQ(run.run_id, "memq");
  ASSERT_EQ(run.setups.size(), 2u);
  for (int k = 0; k < 2; ++k) {
    const SetupRecord& r = run.setups[k];
    EXPECT_EQ(r.target, k + 1);
    EXPECT_EQ(r.execution_s, 61.0 + k);
    ASSERT_EQ(r.reached_deg.size(), 7u);
    for (int i = 0; i < 7; ++i) EXPECT_NEAR(r.reached_deg[i], FixedOnly().targets_deg[k][i] + 1.0, 1e-9);
  }
}

TEST(SetupProcess, ARunNobodyAnswersFailsAndSaysWhy) {
  const std::string dir = ResultsDir("failed");
  SetupOptions options = FixedOnly();
  options.startup_timeout_s = 0.2;
  SetupProcess setup(MemqFlags(30), options, Urdf(), dir, nullptr);
  EXPECT_EQ(setup.Run(), 1);
  std::string status;
  const SetupRun run = ReadSetupRunFile(dir + "/setup_results.json", &status);
  EXPECT_EQ(status, "failed");
  EXPECT_FALSE(run.ok);
  EXPECT_NE(run.error.find("ROBOT_STATE"), std::string::npos) << run.error;
  EXPECT_TRUE(run.setups.empty());
}

// The mode orders: each seed's a permutation of the three modes; all six occur over seeds; --modes
// names in order, a bad name refused naming it.
TEST(SetupProcess, ModeOrders) {
  std::vector<std::vector<int8_t>> seen;
  for (uint64_t seed = 1; seed <= 60; ++seed) {
    std::vector<int8_t> order = ModeOrderForSeed(seed);
    std::vector<int8_t> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(sorted, (std::vector<int8_t>{0, 1, 2}));
    if (std::find(seen.begin(), seen.end(), order) == seen.end()) seen.push_back(order);
  }
  EXPECT_EQ(seen.size(), 6u);
  EXPECT_EQ(ModeOrderFromNames("fixed,ar,ar_reflective"), (std::vector<int8_t>{2, 0, 1}));
  try {
    ModeOrderFromNames("ar,holo");
    ADD_FAILURE() << "holo accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("holo"), std::string::npos);
  }
}

// Every order of the three modes comes from some seed, and a seed always gives the same one.
TEST(SetupConductor, UserSeedsGiveEveryOrder) {
  std::set<std::vector<int8_t>> seen;
  for (uint64_t seed = 1; seed <= 60; ++seed) {
    const std::vector<int8_t> order = ModeOrderForSeed(seed);
    EXPECT_EQ(order, ModeOrderForSeed(seed));
    std::vector<int8_t> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(sorted, (std::vector<int8_t>{0, 1, 2}));
    seen.insert(order);
  }
  EXPECT_EQ(seen.size(), 6u);
}

}  // namespace
}  // namespace orbed::setup
