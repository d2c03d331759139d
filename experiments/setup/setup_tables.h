#pragma once
/// @file
/// The set-up half of `scripts/orbed study`: one orbed-setup run per user (scripts/launch/setup.yaml,
/// each a different emulated person) writes setup_results.json (experiments/setup/setup_conductor.h); this
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
///   setup_docking.csv user,mode,order,target,docking_tip_mm,docking_axis_deg,min_clearance_m,
///                     contact,collision_stops (beyond the paper: what the joint errors do at the
///                     trocar, and what the arm came close to while the assistant moved it; empty
///                     cells for runs that did not record them)
///   tables.json "beyond": {"docking": {mode: {"tip_mm": {...}, "axis_deg": {...}}},
///                     "collisions": {mode: {"setups", "contact", "collision_stops", "near_miss",
///                     "min_clearance_m": {...}}} with "near_miss_m" (a set-up is a near miss when
///                     its smallest clearance is below it and nothing touched), "power": {pair:
///                     {"users": [...], "power": [...], "users_for_80": n | null}} with "power_method".
///
/// Power analysis (SetupPower): how many users a study would need for Table 3's total test to
/// reject at alpha = 0.05 with probability 0.8, if people were like the emulated ones. A bootstrap
/// over users: for each study size N, `resamples` studies of N users drawn with replacement from
/// the runs (each drawn user brings all their set-ups), the pooled test of Table 3 on each; the
/// power is the fraction with p < alpha. Deterministic for a seed (base/random.h).
///
/// Statistics: sample standard deviations (n − 1); medians of even counts average the middle two.
/// Threading: pure functions.

#include <cstdint>
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
  /// "measured" or "truth" (orbed-setup --registration) in the headset modes; "" for fixed or
  /// older results.
  std::string registration;
  /// Beyond the paper (orbed-setup records them; absent in older results).
  std::optional<double> docking_tip_mm, docking_axis_deg, min_clearance_m;
  bool contact{false};
  int collision_stops{0};
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
std::string SetupDockingCsv(const std::vector<SetupUserRun>& runs);

/// A set-up is a near miss when nothing touched but the arm came closer than this [m] to itself or
/// the scene: the plan's own clearance for its targets (sim/trocar_plan.h min_clearance_m).
inline constexpr double kNearMissM = 0.05;

struct PowerPoint {
  int users{0};
  double power{0};  ///< fraction of the resampled studies with p < alpha
};
/// Study sizes the power analysis tries.
inline const std::vector<int> kPowerUsers = {4, 8, 12, 16, 24, 32, 48, 64};
/// The power of Table 3's total test between modes a and b (see the file comment) at each size of
/// `users`. Empty when a mode is missing or no run has both.
std::vector<PowerPoint> SetupPower(const std::vector<SetupUserRun>& runs, const std::string& a,
                                   const std::string& b, const std::vector<int>& users, int resamples,
                                   double alpha, uint64_t seed);
/// Writes the "table2", "table3", "table3_test", "table4" and "beyond" members into an open JSON
/// object (the power analysis: 500 resamples per size, seed 1). With `truth_runs` (the same users
/// with --registration truth) also beyond.registration_share: {mode: {"measured_deg": {...},
/// "truth_deg": {...}, "share": 1 − truth mean / measured mean}} over every joint's error: the
/// part of a headset mode's error that a perfect registration removes.
void WriteSetupTables(JsonWriter* json, const std::vector<SetupUserRun>& runs,
                      const std::vector<SetupUserRun>& truth_runs = {});
/// Writes the paper's "table2", "table3", "table4" (and "setup_source") into an open JSON object.
void WriteSetupPaper(JsonWriter* json);
/// Tables 2-4 beside the paper's, for the terminal.
std::string SetupSummary(const std::vector<SetupUserRun>& runs,
                         const std::vector<SetupUserRun>& truth_runs = {});

}  // namespace orbed::study
