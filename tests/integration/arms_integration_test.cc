// Several arms over real LCM in a private network namespace: two orbed-iiwa-sim
// processes, `--arm a0` and `--arm a1` of sim/models/scenes/four_arms_or.yaml, each on its own
// suffixed channels and each knowing the other from its ROBOT_STATE_<NAME>. a0, turned and laid
// horizontal toward a1 (upright 0.7 m away), stops before a1, naming a1's link; a1, at rest, sees
// a0 come close in its own COLLISION_STATUS_A1; the single arm's plain channels stay silent.
#include <cmath>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <lcm/lcm-cpp.hpp>
#include <orbed/collision_status_t.hpp>
#include <orbed/iiwa_command_t.hpp>
#include <orbed/robot_state_t.hpp>

#include "base/units.h"
#include "lcmtypes/contract/conversions.h"
#include "sim/scene.h"
#include "tests/integration/testbed_util.h"

namespace orbed::testing {
namespace {

struct Seen {
  orbed::robot_state_t a0;
  bool have_a0 = false;
  orbed::collision_status_t collision_a0, collision_a1;
  int plain_status = 0;  // anything on the single arm's IIWA_STATUS
};

Eigen::Vector3d ReadVector(const YAML::Node& node) {
  return Eigen::Vector3d(node[0].as<double>(), node[1].as<double>(), node[2].as<double>());
}

bool Names(const orbed::collision_status_t& status, const std::string& prefix) {
  for (const auto& contact : status.contacts) {
    if (contact.body_b.rfind(prefix, 0) == 0) return true;
  }
  return false;
}

TEST(Arms, OneArmStopsBeforeAnotherRunningInItsOwnProcess) {
  const std::string scene = SourcePath("sim/models/scenes/four_arms_or.yaml");
  RunningProcess a0({BinPath("orbed-iiwa-sim"), "--scene", scene, "--arm", "a0", "--name", "sim_a0"});
  RunningProcess a1({BinPath("orbed-iiwa-sim"), "--scene", scene, "--arm", "a1", "--name", "sim_a1"});
  lcm::LCM lcm;
  ASSERT_TRUE(lcm.good());
  Seen seen;
  lcm.subscribeFunction(
      "ROBOT_STATE_A0",
      +[](const lcm::ReceiveBuffer*, const std::string&, const orbed::robot_state_t* m, Seen* s) {
        s->a0 = *m;
        s->have_a0 = true;
      },
      &seen);
  lcm.subscribeFunction(
      "COLLISION_STATUS_A0",
      +[](const lcm::ReceiveBuffer*, const std::string&, const orbed::collision_status_t* m, Seen* s) {
        s->collision_a0 = *m;
      },
      &seen);
  lcm.subscribeFunction(
      "COLLISION_STATUS_A1",
      +[](const lcm::ReceiveBuffer*, const std::string&, const orbed::collision_status_t* m, Seen* s) {
        s->collision_a1 = *m;
      },
      &seen);
  lcm.subscribeFunction(
      "IIWA_STATUS", +[](const lcm::ReceiveBuffer*, const std::string&, Seen* s) { ++s->plain_status; },
      &seen);
  auto until = [&](const std::function<bool()>& done, double timeout_s) {
    return WaitFor(
        [&] {
          lcm.handleTimeout(10);
          return done();
        },
        timeout_s);
  };
  ASSERT_TRUE(until([&] { return seen.have_a0 && !seen.collision_a1.link_names.empty(); }, 30));

  // Joint 1 to 90 deg (turning in place), then joint 2 to 90 deg: horizontal, toward a1. Commands
  // are re-sent as a client would (a datagram may be lost), until the arm has settled.
  auto command = [&](const std::vector<double>& q_deg) {
    orbed::iiwa_command_t cmd{};
    cmd.utime = NowMicros();
    cmd.num_joints = 7;
    for (double q : q_deg) cmd.joint_position.push_back(q * kDegToRad);
    lcm.publish("IIWA_COMMAND_A0", &cmd);
  };
  ASSERT_TRUE(until(
      [&] {
        command({90, 0, 0, 0, 0, 0, 0});
        return std::abs(seen.a0.joint_position[0] - M_PI / 2) < 1e-9;
      },
      30));
  ASSERT_TRUE(until(
      [&] {
        command({90, 90, 0, 0, 0, 0, 0});
        return seen.a0.motion_state == orbed::robot_state_t::MOTION_STOPPED_BEFORE_COLLISION;
      },
      30))
      << "a0 did not stop: " << seen.a0.stop_reason;
  EXPECT_NE(seen.a0.stop_reason.find(" vs a1/"), std::string::npos) << seen.a0.stop_reason;
  EXPECT_LT(seen.a0.joint_position[1], 89 * kDegToRad);
  // Both arms see the pair within the report distance (5 cm) in their own COLLISION_STATUS.
  ASSERT_TRUE(until([&] { return Names(seen.collision_a0, "a1/") && Names(seen.collision_a1, "a0/"); }, 10));
  EXPECT_GT(seen.collision_a0.min_distance_m, 0.0);
  EXPECT_EQ(seen.plain_status, 0) << "an arm of several published on the single arm's IIWA_STATUS";
}

// Several headsets, each registering its own map to its own arm: two arms (a1 and a2 of
// four_arms_or.yaml, 1.4 m apart), and per arm a headset with its own person (--user-seed), its
// registration server and its ViRAAl conductor, all on the headset's and the arm's channels, run
// at once on one bus. Each run ends ok; each results.json holds the truth of its own arm (the
// scene file's base) and a mean registration near that arm, not the other.
TEST(Arms, TwoHeadsetsRegisterTheirMapsToTwoArmsAtOnce) {
  const std::string scene = SourcePath("sim/models/scenes/four_arms_or.yaml");
  const std::string dir = MakeTempDir("arms_viraal");
  const std::vector<std::pair<std::string, std::string>> pairs = {{"h1", "a1"}, {"h2", "a2"}};
  std::vector<std::unique_ptr<RunningProcess>> processes, conductors;
  for (const auto& [headset, arm] : pairs) {
    processes.push_back(std::make_unique<RunningProcess>(std::vector<std::string>{
        BinPath("orbed-iiwa-sim"), "--scene", scene, "--arm", arm, "--name", "sim_" + arm}));
    processes.push_back(std::make_unique<RunningProcess>(std::vector<std::string>{
        BinPath("orbed-registration"), "--headset", headset, "--name", "registration_" + headset}));
    processes.push_back(std::make_unique<RunningProcess>(
        std::vector<std::string>{BinPath("orbed-hmd"), "--scene", scene, "--headset", headset, "--arm", arm,
                                 "--user-seed", headset == "h1" ? "11" : "12", "--name", "hmd_" + headset}));
  }
  for (const auto& [headset, arm] : pairs) {
    std::filesystem::create_directories(dir + "/" + headset);
    conductors.push_back(std::make_unique<RunningProcess>(std::vector<std::string>{
        BinPath("orbed-scenario"), "--headset", headset, "--arm", arm, "--trials", "2", "--run-id",
        "two-" + headset, "--results-dir", dir + "/" + headset, "--name", "scenario_" + headset}));
  }
  const sim::Scene four = sim::LoadSceneFile(scene);
  for (size_t k = 0; k < pairs.size(); ++k) {
    const auto& [headset, arm] = pairs[k];
    SCOPED_TRACE(headset + " at " + arm);
    ASSERT_TRUE(conductors[k]->Wait(240)) << "the run did not finish";
    ASSERT_EQ(conductors[k]->exit_code(), 0);
    const YAML::Node results = YAML::LoadFile(dir + "/" + headset + "/results.json");
    EXPECT_EQ(results["status"].as<std::string>(), "ok");
    const Eigen::Vector3d p_WR = ReadVector(results["X_WR"]["position_m"]);
    EXPECT_LT((p_WR - four.FindArm(arm)->X_WR.translation()).norm(), 1e-9);
    ASSERT_EQ(results["sessions"].size(), 2u);
    for (const auto& session : results["sessions"]) {
      ASSERT_EQ(session["trials"].size(), 2u);
      EXPECT_LT(session["mean"]["translation_error_mm"].as<double>(), 200.0);
      // The mean places the hologram at this arm: within 0.2 m of its base, 1.4 m from the other's.
      const Eigen::Vector3d p_WV = ReadVector(session["mean"]["X_WV"]["position_m"]);
      EXPECT_LT((p_WV - p_WR).norm(), 0.2);
    }
  }
}

}  // namespace
}  // namespace orbed::testing
