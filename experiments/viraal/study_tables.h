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
///                         rotation; duration_s the user's alignment time); then landmarks,
///                         true_misalignment_mm and v_x_mm,v_y_mm,v_z_mm: the same per-axis error in
///                         the trial's viewer frame S (z the line of sight from where the person
///                         aligned: experiments/viraal/metrics.h), empty for a trial nobody annotated
///   alignment_means.csv   the same columns, one row per user and mode for the session's SE(3) mean
///                         (trial = "mean"; duration_s the sum of the trials' times; v_* each landmark
///                         pair in the frame of the trial made at its configuration)
///   alignment_groups.csv  user,mode,group,trials,misalignment_mm,true_translation_mm,true_rotation_deg,
///                         landmarks,true_misalignment_mm   (the paper's SE(3) row, "means of N = 3
///                         trials": each user's trials of a mode taken 3 at a time in order, the last
///                         incomplete group left out, each group averaged on SE(3) by the
///                         registration server's core with the scenario's method; group 1, 2, ...;
///                         trials the range of trial numbers "1-3"; misalignment_mm measured as a
///                         session mean is (viraal_study.h GroupMeans); true_* against the truth)
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
/// alignment_groups.csv with groups of `group_size` and the SE(3) averaging `method`
/// (registration_t.METHOD_*), on the shipped robot model.
std::string AlignmentGroupsCsv(const std::vector<UserRun>& runs, int8_t method, int group_size = 3);
/// tables.json as this writes it: the paper's figures of the halves given (see the file comment);
/// with a `provenance` record name (base/run_folder.h), a first key "provenance" naming it.
std::string TablesJson(bool viraal, bool setup, const std::string& provenance = "");

/// orbed-study-tables --out DIR [--seed S] [--scenario FILE] [--setup SETUP_RUN]... [RUN...]: reads
/// each RUN's results.json (a file or its folder) and each SETUP_RUN's setup_results.json, runs the
/// landmark check (--seed), writes the files above (the groups averaged with --scenario's method),
/// landmark_validation.csv and, with set-up runs, the set-up files (setup_tables.h) into DIR, and says
/// which. Exit 0, 2 on bad arguments, 1 when a run cannot be read or did not finish (the message names
/// it). The tables: `python3 -m orbed.study DIR`.
int RunStudyTables(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::study
