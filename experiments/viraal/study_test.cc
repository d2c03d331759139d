// The offline study against the live testbed and the paper's claims:
//   - for the pinned seed and run id its results equal, number for number, the results.json that
//     `scripts/orbed run` wrote (tests/integration/testdata/viraal_pinned_results.json): one
//     protocol, one set of numbers;
//   - the mechanism: with a display captured from another viewpoint the misalignment is smaller
//     (rank test over many trials), with a display from the alignment viewpoint it is not (the
//     negative control);
//   - the command line: help, bad arguments, a small run and its results.json.
#include "experiments/viraal/viraal_study.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "base/source_paths.h"
#include "base/stats.h"
#include "base/test_command.h"
#include "experiments/viraal/rank_flip.h"
#include "experiments/viraal/results.h"
#include "experiments/viraal/study_cli.h"
#include "tests/same_tree.h"

namespace orbed::study {
namespace {

StudyOptions Shipped(int trials, const std::string& run_id) {
  StudyOptions o;
  o.scenario = viraal::LoadScenarioFile(SourceTreePath(viraal::kDefaultScenarioRelativePath));
  o.scenario.trials = trials;
  o.run_id = run_id;
  return o;
}

// The landmark misalignment against the truth (the registration's error at the landmarks; the
// user's gaze measurement cannot see the SLAM map's error, see GazeMeasurementSeesTheViewNotTheMap).
std::vector<double> Misalignment(const viraal::SessionResult& session) {
  std::vector<double> out;
  for (const auto& t : session.trials) out.push_back(t.errors.truth_misalignment_mm);
  return out;
}

TEST(ViraalStudy, EqualsThePinnedLiveRun) {
  const viraal::RunResults results = RunViraalStudy(Shipped(3, "pinned"));
  const YAML::Node pinned =
      YAML::LoadFile(SourceTreePath("tests/integration/testdata/viraal_pinned_results.json"));
  // The live run's timing is its own; everything else is the protocol's.
  orbed::testing::ExpectSameTree(pinned, YAML::Load(viraal::ResultsJson(results)), "results",
                                 {"started_utime", "duration_s"});
}

// One group of three is the session itself: its mean is the session mean the conductor scored,
// measured the same way (against the real landmarks annotated in its trials, in their viewer
// frames), and its truth errors are the session mean's.
TEST(ViraalStudy, AGroupOfAllTheTrialsIsTheSessionMean) {
  const StudyOptions o = Shipped(3, "pinned");
  const viraal::RunResults results = RunViraalStudy(o);
  for (const viraal::SessionResult& s : results.sessions) {
    const std::vector<GroupMean> groups = GroupMeans(o, s, 3);
    ASSERT_EQ(groups.size(), 1u);
    ASSERT_TRUE(s.mean.has_value());
    const viraal::ErrorMeasures& want = s.mean->errors;
    const viraal::ErrorMeasures& got = groups[0].errors;
    EXPECT_EQ(groups[0].first_trial, 0);
    EXPECT_EQ(groups[0].num_trials, 3);
    EXPECT_EQ(got.landmarks, "gaze_real");
    EXPECT_NEAR(got.misalignment_mm, want.misalignment_mm, 1e-9) << s.mode;
    EXPECT_NEAR(got.truth_misalignment_mm, want.truth_misalignment_mm, 1e-9) << s.mode;
    EXPECT_NEAR(got.translation_error_mm, want.translation_error_mm, 1e-9) << s.mode;
    EXPECT_NEAR(got.rotation_error_deg, want.rotation_error_deg, 1e-9) << s.mode;
    ASSERT_TRUE(got.viewer_axes_mm && want.viewer_axes_mm);
    EXPECT_NEAR((*got.viewer_axes_mm - *want.viewer_axes_mm).norm(), 0, 1e-9) << s.mode;
  }
  const std::vector<GroupMean> pairs = GroupMeans(o, results.sessions[0], 2);
  ASSERT_EQ(pairs.size(), 1u);  // the third trial left out
  EXPECT_EQ(pairs[0].num_trials, 2);
  EXPECT_THROW(GroupMeans(o, results.sessions[0], 0), std::invalid_argument);
}

TEST(ViraalStudy, SeedAndRunIdChooseTheTrials) {
  const viraal::RunResults a = RunViraalStudy(Shipped(2, "a"));
  const viraal::RunResults a_again = RunViraalStudy(Shipped(2, "a"));
  const viraal::RunResults b = RunViraalStudy(Shipped(2, "b"));
  EXPECT_EQ(viraal::ResultsJson(a), viraal::ResultsJson(a_again));
  EXPECT_NE(a.sessions[0].trials[0].errors.misalignment_mm, b.sessions[0].trials[0].errors.misalignment_mm);
}

// Writes a headset config that places the one display at `waypoint`, on a map without drift or
// tracking losses (jitter only): the display's viewpoint alone, apart from the map's error, which a
// session shares between its trials (slam_model.h) and which the display's frame carries.
std::string DisplayAt(const std::string& waypoint) {
  const std::string path = ::testing::TempDir() + "display_at_" + waypoint + ".yaml";
  std::ofstream(path) << "hmd:\n  displays:\n    - {capture_waypoint: " << waypoint << "}\n"
                      << "slam:\n  drift: {fraction_of_distance: 0, yaw_deg_per_m: 0}\n"
                      << "  tracking_loss: {rate_per_min: 0}\n";
  return path;
}

// The mechanism of the paper's display: a frame captured from the foot end of the table (another
// viewpoint than the alignment's, at the head end) shows the depth along the person's line of
// sight, and lowers the misalignment against the truth.
TEST(ViraalStudy, DisplayFromAnotherViewpointLowersTheMisalignment) {
  StudyOptions o = Shipped(60, "mechanism");
  o.headset_config_paths = {DisplayAt("foot_end")};
  const viraal::RunResults r = RunViraalStudy(o);
  ASSERT_EQ(r.sessions.size(), 2u);
  ASSERT_EQ(r.sessions[0].mode, "ar_reflective");
  const std::vector<double> with = Misalignment(r.sessions[0]), without = Misalignment(r.sessions[1]);
  const stats::MannWhitneyResult mw = stats::MannWhitneyU(with, without);
  ASSERT_TRUE(mw.valid);
  EXPECT_LT(mw.p_x_less, 0.01) << stats::Mean(with) << " vs " << stats::Mean(without) << " mm";
  EXPECT_LT(stats::Mean(with), 0.8 * stats::Mean(without));
}

// The negative control: a display captured where the person aligns shows the robot from their own
// viewpoint; it adds no second view of the depth along the line of sight, so it must not lower the
// misalignment significantly: the mechanism, not the mere presence of a display, makes the gain.
TEST(ViraalStudy, DisplayFromTheAlignmentViewpointDoesNotHelp) {
  StudyOptions o = Shipped(60, "mechanism");
  o.headset_config_paths = {DisplayAt("head_end")};
  const viraal::RunResults r = RunViraalStudy(o);
  const std::vector<double> with = Misalignment(r.sessions[0]), without = Misalignment(r.sessions[1]);
  const stats::MannWhitneyResult mw = stats::MannWhitneyU(with, without);
  ASSERT_TRUE(mw.valid);
  EXPECT_GT(mw.p_x_less, 0.05) << stats::Mean(with) << " vs " << stats::Mean(without) << " mm";
}

// The rows of one study, by hand: mode ar pools user A's trials t̄ = (3, 0, 0) and (0, 4, 0) mm and
// user B's (0, 0, 12) mm: per-axis means (1, 4/3, 4), norm √(1 + 16/9 + 16) = 13/3 mm; true
// translation errors 10, 20, 60 mm: mean 30. In mode ar_reflective one trial has no viewer frame:
// measured_s_mm is NaN.
TEST(RankFlip, RowsAreTheTable1FigureAndTheTruthsMeanOverThePooledTrials) {
  const auto trial = [](const Eigen::Vector3d& axes, double translation, double truth, bool viewer) {
    viraal::TrialResult t;
    t.errors.misalignment_axes_mm = axes;
    t.errors.translation_error_mm = translation;
    t.errors.truth_misalignment_mm = truth;
    if (viewer) t.errors.viewer_axes_mm = Eigen::Vector3d(0, 0, 3);
    return t;
  };
  const auto session = [](const std::string& mode, std::vector<viraal::TrialResult> trials) {
    viraal::SessionResult s;
    s.mode = mode;
    s.trials = std::move(trials);
    return s;
  };
  viraal::RunResults a, b;
  a.sessions = {session("ar_reflective", {trial({1, 1, 1}, 5, 1, true)}),
                session("ar", {trial({3, 0, 0}, 10, 1, true), trial({0, 4, 0}, 20, 2, true)})};
  b.sessions = {session("ar_reflective", {trial({1, 1, 1}, 7, 1, false)}),
                session("ar", {trial({0, 0, 12}, 60, 3, true)})};
  const std::vector<StudyModeRow> rows = StudyRows(7, 29, {a, b});
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1].mode, "ar");
  EXPECT_EQ(rows[1].study, 7);
  EXPECT_EQ(rows[1].first_user_seed, 29u);
  EXPECT_EQ(rows[1].users, 2);
  EXPECT_EQ(rows[1].trials, 3);
  EXPECT_NEAR(rows[1].measured_w_mm, 13.0 / 3, 1e-12);
  EXPECT_NEAR(rows[1].measured_s_mm, 3.0, 1e-12);
  EXPECT_NEAR(rows[1].true_translation_mm, 30.0, 1e-12);
  EXPECT_NEAR(rows[1].true_misalignment_mm, 2.0, 1e-12);
  EXPECT_NEAR(rows[0].measured_w_mm, std::sqrt(3.0), 1e-12);
  EXPECT_TRUE(std::isnan(rows[0].measured_s_mm));
  const std::string csv = RankFlipCsv(rows);
  EXPECT_EQ(
      csv.rfind("study,first_user_seed,mode,users,trials,measured_w_mm,measured_s_mm,true_translation_mm,"
                "true_misalignment_mm\n7,29,ar_reflective,2,2,",
                0),
      0u)
      << csv;
}

// Study m is `scripts/orbed study --seed S + U·m`: its users are the persons of seeds S + U·m, +1, ...
// with run ids study-s<S + U·m>-u<k>.
TEST(RankFlip, StudyMIsTheStudyWhoseFirstUserSeedIsSPlusUsersTimesM) {
  EXPECT_EQ(StudyUserSeed(5, 1), 5u);
  EXPECT_EQ(StudyUserSeed(5, 4), 8u);
  EXPECT_EQ(StudyRunId(5, 2), "study-s5-u2");
  RankFlipOptions options;
  options.study = Shipped(2, "ignored");
  options.studies = 2;
  options.users = 2;
  options.first_user_seed = 3;
  const std::vector<StudyModeRow> rows = RunRankFlipStudies(options);
  ASSERT_EQ(rows.size(), 4u);
  std::vector<viraal::RunResults> second;
  for (int k = 1; k <= 2; ++k) {
    StudyOptions o = Shipped(2, StudyRunId(5, k));
    o.user_seed = StudyUserSeed(5, k);
    second.push_back(RunViraalStudy(o));
  }
  EXPECT_EQ(second[1].sessions[0].trials[0].user_id, "emulated-seed-6");
  const std::vector<StudyModeRow> want = StudyRows(1, 5, second);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(rows[2 + i].first_user_seed, 5u);
    EXPECT_EQ(rows[2 + i].mode, want[i].mode);
    EXPECT_EQ(rows[2 + i].measured_w_mm, want[i].measured_w_mm);
    EXPECT_EQ(rows[2 + i].true_translation_mm, want[i].true_translation_mm);
  }
  EXPECT_NE(rows[0].measured_w_mm, rows[2].measured_w_mm);  // another study, other persons
  options.studies = 0;
  EXPECT_THROW(RunRankFlipStudies(options), std::invalid_argument);
}

TEST(UserStudyCli, StudiesWriteTheirRowsAndNeedACsv) {
  const std::string csv = ::testing::TempDir() + "rank_flip.csv";
  test::CommandRun r =
      test::RunCommand(RunUserStudy, "orbed-user-study",
                       {"--studies", "2", "--users", "1", "--trials", "1", "--csv", csv, "--quiet"});
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(csv);
  int lines = 0;
  for (std::string line; std::getline(in, line);) ++lines;
  EXPECT_EQ(lines, 1 + 2 * 2);
  EXPECT_EQ(test::RunCommand(RunUserStudy, "orbed-user-study", {"--studies", "2"}).code, 2);
  EXPECT_EQ(test::RunCommand(RunUserStudy, "orbed-user-study", {"--csv", csv}).code, 2);
  EXPECT_EQ(test::RunCommand(RunUserStudy, "orbed-user-study", {"--users", "2"}).code, 2);
}

TEST(UserStudyCli, HelpGoesToOutAndExitsZero) {
  const test::CommandRun r = test::RunCommand(RunUserStudy, "orbed-user-study", {"--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("--trials"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--run-id"), std::string::npos) << r.out;
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST(UserStudyCli, BadArgumentsExitTwo) {
  test::CommandRun r = test::RunCommand(RunUserStudy, "orbed-user-study", {"--no-such-flag"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--no-such-flag"), std::string::npos) << r.err;
  // --trials: a positive decimal integer that fits an int, nothing else (010 would be octal 8 and
  // 0x10 hex 16 for CLI11's own integer parser).
  // At most 1000: a headset session holds no more (lcmtypes/contract/alignment_trial.h).
  for (const char* bad : {"0", "-3", "abc", "12x", "1e3", "99999999999", "0x10", "+5", "", "1001"}) {
    r = test::RunCommand(RunUserStudy, "orbed-user-study", {"--trials", bad});
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_NE(r.err.find("--trials"), std::string::npos) << bad << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
  r = test::RunCommand(RunUserStudy, "orbed-user-study", {"--modes", "ar,nothing"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("nothing"), std::string::npos) << r.err;
}

TEST(UserStudyCli, SmallRunPrintsTheTableAndWritesResultsJson) {
  const std::string json = ::testing::TempDir() + "study_results.json";
  std::remove(json.c_str());
  const test::CommandRun r = test::RunCommand(
      RunUserStudy, "orbed-user-study", {"--trials", "02", "--run-id", "pinned", "--json", json, "--quiet"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_NE(r.out.find("paper: 16.5 +/- 11.0 mm"), std::string::npos) << r.out;
  const YAML::Node written = YAML::LoadFile(json);
  ASSERT_EQ(written["sessions"].size(), 2u);
  EXPECT_EQ(written["sessions"][0]["trials"].size(), 2u);  // "02" read as decimal 2
  // The first trials are the pinned run's first trials: same seeds, same protocol.
  const YAML::Node pinned =
      YAML::LoadFile(SourceTreePath("tests/integration/testdata/viraal_pinned_results.json"));
  orbed::testing::ExpectSameTree(pinned["sessions"][0]["trials"][1], written["sessions"][0]["trials"][1],
                                 "trial 1", {});
}

TEST(UserStudyCli, ManyTrialsPrintASummaryWithTheRankTest) {
  const test::CommandRun r =
      test::RunCommand(RunUserStudy, "orbed-user-study", {"--trials", "12", "--run-id", "summary"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("ar_reflective (12 trials)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Table 1 [mm]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Mann-Whitney U"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("24/24 trials"), std::string::npos) << r.err;  // progress
}

}  // namespace
}  // namespace orbed::study
