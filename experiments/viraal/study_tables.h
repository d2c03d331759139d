#pragma once
/// @file
/// The ViRAAl half of `scripts/orbed study`: the paper's design (4 users x 10 trials per display mode,
/// Sec. III-B) is run over the bus, one `scripts/orbed run` per user (each a different emulated
/// person, orbed-hmd --user-seed); this turns their results.json files into the study's files:
///
///   alignment_trials.csv  user,mode,trial,t_x_mm,t_y_mm,t_z_mm,misalignment_mm,true_translation_mm,
///                         true_rotation_deg,duration_s   (one row per trial; t_* the trial's mean
///                         absolute landmark error per axis of W; misalignment_mm its norm; true_* the
///                         errors against the simulator's truth: translation at the robot centroid,
///                         rotation; duration_s the user's alignment time)
///   alignment_means.csv   the same columns, one row per user and mode for the session's SE(3) mean
///                         (trial = "mean"; duration_s the sum of the trials' times)
///   tables.json           {"table1": {mode: {"t_x": [mean, std], "t_y": [...], "t_z": [...],
///                                            "norm": [norm of means, norm of stds], "num_trials"},
///                                     "se3_mean": {mode: the same over the users' means}},
///                          "landmark_validation_mm": mean error of the optical-table check,
///                          "paper": the paper's figures in the same shape}
///
/// Users are named u1, u2, ... in the order of the runs given. Standard deviations are sample ones
/// (N − 1), as viraal::Table1Row computes them. Units: mm, deg, s as the column names say.
/// Threading: pure functions.

#include <string>
#include <vector>

#include "experiments/setup/setup_tables.h"
#include "experiments/viraal/landmark_validation.h"
#include "experiments/viraal/results.h"

namespace orbed::study {

struct UserRun {
  std::string user;  ///< "u1", "u2", ...
  viraal::RunResults results;
};

/// Every trial of every user, pooled per mode (in the runs' order of modes, first seen first).
std::vector<std::string> StudyModes(const std::vector<UserRun>& runs);
/// The Table 1 row of `mode` over all users' trials, or over the users' SE(3) means.
viraal::Table1Row ModeTrialsRow(const std::vector<UserRun>& runs, const std::string& mode);
viraal::Table1Row ModeMeansRow(const std::vector<UserRun>& runs, const std::string& mode);

std::string AlignmentTrialsCsv(const std::vector<UserRun>& runs);
std::string AlignmentMeansCsv(const std::vector<UserRun>& runs);
/// With set-up runs, tables.json also has Tables 2-4 (setup_tables.h) and the paper's; with a
/// `provenance` record name (base/run_folder.h), a first key "provenance" naming it.
std::string TablesJson(const std::vector<UserRun>& runs, const LandmarkValidation& validation,
                       const std::vector<SetupUserRun>& setup_runs = {},
                       const std::vector<SetupUserRun>& setup_truth_runs = {},
                       const std::string& provenance = "");
/// Table 1 as the study measured it, beside the paper's, for the terminal.
std::string StudySummary(const std::vector<UserRun>& runs, const LandmarkValidation& validation);

/// orbed-study-tables --out DIR [--seed S] [--setup SETUP_RUN]... [RUN...]: reads each RUN's
/// results.json (a file or its folder) and each SETUP_RUN's setup_results.json, runs the landmark
/// check (--seed), writes the three files above, landmark_validation.csv and, with set-up runs,
/// setup_joints.csv and setup_times.csv into DIR, prints StudySummary and SetupSummary. Exit 0, 2 on bad
/// arguments, 1 when a run cannot be read or did not finish (the message names it).
int RunStudyTables(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::study
