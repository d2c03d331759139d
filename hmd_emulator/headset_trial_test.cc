// The headset's emulated trial as a pure function: the same inputs give the same outcome bit for
// bit, another trial index or session another draw, the seeds are what they were, and the displays
// used follow num_mirrors. (That the process publishes exactly this outcome for a REQUEST_TRIAL is
// checked in hmd_process_test.)
#include "hmd_emulator/headset_trial.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/units.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::hmd {
namespace {

HmdConfigSet ShippedConfigs() {
  std::vector<std::string> paths;
  for (const auto& rel : DefaultHmdConfigRelativePaths()) paths.push_back(HmdSourcePath(rel));
  return LoadHmdConfigs(paths);
}

HeadsetTrialInputs Inputs(const HmdConfigSet& config) {
  const sim::Scene scene = sim::LoadSceneFile(HmdSourcePath(sim::kDefaultSceneRelativePath));
  const sim::RobotModel robot =
      sim::LoadRobotForScene(HmdSourcePath(sim::RobotModel::kDefaultUrdfRelativePath), scene);
  Eigen::VectorXd q(7);
  q << 0, 30 * kDegToRad, 0, -60 * kDegToRad, 0, 45 * kDegToRad, 0;
  HeadsetTrialInputs in;
  SetRobotAt(robot, q, &in);
  in.X_WR = scene.X_WR;
  in.X_WV_start = EmulatedUser(config.user).StartPose(scene.X_WR);
  in.process_seed = 1;
  in.session_id = "session-a";
  in.trial_index = 0;
  in.num_mirrors = 1;
  return in;
}

void ExpectSame(const TrialOutcome& a, const TrialOutcome& b) {
  EXPECT_TRUE(a.alignment.X_WV.matrix() == b.alignment.X_WV.matrix());
  EXPECT_EQ(a.alignment.duration_s, b.alignment.duration_s);
  EXPECT_EQ(a.alignment.nudges, b.alignment.nudges);
  EXPECT_EQ(a.alignment.stop_reason, b.alignment.stop_reason);
  EXPECT_EQ(a.registration.translation_error_m, b.registration.translation_error_m);
  EXPECT_EQ(a.relocalizations, b.relocalizations);
  EXPECT_TRUE(a.at_alignment.X_WC_est.matrix() == b.at_alignment.X_WC_est.matrix());
}

TEST(HeadsetTrial, SameInputsGiveTheSameOutcome) {
  const HmdConfigSet config = ShippedConfigs();
  const HeadsetTrialInputs in = Inputs(config);
  const TrialOutcome a = RunHeadsetTrial(config, in);
  const TrialOutcome b = RunHeadsetTrial(config, in);
  ExpectSame(a, b);
  // A trial does not depend on what ran before it: another trial in between changes nothing.
  HeadsetTrialInputs other = in;
  other.trial_index = 5;
  RunHeadsetTrial(config, other);
  ExpectSame(RunHeadsetTrial(config, in), a);
  // The person aligned: closer to the truth than the start offset.
  EXPECT_LT((a.alignment.X_WV.translation() - in.X_WR.translation()).norm(),
            (in.X_WV_start.translation() - in.X_WR.translation()).norm());
  EXPECT_GT(a.alignment.duration_s, 0);
  ASSERT_EQ(a.at_capture.size(), 1u);  // one display used
}

TEST(HeadsetTrial, AnotherIndexSessionOrSeedIsAnotherDraw) {
  const HmdConfigSet config = ShippedConfigs();
  const HeadsetTrialInputs in = Inputs(config);
  const TrialOutcome base = RunHeadsetTrial(config, in);
  HeadsetTrialInputs index = in, session = in, seed = in;
  index.trial_index = 1;
  session.session_id = "session-b";
  seed.process_seed = 2;
  for (const HeadsetTrialInputs* other : {&index, &session, &seed}) {
    const TrialOutcome o = RunHeadsetTrial(config, *other);
    EXPECT_FALSE(o.alignment.X_WV.matrix() == base.alignment.X_WV.matrix()) << other->session_id;
  }
}

TEST(HeadsetTrial, NumMirrorsChoosesTheDisplays) {
  const HmdConfigSet config = ShippedConfigs();
  HeadsetTrialInputs in = Inputs(config);
  for (int n = 0; n <= 2; ++n) {
    in.num_mirrors = n;
    const TrialSetup setup = MakeHeadsetTrialSetup(config, in);
    ASSERT_EQ(setup.capture_waypoints.size(), static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i)
      EXPECT_EQ(setup.capture_waypoints[i], config.hmd.displays[i].capture_waypoint);
    EXPECT_EQ(setup.align_waypoint, config.hmd.align_waypoint);
    EXPECT_EQ(setup.settle_s, config.hmd.settle_s);
    EXPECT_EQ(setup.p_RQ.size(), in.p_RQ.size());
  }
  in.num_mirrors = 3;  // the shipped hmd.yaml places two
  EXPECT_THROW(MakeHeadsetTrialSetup(config, in), std::invalid_argument);
  in.num_mirrors = -1;
  EXPECT_THROW(RunHeadsetTrial(config, in), std::invalid_argument);
}

// The session's START may choose where the display captures (contract change 6): the trial then
// captures its frame there, the pose the walk has at that waypoint, not where hmd.displays says.
TEST(HeadsetTrial, TheSessionsCaptureWaypointsChooseWhereTheDisplayCaptures) {
  const HmdConfigSet config = ShippedConfigs();
  HeadsetTrialInputs in = Inputs(config);
  in.capture_waypoints = {config.hmd.align_waypoint};
  ASSERT_NE(config.hmd.displays[0].capture_waypoint, config.hmd.align_waypoint);
  const TrialSetup setup = MakeHeadsetTrialSetup(config, in);
  EXPECT_EQ(setup.capture_waypoints, (std::vector<std::string>{config.hmd.align_waypoint}));
  const TrialOutcome o = RunHeadsetTrial(config, in);
  ASSERT_EQ(o.at_capture.size(), 1u);
  const HeadWaypoint* align = nullptr;
  for (const HeadWaypoint& w : config.walk.waypoints) {
    if (w.name == config.hmd.align_waypoint) align = &w;
  }
  ASSERT_NE(align, nullptr);
  EXPECT_LT((o.at_capture[0].X_WH_true.translation() - align->p_WH).norm(), 1e-9);
  in.capture_waypoints = {"foot_end", "head_end"};  // two names for one display
  EXPECT_THROW(MakeHeadsetTrialSetup(config, in), std::invalid_argument);
}

// slam.faults picks its trials: the session's (or every session's) trial of that index gets the
// fault while aligning; the others are the trials they always were.
TEST(HeadsetTrial, ForcedFaultsOfTheirTrialOnly) {
  HmdConfigSet config = ShippedConfigs();
  const HeadsetTrialInputs in = Inputs(config);  // session-a, trial 0
  const TrialOutcome base = RunHeadsetTrial(config, in);
  EXPECT_EQ(base.faults.losses, 0);
  ScheduledFault fault;
  fault.session_id = "session-a";
  fault.trial_index = 0;
  fault.timed.at_s = 1.0;
  fault.timed.fault.state = TrackingState::kLost;
  fault.timed.fault.duration_s = 2.0;
  config.slam.faults = {fault};
  EXPECT_EQ(MakeHeadsetTrialSetup(config, in).faults.size(), 1u);
  EXPECT_EQ(MakeHeadsetTrialSetup(config, in).max_repeats, config.hmd.max_repeats);
  const TrialOutcome o = RunHeadsetTrial(config, in);
  EXPECT_EQ(o.faults.losses, 1);
  EXPECT_NEAR(o.faults.wait_s, 2.0, 1e-9);
  HeadsetTrialInputs other_index = in, other_session = in;
  other_index.trial_index = 1;
  other_session.session_id = "session-b";
  EXPECT_TRUE(MakeHeadsetTrialSetup(config, other_index).faults.empty());
  EXPECT_TRUE(MakeHeadsetTrialSetup(config, other_session).faults.empty());
  ExpectSame(RunHeadsetTrial(config, other_session), RunHeadsetTrial(ShippedConfigs(), other_session));
  config.slam.faults[0].session_id = "";  // every session's trial 0
  EXPECT_EQ(MakeHeadsetTrialSetup(config, other_session).faults.size(), 1u);
}

TEST(HeadsetTrial, SeedsArePinned) {
  // Distinct per purpose, index and session; a pure function of its arguments.
  const std::uint64_t slam = TrialSeed(1, "s", 0, kSessionMapPurpose);
  EXPECT_EQ(slam, TrialSeed(1, "s", 0, kSessionMapPurpose));
  EXPECT_NE(slam, TrialSeed(1, "s", 0, kTrialSeedPurpose));
  EXPECT_NE(slam, TrialSeed(1, "s", 1, kSessionMapPurpose));
  EXPECT_NE(slam, TrialSeed(1, "t", 0, kSessionMapPurpose));
  EXPECT_NE(slam, TrialSeed(2, "s", 0, kSessionMapPurpose));
}

}  // namespace
}  // namespace orbed::hmd
