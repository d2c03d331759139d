// The set-up study's files from setup_results.json files (experiments/setup/setup_tables.h). Oracles:
// the files' values in the CSV rows, and the paper's own numbers carried through unchanged. The tables
// computed from these CSVs are python/tests' (Tables 2-4, the tests, the power analysis, the
// registration's share).
#include "experiments/setup/setup_tables.h"

#include <algorithm>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "experiments/setup/paper_setup.h"

namespace orbed::study {
namespace {

// One set-up: joint 1 reached at `error1` from a target of 10 deg, the other joints exactly.
std::string SetupJson(const std::string& mode, int order, int target, double error1, double execution_s,
                      const std::string& alignment_s) {
  return R"({"task_id": "x", "mode": ")" + mode + R"(", "order": )" + std::to_string(order) +
         R"(, "target": )" + std::to_string(target) +
         R"(, "target_deg": [10, 20, 0, -60, 0, 40, 0], "reached_deg": [)" + std::to_string(10 + error1) +
         R"(, 20, 0, -60, 0, 40, 0], "assistant_reached_deg": [0, 0, 0, 0, 0, 0, 0],
          "twisting": [1, 0, 1, 0, 1, 0, 1], "ranges": [1, 1, 1, 1, 1, 1, 1], "execution_s": )" +
         std::to_string(execution_s) + R"(, "alignment_s": )" + alignment_s + R"(, "person_scale": 1,
          "alignment": null})";
}

std::string Write(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

std::vector<SetupUserRun> TwoUsers() {
  const std::string u1 =
      R"({"user": "u1", "run_id": "r", "status": "ok", "error": "", "order": ["ar", "fixed"],
    "setups": [)" +
      SetupJson("ar", 1, 1, 1, 60, "100") + "," + SetupJson("ar", 1, 2, 2, 90, "140") + "," +
      SetupJson("fixed", 2, 1, 4, 100, "null") + "," + SetupJson("fixed", 2, 2, -5, 120, "null") + "]}";
  const std::string u2 =
      R"({"user": "u2", "run_id": "r", "status": "ok", "error": "", "order": ["fixed", "ar"],
    "setups": [)" +
      SetupJson("fixed", 1, 1, 6, 80, "null") + "," + SetupJson("fixed", 1, 2, 7, 140, "null") + "," +
      SetupJson("ar", 2, 1, -3, 75, "120") + "]}";
  return {ReadSetupResults(Write("u1.json", u1)), ReadSetupResults(Write("u2.json", u2))};
}

TEST(SetupTables, ReadsTheRunsAndWritesTheCsvFiles) {
  const std::vector<SetupUserRun> runs = TwoUsers();
  ASSERT_EQ(runs[0].setups.size(), 4u);
  EXPECT_EQ(runs[1].user, "u2");
  EXPECT_FALSE(runs[0].setups[2].alignment_s.has_value());
  EXPECT_EQ(*runs[0].setups[1].alignment_s, 140);
  const std::string joints = SetupJointsCsv(runs);
  EXPECT_EQ(
      joints.substr(0, joints.find('\n')),
      "user,mode,order,target,joint,twisting,target_deg,reached_deg,error_deg,start_id,target_id,start_deg");
  // Results without a design: its three cells empty.
  EXPECT_NE(joints.find("\nu1,ar,1,1,1,1,10,11,1,,,\n"), std::string::npos) << joints;
  EXPECT_NE(joints.find("\nu1,fixed,2,2,1,1,10,5,5,,,\n"), std::string::npos) << joints;
  EXPECT_EQ(std::count(joints.begin(), joints.end(), '\n'), 1 + 7 * 7);
  const std::string times = SetupTimesCsv(runs);
  EXPECT_EQ(times.substr(0, times.find('\n')),
            "user,mode,order,target,execution_s,alignment_s,start_id,target_id");
  EXPECT_NE(times.find("\nu1,fixed,2,1,100,,,\n"), std::string::npos) << times;
  EXPECT_NE(times.find("\nu2,ar,2,1,75,120,,\n"), std::string::npos) << times;
}

// A design's run: the ids in both files, each joint's start angle in setup_joints.csv.
TEST(SetupTables, TheDesignsIdsAndStartsAreAppended) {
  std::string setup = SetupJson("ar", 1, 1, 1, 60, "100");
  setup.insert(
      1,
      R"("start_id": "aside", "target_id": "medium/umbilicus/2", "start_deg": [-90, 20, 0, -60, 0, 40, 0], )");
  const std::string u1 =
      R"({"user": "u1", "run_id": "r", "status": "ok", "error": "", "order": ["ar"], "setups": [)" + setup +
      "]}";
  const std::vector<SetupUserRun> runs = {ReadSetupResults(Write("design.json", u1))};
  EXPECT_EQ(runs[0].setups[0].target_id, "medium/umbilicus/2");
  const std::string joints = SetupJointsCsv(runs);
  EXPECT_NE(joints.find("\nu1,ar,1,1,1,1,10,11,1,aside,medium/umbilicus/2,-90\n"), std::string::npos)
      << joints;
  EXPECT_NE(joints.find("\nu1,ar,1,1,4,0,-60,-60,0,aside,medium/umbilicus/2,-60\n"), std::string::npos)
      << joints;
  const std::string times = SetupTimesCsv(runs);
  EXPECT_NE(times.find("\nu1,ar,1,1,60,100,aside,medium/umbilicus/2\n"), std::string::npos) << times;
}

TEST(SetupTables, ThePapersTablesUnchanged) {
  JsonWriter paper;
  paper.BeginObject();
  WriteSetupPaper(&paper);
  paper.EndObject();
  const nlohmann::json p = nlohmann::json::parse(paper.str());
  EXPECT_EQ(p["table2"]["fixed"]["median"].get<double>(), 50.6);
  EXPECT_EQ(p["table3"]["ar/fixed"]["total"].get<double>(), 2.0e-18);
  EXPECT_EQ(p["table4"]["ar"]["execution_s"]["mean"].get<double>(), 91.0);              // 1:31
  EXPECT_EQ(p["table4"]["ar_reflective"]["alignment_s"]["mean"].get<double>(), 272.0);  // 4:32
}

// One set-up with every joint `error` deg off, and what orbed-setup records beyond the paper.
std::string SetupJsonBeyond(const std::string& mode, int target, double error, double tip_mm, double axis_deg,
                            const std::string& clearance_m, bool contact, int stops) {
  std::string reached;
  const double target_deg[7] = {10, 20, 0, -60, 0, 40, 0};
  for (int j = 0; j < 7; ++j) reached += (j ? ", " : "") + std::to_string(target_deg[j] + error);
  return R"({"task_id": "x", "mode": ")" + mode + R"(", "order": 1, "target": )" + std::to_string(target) +
         R"(, "target_deg": [10, 20, 0, -60, 0, 40, 0], "reached_deg": [)" + reached +
         R"(], "twisting": [1, 0, 1, 0, 1, 0, 1], "execution_s": 60, "alignment_s": null, "docking_tip_mm": )" +
         std::to_string(tip_mm) + R"(, "docking_axis_deg": )" + std::to_string(axis_deg) +
         R"(, "min_clearance_m": )" + clearance_m + R"(, "contact": )" + (contact ? "true" : "false") +
         R"(, "collision_stops": )" + std::to_string(stops) + "}";
}

SetupUserRun User(const std::string& name, const std::vector<std::string>& setups) {
  std::string text = R"({"user": ")" + name + R"(", "status": "ok", "error": "", "order": [], "setups": [)";
  for (size_t i = 0; i < setups.size(); ++i) text += (i ? "," : "") + setups[i];
  return ReadSetupResults(Write(name + ".json", text + "]}"));
}

// What orbed-setup records beyond the paper, in setup_docking.csv; an unknown clearance an empty cell.
TEST(SetupTables, DockingCsvHasTheRecordedValues) {
  const std::vector<SetupUserRun> runs = {
      User("u1", {SetupJsonBeyond("ar", 1, 1, 4, 0.5, "0.01", false, 0),
                  SetupJsonBeyond("ar", 2, 1, 10, 1.5, "-0.002", true, 2),
                  SetupJsonBeyond("fixed", 1, 3, 80, 12, "0.05", false, 1)}),
      User("u2", {SetupJsonBeyond("ar", 1, 1, 6, 1.0, "null", false, 0),
                  SetupJsonBeyond("fixed", 1, 3, 40, 6, "0.049", false, 0)})};
  const std::string csv = SetupDockingCsv(runs);
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "user,mode,order,target,docking_tip_mm,docking_axis_deg,min_clearance_m,contact,collision_stops");
  EXPECT_NE(csv.find("\nu1,ar,1,2,10,1.5,-0.002,1,2\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\nu2,ar,1,1,6,1,,0,0\n"), std::string::npos) << csv;
}

// A --registration truth run reads as one; a registration other than measured, truth or null is refused.
TEST(SetupTables, ReadsTheRegistration) {
  auto with = [](const std::string& registration, double error) {
    std::string setup = SetupJsonBeyond("ar", 1, error, 0, 0, "null", false, 0);
    setup.insert(setup.size() - 1, R"(, "registration": ")" + registration + "\"");
    return setup;
  };
  const std::vector<SetupUserRun> truth = {User("t1", {with("truth", 1)})};
  EXPECT_EQ(truth[0].setups[0].registration, "truth");
  EXPECT_NE(SetupJointsCsv(truth).find("\nt1,ar,1,1,1,1,10,11,1,,,\n"), std::string::npos)
      << SetupJointsCsv(truth);
  EXPECT_THROW(User("bad", {with("guess", 1)}), std::runtime_error);
}

TEST(SetupTables, RefusesUnfinishedOrMalformedRuns) {
  auto error = [](const std::string& text) {
    try {
      ReadSetupResults(Write("bad.json", text));
      return std::string("(accepted)");
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
  };
  EXPECT_NE(
      error(R"({"user": "u1", "status": "failed", "error": "no SETUP_RESULT", "order": [], "setups": []})")
          .find("no SETUP_RESULT"),
      std::string::npos);
  EXPECT_NE(error(R"({"user": "u1", "status": "ok", "error": "", "order": [], "setups": [)" +
                  SetupJson("holo", 1, 1, 1, 1, "1") + "]}")
                .find("holo"),
            std::string::npos);
  std::string short_target = SetupJson("ar", 1, 1, 1, 1, "1");
  short_target.replace(short_target.find("[10, 20, 0, -60, 0, 40, 0]"), 26, "[10, 20]");
  EXPECT_NE(
      error(R"({"user": "u1", "status": "ok", "error": "", "order": [], "setups": [)" + short_target + "]}"),
      "(accepted)");
  EXPECT_NE(error("{not json"), "(accepted)");
}

}  // namespace
}  // namespace orbed::study
