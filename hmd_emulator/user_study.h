#pragma once
/// @file
/// A batch of emulated ViRAAl trials per display mode in the trocar OR, from the shipped files
/// (URDF, scene, slam.yaml, user.yaml, viraal_walk.yaml): the statistics the tests assert on and
/// the `orbed-user-study` tool prints next to the paper's Table 1.
///
/// Trial i of a mode uses person (user seed) base_user_seed + i / trials_per_user, SLAM seed
/// 100000 + i, trial seed 900000 + i and joint configuration i mod 3 of kStudyConfigurationsDeg.
/// The seeds do not depend on the mode: trial i of "ar" and of "ar_reflective" is the same person
/// walking with the same SLAM error and holding the same per-trial depth and lateral biases, with
/// and without the display, so the modes are paired samples (compared with the signed-rank test;
/// the Mann–Whitney test, which ignores the pairing, is reported too). The reflective display
/// freezes its frame at the walk's first waypoint (or at display_waypoints); the user aligns at
/// the last.
///
/// Group means: the paper averages N = 3 trials per set-up in SE(3) (registration_lib, Karcher
/// mean, eq. 2 and 3 about the base origin); here consecutive triples of a mode's trials (the three
/// configurations, mostly one person) are averaged and the mean's base origin compared with the
/// truth.
///
/// Threading: pure function of its inputs; reentrant.

#include <array>
#include <string>
#include <vector>

#include "base/stats.h"
#include "hmd_emulator/viraal_trial.h"

namespace orbed::hmd {

/// Three joint configurations [deg] (the paper aligns at N pre-defined configurations).
inline const std::array<std::array<double, 7>, 3> kStudyConfigurationsDeg{{
    {0, 20, 0, -70, 0, 60, 0},
    {30, 35, -20, -60, 10, 50, 0},
    {-25, 25, 15, -80, -10, 40, 0},
}};

struct StudyOptions {
  std::string source_dir = ".";  ///< repository root (URDF, scene, configs)
  int trials_per_mode = 200;
  int trials_per_user = 10;  ///< the paper: 10 trials per user
  std::uint64_t base_user_seed = 1000;
  /// Optional overrides of the shipped configs (empty = hmd_emulator/config/*.yaml).
  std::string slam_config_path, user_config_path, walk_path;
  /// Waypoints where the "ar_reflective" mode's displays capture their frames (empty = one display
  /// at the walk's first waypoint). A display at the alignment waypoint adds no second viewpoint:
  /// the negative control.
  std::vector<std::string> display_waypoints;
};

struct StudyMode {
  std::string name;  ///< "ar" or "ar_reflective"
  std::vector<TrialOutcome> trials;
  /// The SE(3) mean of each consecutive triple of trials: its base origin's error against the real
  /// base [m] (triples whose mean is not valid are left out).
  std::vector<double> mean_base_error_m;
};

/// Runs both modes ("ar": no display, "ar_reflective": the displays of display_waypoints), paired
/// by seed. Throws on unreadable files or an unknown waypoint.
std::vector<StudyMode> RunStudy(const StudyOptions& options);

/// The paired comparison of the registration error (centroid translation) of two modes' trials:
/// x = `with`, y = `without`, one-sided alternatives "x smaller".
struct StudyComparison {
  stats::MannWhitneyResult mann_whitney;  ///< unpaired (the issue's rank test)
  stats::SignedRankResult signed_rank;    ///< paired trial by trial (valid only for equal sizes)
};
StudyComparison CompareModes(const StudyMode& with, const StudyMode& without);

/// The `orbed-user-study` report: per mode the error statistics (registration, augmentation along
/// and across the ray, nudges, duration, SE(3) means of three), the comparison of the last mode
/// with the first, and the paper's Table 1 for reference.
std::string FormatStudyReport(const std::vector<StudyMode>& modes);

}  // namespace orbed::hmd
