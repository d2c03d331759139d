#pragma once
/// @file
/// `orbed-user-study` (thin main in study_main.cc) as a library function, so tests run it in-process:
/// the ViRAAl experiment of `scripts/orbed run` without the bus (viraal_study.h), as many trials as
/// wanted, in seconds.
///
///   orbed-user-study [--trials N] [--modes LIST] [--seed N] [--user-seed N] [--run-id ID]
///                    [--scenario FILE] [--config FILE]... [--urdf FILE] [--scene FILE] [--json FILE]
///                    [--quiet]
///   orbed-user-study --studies M [--users U] [--user-seed S] [--trials N] --csv FILE [...]
///   orbed-user-study --landmark-validation [--repeats N] [--pointing-std-deg X] [--csv FILE]
///                    [--seed N] [--config FILE]...
///
/// Prints the run's table (experiments/viraal/results.h) for up to 10 trials per mode, else a summary per
/// mode (the trials' misalignment, translation and rotation errors, mean ± std, and the SE(3) mean of all the
/// mode's trials) beside the paper's Table 1, and the one-sided Mann–Whitney test that the first mode's trial
/// misalignment is smaller than the second's. Progress goes to `err` unless --quiet.
/// --json writes the results.json the conductor would write. Each mode's first line is the paper's
/// Table 1 statistic (viraal::Table1Row: the norms of the per-axis means and standard deviations).
/// --landmark-validation runs the paper's check of the measurement itself instead
/// (landmark_validation.h): the error per separation and on average beside the paper's 3.6 mm;
/// --csv writes landmark_validation.csv.
/// --studies runs M studies of U users (default 4) x N trials per mode (default 10: the paper's
/// size), user k of study m the person of seed S + U·m + k − 1 (rank_flip.h), and writes one row
/// per study and mode to --csv: the Table 1 figure as measured and the truth's, for the rank-flip
/// fraction (python/orbed/study/rank_flip.py).
///
/// Exit codes: 0 done (or --help, on `out`); 2 bad arguments (the message on `err` names the flag);
/// 1 the study failed (unreadable file, a configuration outside the limits; message on `err`).

#include <ostream>

namespace orbed::study {

int RunUserStudy(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::study
