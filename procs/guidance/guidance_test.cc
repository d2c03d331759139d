// orbed-guidance against hand computations:
//   - joint kinds from the iiwa's geometry: 1, 3, 5, 7 twist, 2, 4, 6 revolve (the paper's split);
//   - errors current − target in degrees, the next joint the first one outside the tolerance from the
//     base, done when none is;
//   - targets outside the limits, of the wrong size, a bad mode or tolerance are refused by name;
//   - the process on memq://: GUIDANCE for the last good IIWA_STATUS, bad ones counted by class.
#include "procs/guidance/guidance.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <orbed/target_pose_t.hpp>

#include "base/source_paths.h"
#include "base/test_command.h"
#include "base/units.h"
#include "lcmtypes/contract/conversions.h"
#include "procs/guidance/guidance_process.h"

namespace orbed::guidance {
namespace {

sim::RobotModel Iiwa() {
  return sim::RobotModel::LoadFile(SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath));
}

Eigen::VectorXd Deg(std::vector<double> q_deg) {
  return Eigen::Map<Eigen::VectorXd>(q_deg.data(), q_deg.size()) * kDegToRad;
}

constexpr int8_t T = orbed::guidance_t::JOINT_TWIST, R = orbed::guidance_t::JOINT_REVOLVE;

TEST(Guidance, TheIiwasOddJointsTwistAndItsEvenJointsRevolve) {
  EXPECT_EQ(JointKinds(Iiwa()), (std::vector<int8_t>{T, R, T, R, T, R, T}));
}

TEST(Guidance, ErrorsNextJointAndDoneByHand) {
  const sim::RobotModel model = Iiwa();
  GuidanceTarget target;
  target.mode = orbed::guidance_t::MODE_AR_REFLECTIVE;
  target.q_target_rad = Deg({0, 30, 0, -60, 0, 45, 0});
  target.tolerance_deg = 1.0;
  const GuidanceCore core(model, target);

  // Joint 1 is 10 deg past its target: it is next, whatever the others.
  orbed::guidance_t g = core.Compute(Deg({10, 30.5, 0, -60, 0, 45, -20}), 77);
  EXPECT_EQ(g.utime, 77);
  EXPECT_EQ(g.mode, int{orbed::guidance_t::MODE_AR_REFLECTIVE});
  ASSERT_EQ(g.num_joints, 7);
  const double expected[7] = {10, 0.5, 0, 0, 0, 0, -20};
  for (int i = 0; i < 7; ++i) {
    EXPECT_NEAR(g.error_deg[i], expected[i], 1e-9) << "joint " << i + 1;
    EXPECT_DOUBLE_EQ(g.target_position[i], target.q_target_rad[i]);
  }
  EXPECT_EQ(g.joint_kind, (std::vector<int8_t>{T, R, T, R, T, R, T}));
  EXPECT_EQ(g.next_joint, 0);
  EXPECT_FALSE(g.done);
  // Joint 1 done, joint 2 within the tolerance (0.5 deg): joint 7 is next (−20 deg: turn it back +20).
  g = core.Compute(Deg({0.9, 30.5, 0, -60, 0, 45, -20}), 78);
  EXPECT_EQ(g.next_joint, 6);
  EXPECT_NEAR(g.error_deg[6], -20, 1e-9);
  // All within 1 deg: done.
  g = core.Compute(Deg({-0.99, 30.99, 0.5, -60.5, 0, 44.01, 0.3}), 79);
  EXPECT_EQ(g.next_joint, -1);
  EXPECT_TRUE(g.done);
}

TEST(Guidance, BadTargetsAreRefusedByName) {
  const sim::RobotModel model = Iiwa();
  auto refused = [&model](GuidanceTarget t) -> std::string {
    try {
      GuidanceCore core(model, t);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "(accepted)";
  };
  GuidanceTarget t;
  t.q_target_rad = Deg({0, 121, 0, 0, 0, 0, 0});  // joint 2's limit is 120 deg
  EXPECT_NE(refused(t).find("iiwa_joint_2"), std::string::npos) << refused(t);
  t.q_target_rad = Deg({0, 0, 0});
  EXPECT_NE(refused(t).find("expected 7"), std::string::npos) << refused(t);
  t.q_target_rad = Deg({0, 0, 0, 0, 0, 0, 0});
  t.tolerance_deg = 0;
  EXPECT_NE(refused(t).find("tolerance"), std::string::npos);
  t.tolerance_deg = 1;
  t.mode = 5;
  EXPECT_NE(refused(t).find("mode 5"), std::string::npos);
  EXPECT_THROW(GuidanceModeFromName("hologram"), std::invalid_argument);
  EXPECT_EQ(GuidanceModeFromName("fixed"), int{orbed::guidance_t::MODE_FIXED_DISPLAY});
}

orbed::iiwa_status_t Status(const Eigen::VectorXd& q) {
  orbed::iiwa_status_t s{};
  s.num_joints = static_cast<int32_t>(q.size());
  s.joint_position_measured.assign(q.data(), q.data() + q.size());
  for (auto* v : {&s.joint_velocity_estimated, &s.joint_position_commanded, &s.joint_position_ipo,
                  &s.joint_torque_measured, &s.joint_torque_commanded, &s.joint_torque_external}) {
    v->assign(q.size(), 0.0);
  }
  return s;
}

TEST(GuidanceProcess, PublishesForTheLastGoodStatusAndCountsBadOnes) {
  CommonFlags flags("orbed-guidance-test");
  flags.lcm_url = "memq://";
  flags.duration_s = 0.3;
  GuidanceOptions options;
  options.target.q_target_rad = Deg({0, 30, 0, -60, 0, 45, 0});
  options.rate_hz = 50;
  GuidanceProcess guidance(flags, options);

  struct Collector {
    std::vector<orbed::guidance_t> seen;
    void On(const lcm::ReceiveBuffer*, const std::string&, const orbed::guidance_t* msg) {
      seen.push_back(*msg);
    }
  } collector;
  guidance.process().lcm().subscribe("GUIDANCE", &Collector::On, &collector);

  auto good = Status(Deg({0, 30, 5, -60, 0, 45, 0}));
  guidance.process().lcm().publish("IIWA_STATUS", &good);
  auto short_status = Status(Deg({0, 30, 0, -60, 0, 45}));
  guidance.process().lcm().publish("IIWA_STATUS", &short_status);
  auto nan = good;
  nan.joint_position_measured[3] = std::nan("");
  guidance.process().lcm().publish("IIWA_STATUS", &nan);
  auto beyond = Status(Deg({0, 125, 0, -60, 0, 45, 0}));
  guidance.process().lcm().publish("IIWA_STATUS", &beyond);
  EXPECT_EQ(guidance.Run(), 0);

  ASSERT_FALSE(collector.seen.empty());
  const orbed::guidance_t& last = collector.seen.back();
  EXPECT_EQ(last.next_joint, 2);  // joint 3, 5 deg off
  EXPECT_NEAR(last.error_deg[2], 5.0, 1e-9);
  EXPECT_FALSE(last.done);
  // A second after the last status (the run ended 0.3 s after it), the arm's pose is stale: none.
  EXPECT_TRUE(guidance.GuidanceNow(last.utime).has_value());
  EXPECT_FALSE(guidance.GuidanceNow(last.utime + 1'000'000).has_value());
  const auto counts = guidance.process().rejections().counts();
  EXPECT_EQ(counts.at("IIWA_STATUS/num_joints"), 1);
  EXPECT_EQ(counts.at("IIWA_STATUS/non_finite"), 1);
  EXPECT_EQ(counts.at("IIWA_STATUS/limits"), 1);
}

// One of several arms (--arm a1): the guidance reads IIWA_STATUS_A1 and publishes GUIDANCE_A1; the
// single arm's channels are neither read nor written.
TEST(GuidanceProcess, AnArmOfSeveralIsGuidedOnItsOwnChannels) {
  CommonFlags flags("orbed-guidance-test");
  flags.lcm_url = "memq://";
  flags.duration_s = 0.3;
  GuidanceOptions options;
  options.target.q_target_rad = Deg({0, 30, 0, -60, 0, 45, 0});
  options.rate_hz = 50;
  options.stale_after_s = 3600;
  options.arm = "a1";
  GuidanceProcess guidance(flags, options);
  std::map<std::string, std::vector<orbed::guidance_t>> seen;
  for (const char* channel : {"GUIDANCE", "GUIDANCE_A1"}) {
    guidance.process().lcm().subscribeFunction(
        channel,
        +[](const lcm::ReceiveBuffer*, const std::string& ch, const orbed::guidance_t* msg,
            std::map<std::string, std::vector<orbed::guidance_t>>* out) { (*out)[ch].push_back(*msg); },
        &seen);
  }
  auto a1 = Status(Deg({0, 30, 0, -60, 0, 45, 7}));  // joint 7, 7 deg off
  guidance.process().lcm().publish("IIWA_STATUS_A1", &a1);
  auto single = Status(Deg({20, 30, 0, -60, 0, 45, 0}));
  guidance.process().lcm().publish("IIWA_STATUS", &single);
  EXPECT_EQ(guidance.Run(), 0);
  EXPECT_EQ(seen.count("GUIDANCE"), 0u);
  ASSERT_FALSE(seen["GUIDANCE_A1"].empty());
  EXPECT_EQ(seen["GUIDANCE_A1"].back().next_joint, 6);
  EXPECT_NEAR(seen["GUIDANCE_A1"].back().error_deg[6], 7.0, 1e-9);
  EXPECT_NEAR(seen["GUIDANCE_A1"].back().error_deg[0], 0.0, 1e-9);
}

// IGTL_TARGET: an unreachable trocar (5 m away) and a non-unit quaternion are refused and the
// command-line target stays; other names are ignored.
TEST(GuidanceProcess, IgtlTargetsTheIkCannotDockAreRefused) {
  CommonFlags flags("orbed-guidance-test");
  flags.lcm_url = "memq://";
  flags.duration_s = 1.0;
  GuidanceOptions options;
  options.target.q_target_rad = Deg({0, 30, 0, -60, 0, 45, 0});
  options.stale_after_s = 3600;  // the status below stays fresh however slowly this machine runs
  GuidanceProcess guidance(flags, options);
  // The cheap messages first, the one the IK works on (0.1 s, more under a sanitizer) last: the run's
  // duration is counted from its start.
  auto status = Status(Deg({0, 0, 0, 0, 0, 0, 0}));
  guidance.process().lcm().publish("IIWA_STATUS", &status);
  orbed::target_pose_t far{};
  far.source = "igtl";
  far.name = "Trocar";
  far.X_WT.position_m[0] = 5.0;
  far.X_WT.quaternion_wxyz[0] = 1;
  orbed::target_pose_t bad = far;
  bad.X_WT.quaternion_wxyz[0] = 2;
  guidance.process().lcm().publish("IGTL_TARGET", &bad);
  orbed::target_pose_t other = bad;
  other.name = "Needle";
  guidance.process().lcm().publish("IGTL_TARGET", &other);
  guidance.process().lcm().publish("IGTL_TARGET", &far);
  EXPECT_EQ(guidance.Run(), 0);
  const auto counts = guidance.process().rejections().counts();
  ASSERT_EQ(counts.count("IGTL_TARGET/ik"), 1u);
  EXPECT_EQ(counts.at("IGTL_TARGET/ik"), 1);
  EXPECT_EQ(counts.at("IGTL_TARGET/pose"), 1);
  EXPECT_EQ(counts.size(), 2u);
  const auto g = guidance.GuidanceNow(NowMicros());
  ASSERT_TRUE(g.has_value());
  EXPECT_NEAR(g->target_position[1], 30 * kDegToRad, 1e-12);  // the command line's target
}

std::string WritePlan(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

TEST(GuidancePlan, TargetsAreReadFromAnOrbedRobotPlanAndCheckedAsInput) {
  const std::string plan = WritePlan("plan.json",
                                     R"({"scene": "x", "targets": [{"q_deg": [0, 30, 0, -60, 0, 45, 0]},
                                         {"q_deg": [10, 20, 30, -40, 50, 60, -70], "clearance_m": 0.1}]})");
  const Eigen::VectorXd q = ReadPlanTarget(plan, 2, 7);
  EXPECT_NEAR((q - Deg({10, 20, 30, -40, 50, 60, -70})).norm(), 0.0, 1e-12);
  auto error = [](const std::string& path, int number) -> std::string {
    try {
      ReadPlanTarget(path, number, 7);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "(accepted)";
  };
  EXPECT_NE(error(plan, 3).find("has 2 target(s); there is no target 3"), std::string::npos)
      << error(plan, 3);
  const std::string short_q = WritePlan("short.json", R"({"targets": [{"q_deg": [0, 30, 0]}]})");
  EXPECT_NE(error(short_q, 1).find("targets[0].q_deg"), std::string::npos) << error(short_q, 1);
  const std::string huge = WritePlan("huge.json", R"({"targets": [{"q_deg": [0, 30, 0, 1e400, 0, 0, 0]}]})");
  EXPECT_NE(error(huge, 1).find("not valid JSON"), std::string::npos) << error(huge, 1);  // beyond a double
  const std::string wild = WritePlan("wild.json", R"({"targets": [{"q_deg": [0, 30, 0, 400, 0, 0, 0]}]})");
  EXPECT_NE(error(wild, 1).find("targets[0].q_deg"), std::string::npos) << error(wild, 1);
  EXPECT_NE(error(WritePlan("garbage.json", "{not json"), 1), "(accepted)");
  // The command with a plan runs, and with neither (then it waits for SETUP_TASK); with both it
  // refuses.
  EXPECT_EQ(
      test::RunCommand(RunGuidance, "orbed-guidance",
                       {"--plan", plan, "--target", "2", "--lcm-url", "memq://", "--duration-s", "0.05"})
          .code,
      0);
  EXPECT_EQ(
      test::RunCommand(RunGuidance, "orbed-guidance", {"--lcm-url", "memq://", "--duration-s", "0.05"}).code,
      0);
  const test::CommandRun both =
      test::RunCommand(RunGuidance, "orbed-guidance",
                       {"--plan", plan, "--target-deg", "0,0,0,0,0,0,0", "--lcm-url", "memq://"});
  EXPECT_NE(both.code, 0);
  EXPECT_NE(both.code, 1);  // a usage error, not a failure to run
  EXPECT_NE(both.err.find("excludes"), std::string::npos) << both.err;
}

TEST(GuidanceCli, BadArgumentsExitTwoAndNameTheFlag) {
  test::CommandRun r = test::RunCommand(RunGuidance, "orbed-guidance", {"--target-deg", "0,30,x"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--target-deg"), std::string::npos) << r.err;
  r = test::RunCommand(RunGuidance, "orbed-guidance", {"--target-deg", "0,0,0,0,0,0,0", "--mode", "holo"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("ar, ar_reflective or fixed"), std::string::npos) << r.err;
  r = test::RunCommand(RunGuidance, "orbed-guidance",
                       {"--target-deg", "0,130,0,0,0,0,0", "--lcm-url", "memq://", "--duration-s", "0.05"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("iiwa_joint_2"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace orbed::guidance
