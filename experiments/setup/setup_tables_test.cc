// The set-up study's tables from setup_results.json files (experiments/setup/setup_tables.h). Oracles: hand
// computations (means, medians of small samples; the Mann-Whitney U normal approximation for a
// fully separated 3 vs 4 sample: U = 0, sigma^2 = 3*4*8/12 = 8, z = (6 - 0.5)/sqrt(8) = 1.94454,
// p = erfc(z/sqrt 2) = 0.0518299), and the paper's own numbers carried through unchanged.
#include "experiments/setup/setup_tables.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/stats.h"
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
  EXPECT_EQ(joints.substr(0, joints.find('\n')),
            "user,mode,order,target,joint,twisting,target_deg,reached_deg,error_deg");
  EXPECT_NE(joints.find("\nu1,ar,1,1,1,1,10,11,1\n"), std::string::npos) << joints;
  EXPECT_NE(joints.find("\nu1,fixed,2,2,1,1,10,5,5\n"), std::string::npos) << joints;
  EXPECT_EQ(std::count(joints.begin(), joints.end(), '\n'), 1 + 7 * 7);
  const std::string times = SetupTimesCsv(runs);
  EXPECT_EQ(times.substr(0, times.find('\n')), "user,mode,order,target,execution_s,alignment_s");
  EXPECT_NE(times.find("\nu1,fixed,2,1,100,\n"), std::string::npos) << times;
  EXPECT_NE(times.find("\nu2,ar,2,1,75,120\n"), std::string::npos) << times;
}

TEST(SetupTables, TablesTwoThreeAndFourByHand) {
  const std::vector<SetupUserRun> runs = TwoUsers();
  JsonWriter writer;
  writer.BeginObject();
  WriteSetupTables(&writer, runs);
  writer.EndObject();
  const nlohmann::json t = nlohmann::json::parse(writer.str());
  // Table 2, ar: joint 1 errors {1, 2, 3} and 18 zeros.
  EXPECT_NEAR(t["table2"]["ar"]["mean"].get<double>(), 6.0 / 21.0, 1e-12);
  EXPECT_EQ(t["table2"]["ar"]["median"].get<double>(), 0.0);
  EXPECT_EQ(t["table2"]["ar"]["max"].get<double>(), 3.0);
  EXPECT_EQ(t["table2"]["ar"]["n"].get<int>(), 21);
  EXPECT_FALSE(t["table2"].contains("ar_reflective"));
  // Table 3, ar/fixed, joint 1: {1, 2, 3} against {4, 5, 6, 7}.
  EXPECT_NEAR(t["table3"]["ar/fixed"]["joint1"].get<double>(), 0.0518299272, 1e-9);
  EXPECT_TRUE(t["table3"]["ar/fixed"]["joint2"].is_null());  // all zero: no test
  EXPECT_FALSE(t["table3"].contains("ar_reflective/ar"));
  EXPECT_EQ(t["table3_test"].get<std::string>(), "mann_whitney_u");
  // Table 4: execution {60, 90, 75}, alignment {100, 140, 120}; fixed has no alignment.
  EXPECT_EQ(t["table4"]["ar"]["execution_s"]["median"].get<double>(), 75.0);
  EXPECT_NEAR(t["table4"]["ar"]["execution_s"]["std"].get<double>(), 15.0, 1e-12);
  EXPECT_EQ(t["table4"]["ar"]["alignment_s"]["mean"].get<double>(), 120.0);
  EXPECT_FALSE(t["table4"]["fixed"].contains("alignment_s"));
  EXPECT_EQ(t["table4"]["fixed"]["execution_s"]["max"].get<double>(), 140.0);

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

// Docking, contacts, stops and near misses counted by hand: a contact is never also a near miss,
// a clearance of exactly 5 cm is not one, an unknown clearance (null) is not one.
TEST(SetupTables, BeyondThePaperByHand) {
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
  JsonWriter writer;
  writer.BeginObject();
  WriteSetupTables(&writer, runs);
  writer.EndObject();
  const nlohmann::json b = nlohmann::json::parse(writer.str())["beyond"];
  EXPECT_EQ(b["docking"]["ar"]["tip_mm"]["median"].get<double>(), 6.0);
  EXPECT_EQ(b["docking"]["ar"]["axis_deg"]["mean"].get<double>(), 1.0);
  EXPECT_EQ(b["docking"]["fixed"]["tip_mm"]["mean"].get<double>(), 60.0);
  EXPECT_EQ(b["collisions"]["ar"]["setups"].get<int>(), 3);
  EXPECT_EQ(b["collisions"]["ar"]["contact"].get<int>(), 1);
  EXPECT_EQ(b["collisions"]["ar"]["collision_stops"].get<int>(), 2);
  EXPECT_EQ(b["collisions"]["ar"]["near_miss"].get<int>(), 1);  // 0.01; not the contact, not null
  EXPECT_EQ(b["collisions"]["ar"]["min_clearance_m"]["n"].get<int>(), 2);
  EXPECT_EQ(b["collisions"]["fixed"]["near_miss"].get<int>(), 1);  // 0.049, not 0.05
  EXPECT_EQ(b["collisions"]["fixed"]["collision_stops"].get<int>(), 1);
  EXPECT_EQ(b["near_miss_m"].get<double>(), kNearMissM);
  // u2 did no fixed set-up: the ar/fixed power analysis draws u1 only.
  ASSERT_TRUE(b["power"].contains("ar/fixed"));
  EXPECT_EQ(b["power"]["ar/fixed"]["users"].size(), kPowerUsers.size());
}

// The power analysis: modes that give each user the same errors are never told apart (power 0);
// modes whose errors never overlap always are (power 1 from the smallest study); and a pool of
// one separating user (S) and one indifferent user (I) has the power the binomial count of S among
// N draws gives: sum over k of C(N, k) / 2^N for the k whose pooled test rejects.
TEST(SetupTables, PowerByBootstrapOverUsers) {
  auto user = [](const std::string& name, double error_a, double error_b) {
    return User(name, {SetupJsonBeyond("ar_reflective", 1, error_a, 0, 0, "null", false, 0),
                       SetupJsonBeyond("ar", 1, error_b, 0, 0, "null", false, 0),
                       SetupJsonBeyond("ar_reflective", 2, error_a + 0.5, 0, 0, "null", false, 0),
                       SetupJsonBeyond("ar", 2, error_b + 0.5, 0, 0, "null", false, 0)});
  };
  const std::vector<int> sizes = {4, 8};
  for (const PowerPoint& q :
       SetupPower({user("a", 2, 2), user("b", 7, 7)}, "ar_reflective", "ar", sizes, 200, 0.05, 3))
    EXPECT_EQ(q.power, 0.0) << q.users;
  for (const PowerPoint& q :
       SetupPower({user("a", 1, 20), user("b", 2, 30)}, "ar_reflective", "ar", sizes, 200, 0.05, 3))
    EXPECT_EQ(q.power, 1.0) << q.users;
  EXPECT_TRUE(SetupPower({user("a", 1, 2)}, "ar_reflective", "fixed", sizes, 10, 0.05, 1).empty());

  const SetupUserRun separating = user("s", 1, 20), indifferent = user("i", 5, 5);
  const int n = 4;
  double expected = 0;
  for (int k = 0; k <= n; ++k) {
    std::vector<SetupUserRun> drawn;
    for (int u = 0; u < n; ++u) drawn.push_back(u < k ? separating : indifferent);
    const stats::MannWhitneyResult r =
        stats::MannWhitneyU(JointErrors(drawn, "ar_reflective", -1), JointErrors(drawn, "ar", -1));
    const double binomial =
        std::tgamma(n + 1) / (std::tgamma(k + 1) * std::tgamma(n - k + 1)) / std::pow(2, n);
    if (r.valid && r.p_two_sided < 0.05) expected += binomial;
  }
  EXPECT_GT(expected, 0.0);
  EXPECT_LT(expected, 1.0);
  const std::vector<PowerPoint> mixed =
      SetupPower({separating, indifferent}, "ar_reflective", "ar", {n}, 4000, 0.05, 7);
  ASSERT_EQ(mixed.size(), 1u);
  // 4000 resamples: the estimate's standard error is at most 0.008.
  EXPECT_NEAR(mixed[0].power, expected, 0.04);
  EXPECT_EQ(mixed[0].power,
            SetupPower({separating, indifferent}, "ar_reflective", "ar", {n}, 4000, 0.05, 7)[0].power);
}

// The registration's share: 1 − (mean error with the true registration) / (mean error measured).
TEST(SetupTables, RegistrationShareByHand) {
  auto with = [](const std::string& registration, double error) {
    std::string setup = SetupJsonBeyond("ar", 1, error, 0, 0, "null", false, 0);
    setup.insert(setup.size() - 1, R"(, "registration": ")" + registration + "\"");
    return setup;
  };
  const std::vector<SetupUserRun> measured = {User("m1", {with("measured", 4)}),
                                              User("m2", {with("measured", 6)})};
  const std::vector<SetupUserRun> truth = {User("t1", {with("truth", 1)}), User("t2", {with("truth", 2)})};
  EXPECT_EQ(truth[0].setups[0].registration, "truth");
  JsonWriter writer;
  writer.BeginObject();
  WriteSetupTables(&writer, measured, truth);
  writer.EndObject();
  const nlohmann::json share = nlohmann::json::parse(writer.str())["beyond"]["registration_share"];
  EXPECT_EQ(share["ar"]["measured_deg"]["mean"].get<double>(), 5.0);
  EXPECT_EQ(share["ar"]["truth_deg"]["mean"].get<double>(), 1.5);
  EXPECT_NEAR(share["ar"]["share"].get<double>(), 0.7, 1e-12);
  EXPECT_FALSE(share.contains("fixed"));
  EXPECT_THROW(User("bad", {[&] {
                      std::string setup = with("truth", 1);
                      setup.replace(setup.find("\"truth\""), 7, "\"guess\"");
                      return setup;
                    }()}),
               std::runtime_error);
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
