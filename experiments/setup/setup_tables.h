#pragma once
/// @file
/// The set-up half of `scripts/orbed study`: one orbed-setup run per user (scripts/launch/setup.yaml,
/// each a different emulated person) writes setup_results.json (experiments/setup/setup_conductor.h); this
/// reads them and writes the study's set-up files:
///
///   setup_joints.csv  user,mode,order,target,joint,twisting,target_deg,reached_deg,error_deg,
///                     start_id,target_id,start_deg
///                     (one row per set-up and joint; joint 1..7; twisting 1/0; error_deg =
///                     |reached − target|, reached = the sim's measured joints when the assistant
///                     said it was done; start_id and target_id the design catalog's ids
///                     (experiments/setup/design.h), start_deg that joint's start angle; empty
///                     cells for runs without a design or older results)
///   setup_times.csv   user,mode,order,target,execution_s,alignment_s,start_id,target_id
///                     (alignment_s empty for fixed)
///   setup_docking.csv user,mode,order,target,docking_tip_mm,docking_axis_deg,min_clearance_m,
///                     contact,collision_stops (beyond the paper: what the joint errors do at the
///                     trocar, and what the arm came close to while the assistant moved it; empty
///                     cells for runs that did not record them)
///   setup_truth_joints.csv  setup_joints.csv's columns for the same users run with
///                     orbed-setup --registration truth (the registration's share of the error)
///
/// The statistics (Tables 2-4, the tests, the power analysis, the registration's share) are the
/// Python analysis's (python/orbed/study, docs/studies.md); the paper's figures, from
/// paper_setup.h, go into tables.json's "paper" here.
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
  /// The design's ids and the start [deg] (empty without a design or in older results).
  std::string start_id, target_id;
  std::vector<double> start_deg;
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

std::string SetupJointsCsv(const std::vector<SetupUserRun>& runs);
std::string SetupTimesCsv(const std::vector<SetupUserRun>& runs);
std::string SetupDockingCsv(const std::vector<SetupUserRun>& runs);

/// Writes the paper's "table2", "table3", "table4" (and "setup_source") into an open JSON object.
void WriteSetupPaper(JsonWriter* json);
}  // namespace orbed::study
