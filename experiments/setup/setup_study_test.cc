// setup_study_test: the in-process set-up user (setup_study.h) and orbed-setup-study
// (setup_study_cli.h):
//   - equal to the bus: for the pinned seeds and run ids RunSetupUser's SetupRun, written as
//     setup_results.json, equals byte for byte what orbed-setup wrote over the bus
//     (tests/integration/testdata/setup_pinned_results.json: user u1, seed 5, measured
//     registration; setup_truth_pinned_results.json: user u2, seed 6, headset modes with the true
//     registration), each user's patient and (start, target) pairs drawn from the design. Made by
//     `scripts/orbed study --users 0 --setup-users 3 --seed 5 --registration-share` (lockstep, sim
//     rate 100): its setup-u1/ and setup-truth-u2/ setup_results.json with the "provenance" line
//     taken out (the file names the run folder's record); re-pin them so whenever the set-up's
//     cores change a number;
//   - the design reaches the run (the pairs are UserDesignFor's draw, the patient's scene the
//     sim's), and --plan / --start-deg still give the plan's targets from one start;
//   - the same files for any thread count;
//   - the injected registration error is exactly the asked shift and turn (closed form), reaches
//     the assistant (a shifted hologram moves the reached joints) and not the conductor's record of
//     the alignment;
//   - bad options exit 2.
#include "experiments/setup/setup_study.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <orbed/guidance_t.hpp>

#include "base/source_paths.h"
#include "experiments/setup/design.h"
#include "experiments/setup/setup_study_cli.h"

namespace orbed::setup {
namespace {

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// User k of the pinned study (scripts/orbed study --seed 5: user k has seed 5 + k - 1).
SetupUserOptions PinnedUser(int k, bool truth) {
  SetupUserOptions o;
  o.user = "u" + std::to_string(k);
  o.user_seed = 5 + static_cast<uint64_t>(k - 1);
  o.run_id = std::string("study-s5-setup-") + (truth ? "truth-" : "") + o.user;
  if (truth) {
    o.modes = {orbed::guidance_t::MODE_AR_REFLECTIVE, orbed::guidance_t::MODE_AR};
    o.perfect_registration = true;
  }
  return o;
}

TEST(SetupStudy, EqualsTheBusRun) {
  const std::string pinned = ReadText(SourceTreePath("tests/integration/testdata/setup_pinned_results.json"));
  ASSERT_FALSE(pinned.empty());
  EXPECT_EQ(SetupRunJson(RunSetupUser(PinnedUser(1, false)), false), pinned);
}

// The in-process rows make the CSVs the bus run's setup_results.json makes, every column (the
// design's ids and starts included).
TEST(SetupStudy, TheTableRowsAreTheResultFilesRows) {
  const std::string pinned = SourceTreePath("tests/integration/testdata/setup_pinned_results.json");
  const SetupRun run = RunSetupUser(PinnedUser(1, false));
  const std::vector<study::SetupUserRun> ours = {TableRun(run)}, bus = {study::ReadSetupResults(pinned)};
  EXPECT_EQ(study::SetupJointsCsv(ours), study::SetupJointsCsv(bus));
  EXPECT_EQ(study::SetupTimesCsv(ours), study::SetupTimesCsv(bus));
  EXPECT_EQ(study::SetupDockingCsv(ours), study::SetupDockingCsv(bus));
  EXPECT_NE(study::SetupJointsCsv(ours).find(",ready,"), std::string::npos);  // a design id is there
}

TEST(SetupStudy, EqualsTheBusRunWithTheTrueRegistration) {
  const std::string pinned =
      ReadText(SourceTreePath("tests/integration/testdata/setup_truth_pinned_results.json"));
  ASSERT_FALSE(pinned.empty());
  EXPECT_EQ(SetupRunJson(RunSetupUser(PinnedUser(2, true)), false), pinned);
}

TEST(SetupStudy, TheSameForAnyThreadCount) {
  SetupUserOptions base;
  base.targets = 1;
  std::vector<SetupUserOptions> jobs;
  for (int k = 1; k <= 4; ++k)
    jobs.push_back(StudyUser(base, 11, "threads", 2, k > 2 ? 1 : 0, (k - 1) % 2 + 1));
  const std::vector<SetupRun> one = RunSetupUsers(jobs, 1);
  const std::vector<SetupRun> three = RunSetupUsers(jobs, 3);
  ASSERT_EQ(one.size(), jobs.size());
  ASSERT_EQ(three.size(), jobs.size());
  for (size_t i = 0; i < jobs.size(); ++i) {
    EXPECT_TRUE(one[i].ok) << one[i].error;
    EXPECT_EQ(SetupRunJson(one[i], false), SetupRunJson(three[i], false)) << "job " << i;
  }
}

TEST(SetupStudy, UsersAreNumberedAsTheBusStudy) {
  const SetupUserOptions first = StudyUser({}, 5, "study-s5", 8, 0, 3);
  EXPECT_EQ(first.user, "u3");
  EXPECT_EQ(first.user_seed, 7u);
  EXPECT_EQ(first.run_id, "study-s5-setup-u3");
  const SetupUserOptions later = StudyUser({}, 5, "study-s5", 8, 2, 3);
  EXPECT_EQ(later.user, "u3");
  EXPECT_EQ(later.user_seed, 5u + 2 * 8 + 2);
  EXPECT_EQ(later.run_id, "study-s5-m2-setup-u3");
}

TEST(SetupStudy, InjectionIsTheAskedShiftAndTurn) {
  Eigen::Isometry3d X_WV = Eigen::Isometry3d::Identity();
  X_WV.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  X_WV.translation() = Eigen::Vector3d(0.25, -0.55, 0.75);
  const Eigen::Vector3d d = Eigen::Vector3d(2, -1, 2) / 3.0;  // unit
  const Eigen::Vector3d a = Eigen::Vector3d(0, 0.6, 0.8);     // unit
  const double offset_m = 0.030, tilt_rad = 3.0 * M_PI / 180.0;
  const Eigen::Isometry3d moved = InjectRegistrationError(X_WV, offset_m, tilt_rad, d, a);
  // p' − p = 30 mm · d: (20, −10, 20) mm.
  const Eigen::Vector3d shift = moved.translation() - X_WV.translation();
  EXPECT_NEAR(shift.x(), 0.020, 1e-15);
  EXPECT_NEAR(shift.y(), -0.010, 1e-15);
  EXPECT_NEAR(shift.z(), 0.020, 1e-15);
  // R' R⁻¹ is a turn of 3° about a: trace = 1 + 2 cos 3°, axis a.
  const Eigen::Matrix3d turn = moved.linear() * X_WV.linear().transpose();
  EXPECT_NEAR(turn.trace(), 1 + 2 * std::cos(tilt_rad), 1e-14);
  const Eigen::AngleAxisd turned(turn);
  EXPECT_NEAR(turned.angle(), tilt_rad, 1e-12);
  EXPECT_NEAR((turned.axis() - a).norm(), 0, 1e-9);
  // Nothing asked, nothing moved.
  EXPECT_TRUE(InjectRegistrationError(X_WV, 0, 0, d, a).isApprox(X_WV, 1e-15));
}

TEST(SetupStudy, RandomInjectionIsAUnitDirectionAndAHorizontalAxisPerSetUp) {
  RegistrationInjection injection;
  injection.random_direction = true;
  const auto [d1, a1] = InjectionFor(injection, 3, "s-u1-ar-1-ar");
  const auto [d2, a2] = InjectionFor(injection, 3, "s-u1-ar-2-ar");
  EXPECT_NEAR(d1.norm(), 1, 1e-12);
  EXPECT_NEAR(a1.norm(), 1, 1e-12);
  EXPECT_EQ(a1.z(), 0);
  EXPECT_GT((d1 - d2).norm(), 1e-6);
  const auto [d1_again, a1_again] = InjectionFor(injection, 3, "s-u1-ar-1-ar");
  EXPECT_EQ(d1, d1_again);
  EXPECT_EQ(a1, a1_again);
}

TEST(SetupStudy, InjectionReachesTheAssistantNotTheAlignmentRecord) {
  SetupUserOptions o;
  o.user_seed = 3;
  o.targets = 1;
  o.modes = {orbed::guidance_t::MODE_AR};
  const SetupRun plain = RunSetupUser(o);
  o.injection.offset_m = 0.05;
  o.injection.tilt_rad = 5 * M_PI / 180;
  const SetupRun injected = RunSetupUser(o);
  ASSERT_TRUE(plain.ok && injected.ok);
  ASSERT_EQ(plain.setups.size(), 1u);
  ASSERT_EQ(injected.setups.size(), 1u);
  // The alignments are the same people's: the registration measured is the same.
  ASSERT_TRUE(plain.setups[0].alignment && plain.setups[0].alignment->mean);
  ASSERT_TRUE(injected.setups[0].alignment && injected.setups[0].alignment->mean);
  EXPECT_TRUE(plain.setups[0].alignment->mean->X_WV.isApprox(injected.setups[0].alignment->mean->X_WV, 0));
  // The hologram the assistant matched moved: so did the joints it reached.
  EXPECT_NE(plain.setups[0].reached_deg, injected.setups[0].reached_deg);
}

TEST(SetupStudy, RunsTheUsersDrawFromTheDesign) {
  SetupUserOptions o;
  o.user_seed = 12;
  o.targets = 2;
  o.modes = {orbed::guidance_t::MODE_AR};
  const UserDesign design = UserDesignFor(SourceTreePath(kDefaultDesignRelativePath), "", 12, 2);
  const SetupRun run = RunSetupUser(o);
  ASSERT_TRUE(run.ok) << run.error;
  ASSERT_EQ(run.setups.size(), design.pairs.size());
  for (size_t i = 0; i < design.pairs.size(); ++i) {
    EXPECT_EQ(run.setups[i].start_id, design.pairs[i].start_id);
    EXPECT_EQ(run.setups[i].target_id, design.pairs[i].target_id);
    EXPECT_EQ(run.setups[i].start_deg, design.pairs[i].start_deg);
    EXPECT_EQ(run.setups[i].target_deg, design.pairs[i].target_deg);
  }
  // Another patient's scene fixes the patient (orbed-setup --scene): its own targets.
  const DesignCatalog catalog = ReadDesignFile(SourceTreePath(kDefaultDesignRelativePath));
  for (const DesignPatient& p : catalog.patients) {
    if (p.name == design.patient) continue;
    o.scene_path = SourceTreePath(p.scene);
    const SetupRun other = RunSetupUser(o);
    ASSERT_TRUE(other.ok) << other.error;
    EXPECT_EQ(other.setups[0].target_id.rfind(p.name + "/", 0), 0u) << other.setups[0].target_id;
    break;
  }
}

TEST(SetupStudy, ThePlanRunsItsTargetsFromOneStart) {
  SetupUserOptions o;
  o.user_seed = 3;
  o.targets = 1;
  o.modes = {orbed::guidance_t::MODE_FIXED_DISPLAY};
  o.use_plan = true;
  o.start_deg = {0, 20, 0, -60, 0, 40, 0};
  const SetupRun run = RunSetupUser(o);
  ASSERT_TRUE(run.ok) << run.error;
  ASSERT_EQ(run.setups.size(), 1u);
  EXPECT_EQ(run.setups[0].start_deg, o.start_deg);
  EXPECT_EQ(run.setups[0].start_id, "");
  EXPECT_EQ(run.setups[0].target_id, "");
}

int RunCli(std::vector<const char*> args) {
  args.insert(args.begin(), "orbed-setup-study");
  std::ostringstream out, err;
  return RunSetupStudy(static_cast<int>(args.size()), args.data(), out, err);
}

TEST(SetupStudyCli, BadOptionsExit2) {
  EXPECT_EQ(RunCli({"--users", "0"}), 2);
  EXPECT_EQ(RunCli({"--studies", "-1"}), 2);
  EXPECT_EQ(RunCli({"--threads", "0"}), 2);
  EXPECT_EQ(RunCli({"--targets", "7"}), 2);
  EXPECT_EQ(RunCli({"--plan", "x.json", "--start-deg", "0,1"}), 2);
  EXPECT_EQ(RunCli({"--registration", "perfect"}), 2);
  EXPECT_EQ(RunCli({"--registration-offset-mm", "nan"}), 2);
  EXPECT_EQ(RunCli({"--registration-tilt-deg", "inf"}), 2);
  EXPECT_EQ(RunCli({"--registration-direction", "0,0,0"}), 2);
  EXPECT_EQ(RunCli({"--registration-direction", "1,x,0"}), 2);
  EXPECT_EQ(RunCli({"--registration-axis", "1,0"}), 2);
  EXPECT_EQ(RunCli({"--no-such-flag"}), 2);
  EXPECT_EQ(RunCli({"--help"}), 0);
}

}  // namespace
}  // namespace orbed::setup
