// orbed-iiwa-sim's state file (sim_state.h): a sim that dies while the arm moves and is started
// again on its state file starts at most one save period of motion behind the last published q
// and exactly where the arm came to rest; damaged or implausible state files are refused naming
// the problem, so the sim does not start somewhere it is not.
#include "sim/sim_state.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/units.h"
#include "lcmtypes/contract/conversions.h"
#include "runtime/journal.h"
#include "sim/iiwa_sim.h"

namespace orbed::sim {
namespace {

namespace fs = std::filesystem;

std::string TempPath(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("orbed_sim_state_test_" + std::to_string(getpid()));
  fs::create_directories(dir);
  fs::remove(dir / name);
  return (dir / name).string();
}

CommonFlags MemqFlags() {
  CommonFlags flags("orbed-iiwa-sim");
  flags.lcm_url = "memq://";
  return flags;
}

struct StatusLog {
  std::vector<orbed::iiwa_status_t> status;
  void On(const lcm::ReceiveBuffer*, const std::string&, const orbed::iiwa_status_t* m) {
    status.push_back(*m);
  }
};

void HandleAll(lcm::LCM& lcm) {
  while (lcm.handleTimeout(0) > 0) {
  }
}

const double kSpeedDegPerS[7] = {98, 98, 100, 130, 140, 180, 180};  // iiwa 7 R800 data sheet

TEST(SimState, ARespawnedSimStartsWhereTheArmWasNotAtZero) {
  const std::string path = TempPath("moving.state");
  IiwaSimOptions options;
  options.state_file = path;
  options.state_save_period_s = 0.05;  // 10 ticks of 5 ms
  std::vector<double> last_q;
  {
    IiwaSim sim(MemqFlags(), options);
    StatusLog log;
    sim.process().lcm().subscribe("IIWA_STATUS", &StatusLog::On, &log);
    orbed::iiwa_command_t command{};
    command.utime = NowMicros();
    command.num_joints = 7;
    command.joint_position = {40 * kDegToRad, 20 * kDegToRad, -30 * kDegToRad, -80 * kDegToRad,
                              20 * kDegToRad, 50 * kDegToRad, 30 * kDegToRad};
    sim.process().lcm().publish("IIWA_COMMAND", &command);
    HandleAll(sim.process().lcm());
    EXPECT_FALSE(fs::exists(path));          // nothing moved yet: nothing to save
    for (int tick = 0; tick < 37; ++tick) {  // 185 ms into a 410 ms move
      sim.Tick();
      HandleAll(sim.process().lcm());
    }
    last_q = log.status.back().joint_position_measured;
  }  // the sim dies mid-move
  IiwaSim respawned(MemqFlags(), options);
  const Eigen::VectorXd q = respawned.arm().q_rad();
  // Not at zero, and at most one save period (10 ticks) of motion behind, joint by joint.
  EXPECT_GT(q[0], 5 * kDegToRad);
  for (int i = 0; i < 7; ++i) {
    EXPECT_LE(std::abs(q[i] - last_q[i]), kSpeedDegPerS[i] * kDegToRad * 0.05 + 1e-12) << "joint " << i + 1;
    EXPECT_LE(std::abs(q[i]), std::abs(last_q[i]) + 1e-12) << "joint " << i + 1;  // behind, never ahead
  }
}

TEST(SimState, AtRestTheStateIsExactlyTheLastConfiguration) {
  const std::string path = TempPath("rest.state");
  IiwaSimOptions options;
  options.state_file = path;
  options.state_save_period_s = 10.0;  // while moving: never; at rest: at once
  std::vector<double> target = {10 * kDegToRad, -5 * kDegToRad, 0, -20 * kDegToRad, 0, 15 * kDegToRad, 0};
  {
    IiwaSim sim(MemqFlags(), options);
    orbed::iiwa_command_t command{};
    command.utime = NowMicros();
    command.num_joints = 7;
    command.joint_position = target;
    sim.process().lcm().publish("IIWA_COMMAND", &command);
    HandleAll(sim.process().lcm());
    for (int tick = 0; tick < 60; ++tick) sim.Tick();  // 0.3 s: arrived (0.2 s)
    ASSERT_EQ(sim.arm().state(), MotionState::kIdle);
  }
  const std::optional<Eigen::VectorXd> q = ReadSimState(path, IiwaSim(MemqFlags(), options).arm().model());
  ASSERT_TRUE(q.has_value());
  for (int i = 0; i < 7; ++i) EXPECT_EQ((*q)[i], target[i]) << "joint " << i + 1;  // bit for bit
}

TEST(SimState, NoFileMeansTheInitialConfiguration) {
  IiwaSimOptions options;
  options.state_file = TempPath("absent.state");
  options.initial_q_deg = {0, 30, 0, -60, 0, 45, 0};
  IiwaSim sim(MemqFlags(), options);
  EXPECT_NEAR(sim.arm().q_rad()[1], 30 * kDegToRad, 1e-15);
}

std::string RefusalOf(const std::string& path) {
  IiwaSimOptions options;
  options.state_file = path;
  try {
    IiwaSim sim(MemqFlags(), options);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

orbed::iiwa_status_t Status(std::vector<double> q_rad) {
  orbed::iiwa_status_t status{};
  status.num_joints = static_cast<int32_t>(q_rad.size());
  status.joint_position_measured = q_rad;
  for (auto* v :
       {&status.joint_velocity_estimated, &status.joint_position_commanded, &status.joint_position_ipo,
        &status.joint_torque_measured, &status.joint_torque_commanded, &status.joint_torque_external}) {
    v->assign(q_rad.size(), 0.0);
  }
  return status;
}

TEST(SimState, DamagedAndImplausibleStatesAreRefusedNamingTheProblem) {
  const std::string path = TempPath("bad.state");
  std::string error;
  ASSERT_TRUE(WriteSimState(path, Status(std::vector<double>(7, 0.1)), &error)) << error;
  EXPECT_EQ(RefusalOf(path), "");
  // Cut short: every length short of the whole file is refused.
  const auto size = fs::file_size(path);
  for (uintmax_t cut : {uintmax_t{3}, uintmax_t{20}, size - 1}) {
    fs::resize_file(path, cut);
    EXPECT_NE(RefusalOf(path).find("cut short"), std::string::npos) << cut << ": " << RefusalOf(path);
    ASSERT_TRUE(WriteSimState(path, Status(std::vector<double>(7, 0.1)), &error));
  }
  // A flipped bit in the payload: the checksum.
  {
    std::fstream f(path, std::ios::binary | std::ios::in | std::ios::out);
    f.seekp(60);
    f.put('\x55');
  }
  EXPECT_NE(RefusalOf(path).find("checksum"), std::string::npos) << RefusalOf(path);
  // Well-formed records that are not a state of this arm.
  ASSERT_TRUE(WriteSimState(path, Status(std::vector<double>(6, 0.1)), &error));
  EXPECT_NE(RefusalOf(path).find("num_joints"), std::string::npos) << RefusalOf(path);
  ASSERT_TRUE(WriteSimState(path, Status({0, 0, 0, std::nan(""), 0, 0, 0}), &error));
  EXPECT_NE(RefusalOf(path).find("joint_position_measured"), std::string::npos) << RefusalOf(path);
  ASSERT_TRUE(WriteSimState(path, Status({0, 3.0, 0, 0, 0, 0, 0}), &error));  // joint 2 beyond 120 deg
  EXPECT_NE(RefusalOf(path).find("joint_position_measured: "), std::string::npos) << RefusalOf(path);
  ASSERT_TRUE(WriteJournalFile(path, {JournalRecord{"IIWA_STATUS", {1, 2, 3}}}, &error));
  EXPECT_NE(RefusalOf(path).find("state file " + path), std::string::npos) << RefusalOf(path);
  ASSERT_TRUE(WriteJournalFile(path, {}, &error));
  EXPECT_NE(RefusalOf(path).find("found 0 record(s)"), std::string::npos) << RefusalOf(path);
  ASSERT_TRUE(WriteJournalFile(path, {MakeJournalRecord("ROBOT_STATE", Status(std::vector<double>(7, 0.1)))},
                               &error));
  EXPECT_NE(RefusalOf(path).find("'ROBOT_STATE'"), std::string::npos) << RefusalOf(path);
}

}  // namespace
}  // namespace orbed::sim
