#pragma once
/// @file
/// A batch of emulated ViRAAl trials per display mode in the trocar OR, from the shipped files
/// (URDF, scene, slam.yaml, user.yaml, viraal_walk.yaml): the statistics the tests assert on and
/// the `hmd-user-study` tool prints next to the paper's Table 1.
///
/// Trial i of a mode uses person (user seed) base_user_seed + i / trials_per_user, SLAM seed and
/// trial seed derived from (mode, i), and joint configuration i mod 3 of kStudyConfigurationsDeg.
/// Modes are independent samples (different seeds). The reflective display freezes its frame at
/// the walk's first waypoint; the user aligns at the second.
///
/// Threading: pure function of its inputs; reentrant.

#include <array>
#include <string>
#include <vector>

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
  int trials_per_user = 10;      ///< the paper: 10 trials per user
  std::uint64_t base_user_seed = 1000;
  /// Optional overrides of the shipped configs (empty = hmd_emulator/config/*.yaml).
  std::string slam_config_path, user_config_path, walk_path;
};

struct StudyMode {
  std::string name;  ///< "ar" or "ar_reflective"
  std::vector<TrialOutcome> trials;
};

/// Runs both modes ("ar": no display, "ar_reflective": one display). Throws on unreadable files.
std::vector<StudyMode> RunStudy(const StudyOptions& options);

}  // namespace orbed::hmd
