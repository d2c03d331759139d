#pragma once
/// @file
/// One emulated ViRAAl trial end to end, without LCM: the wearer walks a head trajectory while the
/// SLAM model tracks it, reflective displays freeze camera frames at chosen waypoints (truth and
/// estimate of that moment), and at the alignment waypoint the emulated user aligns the virtual
/// robot from what they see. Used by the tests, the study statistics and (through its pieces) the
/// orbed-hmd process.
///
/// Frames as in slam_model.h and user_model.h. The registration error compares the chosen X_WV (map
/// coordinates) with the truth X_WR; the augmentation error compares where the hologram appears at
/// the end of the trial (ApparentPose) with the real robot, i.e. what the paper's landmark protocol
/// measures inside the headset's own map.
///
/// Threading: pure function of its inputs (seeds included); reentrant.

#include <cstdint>
#include <string>
#include <vector>

#include "hmd_emulator/head_trajectory.h"
#include "hmd_emulator/slam_model.h"
#include "hmd_emulator/user_model.h"

namespace orbed::hmd {

struct TrialSetup {
  Eigen::Isometry3d X_WR{Eigen::Isometry3d::Identity()};  ///< real robot base (truth)
  std::vector<Eigen::Vector3d> p_RQ;                      ///< model points at the trial's q
  HeadTrajectoryConfig walk;
  /// Waypoints where a reflective display captures its frame (at arrival); empty = AR only.
  std::vector<std::string> capture_waypoints;
  /// Waypoint where the user aligns (at arrival, after `settle_s`, once tracking is TRACKING).
  std::string align_waypoint;
  double settle_s{0.5};
  /// If tracking is not TRACKING at the alignment time, the person stands and waits up to this
  /// long for it to recover (then aligns anyway) [s].
  double max_wait_s{30.0};
  geometry::Intrinsics intrinsics;
};

struct TrialOutcome {
  AlignmentResult alignment;
  PoseError registration;  ///< X_WV (map) against X_WR (truth)
  PoseError augmentation;  ///< apparent hologram against X_WR, at the alignment sample
  SlamSample at_alignment;
  std::vector<SlamSample> at_capture;
  int relocalizations{0};  ///< RELOCALIZED samples during the walk
};

/// Runs one trial. slam.seed and trial_seed make it reproducible; X_WV_start is in map coordinates.
/// Throws std::invalid_argument naming a waypoint that the walk does not have.
TrialOutcome RunTrial(const TrialSetup& setup, const SlamConfig& slam, const EmulatedUser& user,
                      const Eigen::Isometry3d& X_WV_start, std::uint64_t trial_seed);

}  // namespace orbed::hmd
