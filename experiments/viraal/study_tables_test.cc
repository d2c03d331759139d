// The study's files from its runs (study_tables.h), against independent figures:
//   - the CSVs have STUDY's columns, a row per trial (per user and mode for the means, per group of
//     three trials for the groups), values from the files; a group of all three pinned trials is the
//     session's mean the conductor scored with the truth's landmarks;
//   - tables.json has the documented shape, the paper's rows consistent with their norms;
//   - the command writes the files, refuses a run that did not finish.
// Table 1 itself (from these CSVs) is python/tests/test_tables.py's.
#include "experiments/viraal/study_tables.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <orbed/registration_t.hpp>

#include "base/source_paths.h"
#include "base/test_command.h"

namespace orbed::study {
namespace {

const char* kPinned = "tests/integration/testdata/viraal_pinned_results.json";

nlohmann::json PinnedJson() {
  std::ifstream in(SourceTreePath(kPinned));
  return nlohmann::json::parse(in);
}

std::vector<UserRun> Users(int n) {
  std::vector<UserRun> runs;
  for (int i = 0; i < n; ++i)
    runs.push_back({"u" + std::to_string(i + 1), viraal::ReadResultsFile(SourceTreePath(kPinned))});
  return runs;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(StudyTables, CsvsHaveTheStudyColumnsAndTheFilesValues) {
  const nlohmann::json pinned = PinnedJson();
  const std::vector<UserRun> runs = Users(2);
  const std::string header =
      "user,mode,trial,t_x_mm,t_y_mm,t_z_mm,misalignment_mm,true_translation_mm,true_rotation_deg,duration_s,"
      "landmarks,true_misalignment_mm,v_x_mm,v_y_mm,v_z_mm";
  const std::vector<std::string> trials = Lines(AlignmentTrialsCsv(runs));
  ASSERT_EQ(trials.size(), 1u + 2 * 2 * 3);
  EXPECT_EQ(trials[0], header);
  // u2's second ar trial: row 1 + 6 (u1) + 3 (u2's ar_reflective) + 1.
  char user[8], mode[32];
  int trial = 0;
  char landmarks[8];
  double t[3], mis, translation, rotation, duration, true_mis, v[3];
  ASSERT_EQ(
      std::sscanf(trials[11].c_str(), "%7[^,],%31[^,],%d,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%7[^,],%lf,%lf,%lf,%lf",
                  user, mode, &trial, &t[0], &t[1], &t[2], &mis, &translation, &rotation, &duration,
                  landmarks, &true_mis, &v[0], &v[1], &v[2]),
      15)
      << trials[11];
  const nlohmann::json& expected = pinned["sessions"][1]["trials"][1];
  EXPECT_STREQ(user, "u2");
  EXPECT_STREQ(mode, "ar");
  EXPECT_EQ(trial, 2);
  for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(t[k], expected["misalignment_axes_mm"][k].get<double>());
  EXPECT_NEAR(mis, expected["misalignment_mm"].get<double>(), 1e-9);  // the norm of the axes
  EXPECT_DOUBLE_EQ(translation, expected["translation_error_mm"].get<double>());
  EXPECT_DOUBLE_EQ(rotation, expected["rotation_error_deg"].get<double>());
  EXPECT_DOUBLE_EQ(duration, expected["user_duration_s"].get<double>());
  EXPECT_STREQ(landmarks, "gaze");
  EXPECT_DOUBLE_EQ(true_mis, expected["truth_misalignment_mm"].get<double>());
  for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(v[k], expected["viewer_axes_mm"][k].get<double>());

  const std::vector<std::string> means = Lines(AlignmentMeansCsv(runs));
  ASSERT_EQ(means.size(), 1u + 2 * 2);
  EXPECT_EQ(means[0], header);
  EXPECT_EQ(means[1].rfind("u1,ar_reflective,mean,", 0), 0u) << means[1];
  // A trial nobody annotated has no viewer frame: its v_* fields are empty.
  std::vector<UserRun> unannotated = Users(1);
  unannotated[0].results.sessions[0].trials[0].errors.viewer_axes_mm.reset();
  const std::string row = Lines(AlignmentTrialsCsv(unannotated))[1];
  EXPECT_EQ(row.substr(row.size() - 3), ",,,") << row;
}

// The SE(3) row's groups: the pinned run's three trials per mode are one group of N = 3, so each
// group's figures are the session mean's that the run measured (its "mean", scored by the
// registration server in the run); with groups of 2 the third trial is left out.
TEST(StudyTables, GroupsOfThreeOfThePinnedRunAreItsSessionMeans) {
  const nlohmann::json pinned = PinnedJson();
  const std::vector<std::string> rows =
      Lines(AlignmentGroupsCsv(Users(2), orbed::registration_t::METHOD_KARCHER));
  ASSERT_EQ(rows.size(), 1u + 2 * 2);
  EXPECT_EQ(rows[0],
            "user,mode,group,trials,misalignment_mm,true_translation_mm,true_rotation_deg,landmarks,"
            "true_misalignment_mm");
  char user[8], mode[32], trials[8], landmarks[16];
  int group = 0;
  double mis, translation, rotation, true_mis;
  ASSERT_EQ(std::sscanf(rows[4].c_str(), "%7[^,],%31[^,],%d,%7[^,],%lf,%lf,%lf,%15[^,],%lf", user, mode,
                        &group, trials, &mis, &translation, &rotation, landmarks, &true_mis),
            9)
      << rows[4];
  EXPECT_STREQ(user, "u2");
  EXPECT_STREQ(mode, "ar");
  EXPECT_EQ(group, 1);
  EXPECT_STREQ(trials, "1-3");
  const nlohmann::json& mean = pinned["sessions"][1]["mean"];
  EXPECT_NEAR(mis, mean["misalignment_mm"].get<double>(), 1e-9);
  EXPECT_NEAR(translation, mean["translation_error_mm"].get<double>(), 1e-9);
  EXPECT_NEAR(rotation, mean["rotation_error_deg"].get<double>(), 1e-9);
  EXPECT_STREQ(landmarks, "gaze_real");
  EXPECT_NEAR(true_mis, mean["truth_misalignment_mm"].get<double>(), 1e-9);
  const std::vector<std::string> pairs =
      Lines(AlignmentGroupsCsv(Users(1), orbed::registration_t::METHOD_KARCHER, 2));
  ASSERT_EQ(pairs.size(), 1u + 2);
  EXPECT_EQ(pairs[1].rfind("u1,ar_reflective,1,1-2,", 0), 0u) << pairs[1];
}

TEST(StudyTables, TablesJsonHasTheDocumentedShape) {
  const nlohmann::json tables = nlohmann::json::parse(TablesJson(true, false, "provenance.json"));
  EXPECT_EQ(tables["provenance"], "provenance.json");
  for (const char* mode : {"ar_reflective", "ar"}) {
    // The paper's rows: their norms are the norms of their per-axis figures (to the print's rounding).
    const nlohmann::json& paper = tables["paper"]["table1"][mode];
    double mean2 = 0, std2 = 0;
    for (const char* key : {"t_x", "t_y", "t_z"}) {
      mean2 += std::pow(paper[key][0].get<double>(), 2);
      std2 += std::pow(paper[key][1].get<double>(), 2);
    }
    EXPECT_NEAR(std::sqrt(mean2), paper["norm"][0].get<double>(), 0.05) << mode;
    EXPECT_NEAR(std::sqrt(std2), paper["norm"][1].get<double>(), 0.05) << mode;
  }
  EXPECT_EQ(tables["paper"]["table1"]["ar"]["norm"], nlohmann::json({30.2, 23.9}));
  EXPECT_EQ(tables["paper"]["table1"]["se3_mean"]["ar_reflective"]["norm"], nlohmann::json({11.3, 1.01}));
  EXPECT_EQ(tables["paper"]["landmark_validation_mm"], 3.6);
  EXPECT_FALSE(tables["paper"].contains("table2"));  // no set-up runs
  const nlohmann::json setup = nlohmann::json::parse(TablesJson(false, true));
  EXPECT_FALSE(setup.contains("provenance"));
  EXPECT_FALSE(setup["paper"].contains("table1"));
  EXPECT_EQ(setup["paper"]["table2"]["fixed"]["median"].get<double>(), 50.6);
}

TEST(StudyTables, TheCommandWritesTheFilesAndRefusesAnUnfinishedRun) {
  const std::string dir = ::testing::TempDir() + "study_tables_out";
  std::filesystem::remove_all(dir);
  const std::string pinned = SourceTreePath(kPinned);
  nlohmann::json other_person = PinnedJson();
  for (auto& session : other_person["sessions"]) {
    for (auto& trial : session["trials"]) trial["user_id"] = "emulated-seed-2";
  }
  const std::string other_path = ::testing::TempDir() + "other_person_results.json";
  std::ofstream(other_path) << other_person.dump();
  // The same run twice is one person twice: refused.
  test::CommandRun r = test::RunCommand(RunStudyTables, "orbed-study-tables", {"--out", dir, pinned, pinned});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("user u2 is the same person as u1 ('emulated-seed-1')"), std::string::npos) << r.err;
  r = test::RunCommand(RunStudyTables, "orbed-study-tables", {"--out", dir, pinned, other_path});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("wrote alignment_trials.csv alignment_means.csv alignment_groups.csv"),
            std::string::npos)
      << r.out;
  for (const char* name : {"alignment_trials.csv", "alignment_means.csv", "alignment_groups.csv",
                           "landmark_validation.csv", "tables.json"}) {
    EXPECT_TRUE(std::filesystem::exists(dir + "/" + name)) << name;
  }

  nlohmann::json partial = PinnedJson();
  partial["status"] = "partial";
  const std::string partial_path = ::testing::TempDir() + "partial_results.json";
  std::ofstream(partial_path) << partial.dump();
  r = test::RunCommand(RunStudyTables, "orbed-study-tables", {"--out", dir, pinned, partial_path});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("did not finish"), std::string::npos) << r.err;
  nlohmann::json odd_mode = other_person;
  odd_mode["sessions"][0]["mode"] = "se3_mean";
  const std::string odd_path = ::testing::TempDir() + "odd_mode_results.json";
  std::ofstream(odd_path) << odd_mode.dump();
  r = test::RunCommand(RunStudyTables, "orbed-study-tables", {"--out", dir, pinned, odd_path});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("mode 'se3_mean' is not one of the study's"), std::string::npos) << r.err;
  EXPECT_EQ(test::RunCommand(RunStudyTables, "orbed-study-tables", {pinned}).code, 2);  // no --out
}

// --paper-only: tables.json with both halves' paper figures and nothing else; runs beside it are a
// usage error.
TEST(StudyTables, PaperOnlyWritesThePapersFigures) {
  const std::string dir = ::testing::TempDir() + "/study_tables_paper_only";
  test::CommandRun r = test::RunCommand(RunStudyTables, "orbed-study-tables", {"--out", dir, "--paper-only"});
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream file(dir + "/tables.json");
  const nlohmann::json tables = nlohmann::json::parse(file);
  EXPECT_DOUBLE_EQ(tables["paper"]["table1"]["ar"]["norm"][0].get<double>(), 30.2);
  EXPECT_DOUBLE_EQ(tables["paper"]["table2"]["fixed"]["mean"].get<double>(), 71.4);
  EXPECT_FALSE(tables.contains("table1"));
  r = test::RunCommand(RunStudyTables, "orbed-study-tables", {"--out", dir, "--paper-only", "run"});
  EXPECT_EQ(r.code, 2);
}

}  // namespace
}  // namespace orbed::study
