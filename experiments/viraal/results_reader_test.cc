// results.json read back (ReadResultsFile / ParseResultsJson): the pinned run's file reads and
// writes back to the same document (poses to their rotation matrix's round-off, the derived trial
// statistics and Table 1 rows to their sums'); a partial run's status survives; damaged documents are
// refused naming the key.
#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/json_fields.h"
#include "base/source_paths.h"
#include "experiments/viraal/results.h"

namespace orbed::viraal {
namespace {

std::string PinnedText() {
  std::ifstream in(SourceTreePath("tests/integration/testdata/viraal_pinned_results.json"));
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(ViraalResultsReader, ThePinnedRunReadsAndWritesBackTheSameDocument) {
  const std::string text = PinnedText();
  const RunResults r = ParseResultsJson(text, "pinned.json");
  EXPECT_TRUE(r.ok);
  EXPECT_EQ(r.run_id, "pinned");
  ASSERT_EQ(r.sessions.size(), 2u);
  ASSERT_EQ(r.sessions[0].trials.size(), 3u);
  ASSERT_TRUE(r.sessions[1].mean.has_value());
  // Every value, written again, is the file's: numbers to the last bit (shortest round trip),
  // poses to 1e-15 (they pass through a rotation matrix).
  const nlohmann::json original = nlohmann::json::parse(text);
  const nlohmann::json again = nlohmann::json::parse(ResultsJson(r));
  std::function<void(const nlohmann::json&, const nlohmann::json&, const std::string&)> same =
      [&](const nlohmann::json& a, const nlohmann::json& b, const std::string& where) {
        // A number keeps its value, not its spelling: the pinned file's "0" (written by the
        // hand-written writer before nlohmann's) reads as an integer, the writer's 0.0 as a float.
        if (!(a.is_number() && b.is_number())) {
          ASSERT_EQ(a.type(), b.type()) << where;
        }
        if (a.is_object()) {
          // The pinned file leaves out the run's times, which the writer always writes.
          const size_t times = where == "results" ? 2 : 0;
          ASSERT_EQ(a.size() + times, b.size()) << where;
          for (auto it = a.begin(); it != a.end(); ++it)
            same(it.value(), b.at(it.key()), where + "." + it.key());
        } else if (a.is_array()) {
          ASSERT_EQ(a.size(), b.size()) << where;
          for (size_t i = 0; i < a.size(); ++i) same(a[i], b[i], where + "[" + std::to_string(i) + "]");
        } else if (a.is_number() && (a.is_number_float() || b.is_number_float())) {
          // Derived numbers are recomputed: the trial statistics and the Table 1 rows to their
          // round-off (the file's Table 1 rows were computed with Python's statistics module).
          const bool pose = where.find("quaternion") != std::string::npos;
          const bool derived = where.find("trial_statistics") != std::string::npos ||
                               where.find("table1") != std::string::npos;
          EXPECT_NEAR(a.get<double>(), b.get<double>(),
                      pose      ? 1e-15
                      : derived ? 1e-12 * std::abs(a.get<double>())
                                : 0.0)
              << where;
        } else {
          EXPECT_EQ(a, b) << where;
        }
      };
  same(original, again, "results");
}

TEST(ViraalResultsReader, PartialRunsAndTheirOriginSurvive) {
  RunResults r = ParseResultsJson(PinnedText(), "pinned.json");
  r.ok = false;
  r.partial = true;
  r.resumed_from = "logs/x/results.json";
  r.sessions[1].mean.reset();
  r.sessions[1].trials.resize(1);
  const std::string text = ResultsJson(r);
  EXPECT_NE(text.find("\"status\": \"partial\""), std::string::npos);
  const RunResults back = ParseResultsJson(text, "partial.json");
  EXPECT_FALSE(back.ok);
  EXPECT_TRUE(back.partial);
  EXPECT_EQ(back.resumed_from, "logs/x/results.json");
  EXPECT_FALSE(back.sessions[1].mean.has_value());
  EXPECT_EQ(back.sessions[1].trials.size(), 1u);
  // Capture waypoints are written only when the scenario chose them, and read back.
  EXPECT_EQ(text.find("capture_waypoints"), std::string::npos);
  r.sessions[0].capture_waypoints = {"head_end"};
  const RunResults chosen = ParseResultsJson(ResultsJson(r), "chosen.json");
  EXPECT_EQ(chosen.sessions[0].capture_waypoints, (std::vector<std::string>{"head_end"}));
  EXPECT_TRUE(chosen.sessions[1].capture_waypoints.empty());
}

// A trial's tracking faults are written only when there were any, and read back.
TEST(ViraalResultsReader, TrackingFaultsOnlyWhereThereWereAny) {
  RunResults r = ParseResultsJson(PinnedText(), "pinned.json");
  EXPECT_FALSE(r.sessions[0].trials[1].tracking_faults.any());  // the pinned run met none
  r.sessions[0].trials[1].tracking_faults = {2, 2, 3.5, 1};
  const std::string text = ResultsJson(r);
  const nlohmann::json doc = nlohmann::json::parse(text);
  EXPECT_FALSE(doc["sessions"][0]["trials"][0].contains("tracking_faults"));
  EXPECT_EQ(doc["sessions"][0]["trials"][1]["tracking_faults"],
            nlohmann::json::parse(R"({"losses": 2, "relocalizations": 2, "wait_s": 3.5, "repeats": 1})"));
  const TrackingFaults back = ParseResultsJson(text, "faults.json").sessions[0].trials[1].tracking_faults;
  EXPECT_EQ(back.losses, 2);
  EXPECT_EQ(back.relocalizations, 2);
  EXPECT_EQ(back.wait_s, 3.5);
  EXPECT_EQ(back.repeats, 1);
}

std::string RefusalOf(const std::function<void(nlohmann::json&)>& damage) {
  nlohmann::json doc = nlohmann::json::parse(PinnedText());
  damage(doc);
  try {
    ParseResultsJson(doc.dump(), "r.json");
  } catch (const JsonReadError& e) {
    return e.what();
  }
  return "";
}

TEST(ViraalResultsReader, DamagedDocumentsAreRefusedNamingTheKey) {
  EXPECT_EQ(RefusalOf([](nlohmann::json&) {}), "");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) { d["status"] = "done"; }),
            "r.json: status: expected ok, failed or partial, got \"done\"");
  EXPECT_EQ(
      RefusalOf([](nlohmann::json& d) { d["sessions"][0]["trials"][1]["X_WV"]["quaternion_wxyz"][0] = 0.5; }),
      "r.json: sessions[0].trials[1].X_WV.quaternion_wxyz: expected a unit quaternion");
  EXPECT_EQ(
      RefusalOf([](nlohmann::json& d) { d["sessions"][1]["trials"][0]["q_deg"][3] = "x"; }).substr(0, 44),
      "r.json: sessions[1].trials[0].q_deg[3]: expe");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) { d["sessions"][0]["mean"].erase("num_used"); }),
            "r.json: sessions[0].mean.num_used: expected a value (missing)");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) {
              d["sessions"][0]["trials"][0]["misalignment_mm"] = -1;
            }).substr(0, 45),
            "r.json: sessions[0].trials[0].misalignment_mm");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) { d["sessions"][0]["display_mode"] = 7; }).substr(0, 35),
            "r.json: sessions[0].display_mode: e");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) { d["sessions"] = nlohmann::json::array({1}); }),
            "r.json: sessions[0]: expected an object, got 1");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) {
              d["sessions"][0]["trials"][0]["tracking_faults"] = {
                  {"losses", 1}, {"relocalizations", 1}, {"wait_s", 1e6}, {"repeats", 0}};
            }).substr(0, 54),
            "r.json: sessions[0].trials[0].tracking_faults.wait_s: ");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) {
              d["sessions"][0]["trials"][0]["annotated_real_W_m"][1] = {0.1, 0.2};
            }).substr(0, 54),
            "r.json: sessions[0].trials[0].annotated_real_W_m[1]: e");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) {
              d["sessions"][0]["trials"][0]["annotated_real_W_m"][0] = {0.1, 0.2, 1e5};
            }).substr(0, 57),
            "r.json: sessions[0].trials[0].annotated_real_W_m[0][2]: e");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) {
              d["sessions"][0]["capture_waypoints"] = {"head end"};
            }).substr(0, 55),
            "r.json: sessions[0].capture_waypoints[0]: expected a wa");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) {
              d["sessions"][0]["capture_waypoints"] = {"a", "b"};
            }).substr(0, 40),
            "r.json: sessions[0].capture_waypoints: e");
  EXPECT_EQ(RefusalOf([](nlohmann::json& d) { d["sessions"][1]["capture_waypoints"] = {"a"}; }).substr(0, 40),
            "r.json: sessions[1].capture_waypoints: e");
  EXPECT_THROW(ReadResultsFile("/nonexistent/results.json"), JsonReadError);
}

TEST(ViraalResultsReader, AFolderMeansItsResultsJson) {
  const RunResults r =
      ReadResultsFile(SourceTreePath("tests/integration/testdata/viraal_pinned_results.json"));
  EXPECT_EQ(r.run_id, "pinned");
  EXPECT_THROW(ReadResultsFile(SourceTreePath("tests/integration/testdata")),
               JsonReadError);  // no results.json
}

}  // namespace
}  // namespace orbed::viraal
