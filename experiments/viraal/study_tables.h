#pragma once
/// @file
/// The ViRAAl half of `scripts/orbed study`: the paper's design (4 users x 10 trials per display mode,
/// Sec. III-B) is run over the bus, one `scripts/orbed run` per user (each a different emulated
/// person, orbed-hmd --user-seed); this turns their results.json files into the study's files:
///
///   alignment_trials.csv  user,mode,trial,t_x_mm,t_y_mm,t_z_mm,misalignment_mm,true_translation_mm,
///                         true_rotation_deg,duration_s,landmarks,true_misalignment_mm (one row per
///                         trial; t_* the trial's mean absolute landmark error per axis of W;
///                         misalignment_mm its norm; true_* the errors against the simulator's truth:
///                         translation at the robot centroid, rotation; duration_s the user's
///                         alignment time)
///   alignment_means.csv   the same columns, one row per user and mode for the session's SE(3) mean of
///                         all its trials (trial = "mean"; duration_s the sum of the trials' times)
///   alignment_groups.csv  user,mode,group,trials,misalignment_mm: the paper's registration statistic,
///                         the SE(3) mean of each group of kGroupTrials consecutive trials of a
///                         session (GroupMeanMisalignment_mm, viraal_study.h; the last incomplete
///                         group left out), scored with the truth's landmarks [mm]; group 1, 2, ...
///   tables.json           {"provenance": its record (when the folder has one), "paper": the paper's
///                         figures (Table 1, the landmark check and, with set-up runs, Tables 2-4)};
///                         the Python analysis (python/orbed/study) adds every computed table.
///
/// Users are named u1, u2, ... in the order of the runs given. Units: mm, deg, s as the column names
/// say. Threading: pure functions.

#include <string>
#include <vector>

#include "experiments/setup/setup_tables.h"
#include "experiments/viraal/landmark_validation.h"
#include "experiments/viraal/protocol.h"
#include "experiments/viraal/results.h"

namespace orbed::study {

struct UserRun {
  std::string user;  ///< "u1", "u2", ...
  viraal::RunResults results;
};

std::string AlignmentTrialsCsv(const std::vector<UserRun>& runs);
std::string AlignmentMeansCsv(const std::vector<UserRun>& runs);
/// Trials per group of alignment_groups.csv: the paper's N = 3 (Sec. II-A, IV-B).
inline constexpr int kGroupTrials = 3;
/// alignment_groups.csv; `scenario` gives the registration method (its configurations and landmarks
/// are each run's own, from its results.json).
std::string AlignmentGroupsCsv(const std::vector<UserRun>& runs, const viraal::ScenarioConfig& scenario);
/// tables.json as this writes it: the paper's figures of the halves given (see the file comment);
/// with a `provenance` record name (base/run_folder.h), a first key "provenance" naming it.
std::string TablesJson(bool viraal, bool setup, const std::string& provenance = "");

/// orbed-study-tables --out DIR [--seed S] [--setup SETUP_RUN]... [RUN...]: reads each RUN's
/// results.json (a file or its folder) and each SETUP_RUN's setup_results.json, runs the landmark
/// check (--seed), writes the files above, landmark_validation.csv and, with set-up runs, the set-up
/// files (setup_tables.h) into DIR, and says which. Exit 0, 2 on bad arguments, 1 when a run cannot be
/// read or did not finish (the message names it). The tables: `python3 -m orbed.study DIR`.
int RunStudyTables(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::study
