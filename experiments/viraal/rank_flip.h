#pragma once
/// @file
/// How often the paper's measurement ranks the two display modes opposite to the truth: many
/// simulated ViRAAl studies of the paper's size (Sec. III-B: 4 users x 10 trials per mode), each
/// through the in-process path (viraal_study.h RunViraalStudy, equal to the bus run for the same
/// seeds), reduced to one row per study and mode. The flip fraction and its interval are computed
/// from the rows in Python (python/orbed/study/rank_flip.py).
///
/// Seeds, as `scripts/orbed study --seed S' --users U` numbers its users: study m (from 0) is that
/// study with S' = S + U·m, its user k (from 1) the emulated person of user seed S' + k − 1 with run
/// id "study-s<S'>-u<k>" (which seeds the alignments); orbed-hmd's process seed is the options'.
/// So studies do not share a person, and study m can be re-run over the bus.
///
/// Per study and mode, over the pooled trials of its users:
///   measured_w_mm        the paper's Table 1 figure: ‖per-axis means of t̄ over the trials‖₂, axes
///                        of W (results.h Table1Row), from the gaze-annotated landmarks
///   measured_s_mm        the same in the trials' viewer frames (metrics.h ViewerFrame); NaN when a
///                        trial has no viewer frame (nobody annotated)
///   true_translation_mm  the mean over the trials of the true translation error (at the robot's
///                        centroid): what the ranking should follow
///   true_misalignment_mm the mean over the trials of ‖t̄‖₂ from the truth's landmark pairs
///
/// Units: mm. Threading: pure functions of their inputs; reentrant.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "experiments/viraal/viraal_study.h"

namespace orbed::study {

struct RankFlipOptions {
  /// The study every simulated one repeats: scenario (its trials per mode), files, process seed.
  /// Its run_id and user_seed are replaced per user.
  StudyOptions study;
  int studies{1000};
  int users{4};
  std::uint64_t first_user_seed{1};  ///< S
  /// Called after each study with (studies done, studies in all); may be empty.
  std::function<void(int, int)> progress;
  /// Called after each study, in order, with its index m and its users' results (user k at k − 1);
  /// may be empty (orbed-user-study --tables-dir writes the study's CSVs from it).
  std::function<void(int, const std::vector<viraal::RunResults>&)> on_study;
};

struct StudyModeRow {
  int study{0};                      ///< m, from 0
  std::uint64_t first_user_seed{0};  ///< S + users·m
  std::string mode;
  int users{0};
  int trials{0};  ///< pooled over the users
  double measured_w_mm{0};
  double measured_s_mm{0};
  double true_translation_mm{0};
  double true_misalignment_mm{0};
};

/// The user seed and run id of user k (from 1) of a study whose first user seed is `seed`.
std::uint64_t StudyUserSeed(std::uint64_t seed, int k);
std::string StudyRunId(std::uint64_t seed, int k);

/// One study's rows (one per mode, in the scenario's order) from its users' results.
std::vector<StudyModeRow> StudyRows(int study, std::uint64_t first_user_seed,
                                    const std::vector<viraal::RunResults>& users);

/// Runs the studies (RunViraalStudy per user); throws as RunViraalStudy does, or
/// std::invalid_argument for fewer than one study or user.
std::vector<StudyModeRow> RunRankFlipStudies(const RankFlipOptions& options);

/// study,first_user_seed,mode,users,trials,measured_w_mm,measured_s_mm,true_translation_mm,
/// true_misalignment_mm (a header, then one line per row; numbers with 17 significant digits).
std::string RankFlipCsv(const std::vector<StudyModeRow>& rows);

}  // namespace orbed::study
