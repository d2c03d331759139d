#pragma once
/// @file
/// `orbed-setup-study` (thin main in setup_study_main.cc) as a library function: the robot set-up
/// half of `scripts/orbed study` without the bus (setup_study.h), many users and many studies on
/// threads, and the study's CSVs.
///
///   orbed-setup-study [--users U] [--studies M] [--seed S] [--run-id ID] [--targets K] [--trials N]
///                     [--design FILE | --plan FILE [--start-deg Q]]
///                     [--threads T] [--out DIR] [--json-dir DIR] [--registration measured|truth]
///                     [--registration-offset-mm X] [--registration-tilt-deg Y]
///                     [--registration-direction X,Y,Z | random] [--registration-axis X,Y,Z]
///                     [--assistant-config FILE] [--allow-failures] [--quiet]
///
/// Users and seeds, as `scripts/orbed study` numbers them: study m (0-based) has users u1 .. uU,
/// user k with seed S + m·U + k − 1 and run id "<ID>-setup-u<k>" for m = 0 (so study 0 is the bus
/// study `scripts/orbed study --seed S --setup-users U --users 0`, number for number) and
/// "<ID>-m<m>-setup-u<k>" for m ≥ 1; ID defaults to "study-s<S>". Each user's modes come in the
/// order drawn from their seed, and their patient and K (start, target) pairs from the design
/// (--design, default experiments/setup/design.json; the patient's scene for the sim, headset,
/// monitor and the conductor's retract), as the bus study launches them; --plan FILE (and
/// --start-deg) gives every user the plan's first K targets from one start instead (orbed-setup
/// --plan).
///
/// Writes into --out (default .): setup_joints.csv, setup_times.csv, setup_docking.csv
/// (experiments/setup/setup_tables.h's writers) over every user; with M > 1 each line starts with
/// a `study` column (1 .. M). --json-dir writes each user's setup_results.json as the bus run
/// would (<dir>/setup-u<k>/ for one study, <dir>/m<m>/setup-u<k>/ for several).
///
/// Registration: --registration truth gives the headset modes the true registration instead of
/// the N alignments (orbed-setup --registration truth); --registration-offset-mm X and
/// --registration-tilt-deg Y move every registration the assistant receives by X mm along the
/// direction and turn it by Y deg about the axis (setup_study.h's RegistrationInjection; defaults
/// +x of W and +y of W; `--registration-direction random` draws both per set-up from the seed).
///
/// Threads: users run independently (one RunSetupUser each), T at a time (default 2); the files
/// are the same for every T. Progress on `err` unless --quiet; --version as every orbed program.
/// Exit codes: 0 done (or --help, --version); 2 bad arguments (one line on `err` naming the flag);
/// 1 a user's run failed (unless --allow-failures: the user is left out of the CSVs and listed in
/// failed_users.csv: study,user,user_seed,run_id,error) or a file could not be read or written.

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "experiments/setup/setup_study.h"
#include "experiments/setup/setup_tables.h"

namespace orbed::setup {

/// The user options of user k (1-based) of study m (0-based), as the file comment numbers them.
SetupUserOptions StudyUser(const SetupUserOptions& base, uint64_t seed, const std::string& run_id, int users,
                           int study, int k);

/// Runs `jobs` on `threads` threads (each index once); results by index, the same for any count.
std::vector<SetupRun> RunSetupUsers(const std::vector<SetupUserOptions>& jobs, int threads,
                                    const std::function<void(int done, int total)>& progress = {});

/// The study's table rows of one run: what study::ReadSetupResults reads back from the run's
/// setup_results.json (setup_study_test holds the two equal through the CSVs they make).
study::SetupUserRun TableRun(const SetupRun& run);

int RunSetupStudy(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::setup
