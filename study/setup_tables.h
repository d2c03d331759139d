#pragma once
/// @file
/// The set-up half of `scripts/orbed study`: one orbed-setup run per user (scripts/launch/setup.yaml,
/// each a different emulated person) writes setup_results.json (procs/setup/setup_conductor.h); this
/// turns them into the study's files and Tables 2-4:
///
///   setup_joints.csv  user,mode,order,target,joint,twisting,target_deg,reached_deg,error_deg
///                     (one row per set-up and joint; joint 1..7; twisting 1/0; error_deg =
///                     |reached − target|, reached = the sim's measured joints when the assistant
///                     said it was done)
///   setup_times.csv   user,mode,order,target,execution_s,alignment_s (alignment_s empty for fixed)
///   tables.json keys  "setup_users" (how many), "table2": {mode: {mean, median, min, max, std, n}} over
///   every joint's error;
///                     "table3": {"ar_reflective/ar" | "ar_reflective/fixed" | "ar/fixed":
///                     {"joint1" .. "joint7", "total"}}: two-sided p-values of the Mann-Whitney U
///                     test (unpaired: every set-up of every user pooled per mode; normal
///                     approximation with tie and continuity corrections, base/stats.h);
///                     "table3_test": "mann_whitney_u"; "table4": {mode: {"execution_s": {...},
///                     "alignment_s": {...} (headset modes)}}; the paper's in "paper".
///
/// Statistics: sample standard deviations (n − 1); medians of even counts average the middle two.
/// Threading: pure functions.

#include <optional>
#include <string>
#include <vector>

#include "base/json.h"

namespace orbed::study {

struct SetupRow {
  std::string mode;  ///< ar_reflective, ar or fixed
  int order{0};
  int target{0};
  std::vector<double> target_deg, reached_deg;
  std::vector<int> twisting;
  double execution_s{0};
  std::optional<double> alignment_s;
};

struct SetupUserRun {
  std::string user;
  std::vector<std::string> order;
  std::vector<SetupRow> setups;
};

/// Reads a setup_results.json (or the folder holding it) as outside input (base/json_fields.h:
/// at most 4 MB, 100 set-ups of at most 20 joints, angles in [−360, 360] deg, times in [0, 1e6) s,
/// modes from the study's three); throws std::runtime_error naming the file and key, or the status
/// when the run did not finish ("ok").
SetupUserRun ReadSetupResults(const std::string& path);

struct Stats5 {
  int n{0};
  double mean{0}, median{0}, min{0}, max{0}, std{0};
};
Stats5 Summarize(const std::vector<double>& values);

/// Every |reached − target| [deg] of `mode` over all users' set-ups; joint 0-based, or −1 for all.
std::vector<double> JointErrors(const std::vector<SetupUserRun>& runs, const std::string& mode, int joint);

std::string SetupJointsCsv(const std::vector<SetupUserRun>& runs);
std::string SetupTimesCsv(const std::vector<SetupUserRun>& runs);
/// Writes the "table2", "table3", "table3_test" and "table4" members into an open JSON object.
void WriteSetupTables(JsonWriter* json, const std::vector<SetupUserRun>& runs);
/// Writes the paper's "table2", "table3", "table4" (and "setup_source") into an open JSON object.
void WriteSetupPaper(JsonWriter* json);
/// Tables 2-4 beside the paper's, for the terminal.
std::string SetupSummary(const std::vector<SetupUserRun>& runs);

}  // namespace orbed::study
