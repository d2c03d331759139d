#pragma once
/// @file
/// The emulated trial that orbed-hmd runs for each accepted SESSION_CONTROL REQUEST_TRIAL, as one
/// pure function: any program that passes the same inputs gets the same TrialOutcome, bit for bit
/// (the process publishes outcome.alignment.X_WV and .duration_s on ALIGNMENT_TRIAL).
///
/// The trial (viraal_trial.h): the emulated person of config.user walks config.walk on the
/// session's one continuous map (SessionMapAtTrial: put on at config.hmd.session_start_m, the
/// earlier trials' walks replayed; config.slam with the session's seed and drift per metre,
/// SessionSlamConfig), the first num_mirrors displays of
/// config.hmd.displays capture their frames at their waypoints, and the person aligns the virtual
/// robot at config.hmd.align_waypoint (after config.hmd.settle_s, waiting up to
/// config.hmd.max_wait_s for tracking), starting from X_WV_start, against the real robot at X_WR
/// whose model points at the trial's q are p_RQ, and then annotates the landmarks p_RL (the
/// config.hmd.annotation_* style). The forced faults of config.slam.faults for this
/// session and trial index happen while the person aligns (viraal_trial.h), who re-does the
/// alignment at most config.hmd.max_repeats times.
///
/// Seeds: derived from (process seed, session id, trial index, purpose) by TrialSeed(): purpose
/// kSessionMapPurpose (index 0) for the session's map, kTrialSeedPurpose for the person's per-trial
/// randomness. The same process seed, session and index give the same trial whatever happened
/// before it (the map's earlier walks are replayed, not remembered); another session gives an
/// independent map.
///
/// Frames: W world (= the SLAM map for estimates), R real robot base, V virtual robot base.
/// Units: m, rad, s.
/// Threading: pure functions of their arguments; reentrant. No LCM, no clock, no process state.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <orbed/alignment_trial_t.hpp>

#include "hmd_emulator/hmd_config.h"
#include "hmd_emulator/viraal_trial.h"
#include "sim/robot_model.h"

namespace orbed::hmd {

/// TrialSeed() purposes.
inline constexpr std::uint64_t kTrialSeedPurpose = 2;
inline constexpr std::uint64_t kSessionMapPurpose = 3;  ///< 1 was a map per trial, before one per session

/// The seed for one purpose of trial `index` of `session_id` in a process seeded with `seed`:
/// SplitMix64 over the seed, the FNV-1a hash of the session id, the index and the purpose
/// (base/hash.h).
std::uint64_t TrialSeed(std::uint64_t seed, const std::string& session_id, std::int32_t index,
                        std::uint64_t purpose);

/// What one emulated headset trial is made of, besides the configuration.
struct HeadsetTrialInputs {
  /// Model points of the robot at the trial's joint vector q, in R (RobotModelPoints(model, q)) [m].
  std::vector<Eigen::Vector3d> p_RQ;
  std::vector<SightSolid> solids_R;  ///< RobotSightSolids at the same q (what hides what)
  /// Where each display captures (the session's START); empty: hmd.displays' capture_waypoint.
  std::vector<std::string> capture_waypoints;
  /// The real robot base (truth) [m].
  Eigen::Isometry3d X_WR{Eigen::Isometry3d::Identity()};
  /// Where the hologram starts, in map coordinates (orbed-hmd: X_WR_nominal · user.X_RV_start).
  Eigen::Isometry3d X_WV_start{Eigen::Isometry3d::Identity()};
  std::uint64_t process_seed{1};  ///< --seed of orbed-hmd
  std::string session_id;
  std::int32_t trial_index{0};  ///< per session, from 0
  /// Displays used (the session's num_mirrors): the first num_mirrors of config.hmd.displays.
  std::int32_t num_mirrors{0};
  /// The landmarks the person annotates after the alignment, in R at q (AnnotationLandmarkPoints);
  /// empty = no annotation.
  std::vector<Eigen::Vector3d> p_RL;
  /// A live collaborator's camera, truly (orbed-hmd --collaborator): the first display is its
  /// frame (CollaboratorDisplay::X_WC_true, with config.hmd.collaborator's anchor error).
  std::optional<Eigen::Isometry3d> collaborator_X_WC_true;
};

/// The origins of config.hmd.annotation_landmarks' links at q [rad], in R [m], in that order.
/// Throws std::invalid_argument naming a link the model does not have.
std::vector<Eigen::Vector3d> AnnotationLandmarkPoints(const sim::RobotModel& model, const HmdConfig& hmd,
                                                      const Eigen::VectorXd& q_rad);

/// Sets inputs->p_RQ and inputs->solids_R for the robot `model` at q_rad (RobotModelPoints,
/// RobotSightSolids). Throws std::invalid_argument on a wrong q size.
void SetRobotAt(const sim::RobotModel& model, const Eigen::VectorXd& q_rad, HeadsetTrialInputs* inputs);

/// The TrialSetup (viraal_trial.h) of a headset trial: the walk, the capture and alignment
/// waypoints and times of `config`, the HoloLens PV intrinsics, X_WR and p_RQ of `inputs`, and
/// the forced faults of config.slam.faults that apply to inputs' session and trial index.
/// Throws std::invalid_argument when num_mirrors is negative or exceeds the displays placed.
TrialSetup MakeHeadsetTrialSetup(const HmdConfigSet& config, const HeadsetTrialInputs& inputs);

/// Writes outcome.annotation into ALIGNMENT_TRIAL's annotation fields (contract change 5),
/// replacing what they held.
void SetAnnotationFields(const std::vector<AnnotationRay>& annotation, orbed::alignment_trial_t* msg);

/// Runs the trial (see the file comment). Throws std::invalid_argument as MakeHeadsetTrialSetup()
/// and RunTrial() do.
/// `cache` (optional, one per process and configuration): the session's map as the last trial
/// found it, so that consecutive trials of a session cost one walk each (SessionMapAtTrial).
TrialOutcome RunHeadsetTrial(const HmdConfigSet& config, const HeadsetTrialInputs& inputs,
                             SessionMapCache* cache = nullptr);

}  // namespace orbed::hmd
