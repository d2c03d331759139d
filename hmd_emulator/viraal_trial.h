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
/// Tracking faults while aligning (setup.faults, forced; times from the start of the alignment,
/// t = 0 at the alignment sample). Without faults the SLAM model is not stepped after the
/// alignment sample and the trial is what it always was. With them the person stands still at the
/// alignment waypoint (no drift; jitter only; drawn tracking losses off, so only the forced ones
/// happen) and the model is stepped at rate_hz from the alignment sample on. A fault whose onset
/// falls before the person submits interrupts them:
///  - they stop and wait while the device is LIMITED or LOST, until its RELOCALIZED sample (the
///    time between the fault's first sample and that one, round(duration_s · rate_hz) / rate_hz,
///    is `wait_s`; it is part of duration_s, as it is part of the time the person took);
///  - if the hologram then appears moved (EmulatedUser::SeesHologramMove, between where it appeared
///    to them at the start of their current alignment and where it appears after the
///    relocalization, at the pose they had reached at the onset), they re-do the alignment from that
///    pose with what they see after the relocalization (same trial seed: the trial's biases are
///    held), at most max_repeats times; the time of the interrupted attempt is spent;
///  - otherwise (or with no repeats left) they carry on where they were: the attempt's result
///    stands and finishes wait_s later.
/// A fault after the person submitted does not happen to them. The augmentation error is taken
/// with the last sample they aligned or waited with (after the last relocalization), so it shows a
/// jump that the person did not re-align for. The record (TrackingFaultRecord) counts all this.
/// Sources: the wait is the device's (the fault's duration); a repeat costs what the user model's
/// looks and nudges cost (config/user.yaml); max_repeats is chosen (hmd.yaml).
///
/// Landmark annotation (paper Sec. III-B, annotation.h), when setup.p_RL names landmarks: after
/// submitting, the person annotates each landmark l on the real robot (X_WR · p_RL[l]) and on the
/// hologram (X_WV · p_RL[l], aimed where it appears) from where they stand (at_end's true head
/// position), walks to their right around the landmarks' centroid (about the vertical through it, at
/// the same distance) until the lines of sight to it from the two positions meet at
/// annotation_view_angle_deg, and annotates them again in the same order: two rays per landmark and
/// side, recorded from the estimated head (map coordinates). The SLAM model is stepped on from
/// at_end (no random tracking losses) and the pointing errors have their own seed (from
/// trial_seed), so nothing the trial measured before changes with the annotation.
///
/// Threading: pure functions of their inputs (seeds included), reentrant, except that a
/// SessionMapCache is written by the call that is given it (one cache per thread).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "hmd_emulator/annotation.h"
#include "hmd_emulator/head_trajectory.h"
#include "hmd_emulator/slam_model.h"
#include "hmd_emulator/user_model.h"

namespace orbed::hmd {

/// A collaborator's headset as the first reflective display (the paper's Discussion: multi-view
/// from collaborative devices). Another person stands at `waypoint` of the walk, their
/// head where the walk's is on arriving there (looking where the walk looks), and their camera's
/// live frame, with the hologram drawn in it, is what the display shows while the wearer aligns.
/// Their headset has its own map, joined to the wearer's by a shared anchor: the frame is stamped
/// with the collaborator's camera in the wearer's map of the moment (CollaboratorView), so it
/// carries the wearer's current map error rather than the error of an earlier capture, times the
/// anchor's error, drawn per trial, normal with these standard deviations per axis. No literature
/// value is assumed for them: `scripts/orbed sweep --only collaborator` sweeps the translation.
struct CollaboratorDisplay {
  std::string waypoint;  ///< "" = none (unless X_WC_true is given)
  /// Where the collaborator's camera truly is, instead of at the waypoint: a live second headset
  /// (orbed-hmd --collaborator, from its HMD_POSE_TRUTH_<NAME>) [m].
  std::optional<Eigen::Isometry3d> X_WC_true;
  double colocalization_translation_mm{0.0};  ///< [mm], 0 .. 1000
  double colocalization_rotation_deg{0.0};    ///< [deg], 0 .. 45
  bool active() const { return !waypoint.empty() || X_WC_true.has_value(); }
};

struct TrialSetup {
  Eigen::Isometry3d X_WR{Eigen::Isometry3d::Identity()};  ///< real robot base (truth)
  std::vector<Eigen::Vector3d> p_RQ;                      ///< model points at the trial's q
  std::vector<SightSolid> solids_R;  ///< the robot's solids at the trial's q; empty: nothing hidden
  HeadTrajectoryConfig walk;
  /// Waypoints where a reflective display captures its frame (at arrival, once tracking; see
  /// WalkSamples::at_capture); empty = AR only.
  std::vector<std::string> capture_waypoints;
  /// With a waypoint and at least one capture waypoint: the first display is the collaborator's
  /// live frame instead of the frame captured on the walk.
  CollaboratorDisplay collaborator;
  /// Waypoint where the user aligns (at arrival, after `settle_s`, once tracking is TRACKING).
  std::string align_waypoint;
  double settle_s{0.5};
  /// If tracking is not TRACKING at the alignment time, the person stands and waits up to this
  /// long for it to recover (then aligns anyway) [s].
  double max_wait_s{30.0};
  geometry::Intrinsics intrinsics;
  /// Forced tracking faults while aligning (see the file comment): ascending at_s, each after the
  /// previous one's end (the `slam.faults` parser checks it).
  std::vector<TimedFault> faults;
  /// The most alignments the person re-does in one trial after seeing the hologram jump.
  int max_repeats{2};
  /// Landmarks to annotate after the alignment, in R at the trial's q [m]; empty = none.
  std::vector<Eigen::Vector3d> p_RL;
  AnnotationStyle annotation;
  /// The angle between the lines of sight of the two annotation positions [deg].
  double annotation_view_angle_deg{40.0};
};

/// One gaze ray of the landmark annotation (see the file comment).
struct AnnotationRay {
  int landmark{0};       ///< index into TrialSetup::p_RL
  bool hologram{false};  ///< aimed at the virtual robot (else the real one)
  GazeRayRecord ray;     ///< map coordinates
};

/// What tracking faults did to the person while aligning (between the alignment sample and the
/// submission; ALIGNMENT_TRIAL carries it).
struct TrackingFaultRecord {
  int losses{0};           ///< faults met (LIMITED or LOST episodes)
  int relocalizations{0};  ///< RELOCALIZED samples
  double wait_s{0};        ///< stood waiting for tracking, included in duration_s [s]
  int repeats{0};          ///< alignments re-done after the hologram jumped
  /// The faults met, at their onset (the sample they started on) from the alignment start.
  std::vector<TimedFault> met;
};

/// The collaborator's display as the wearer sees it while aligning from `at`: the collaborator's
/// camera truly at X_WC = setup.collaborator.X_WC_true, else X_WH(arrival at its waypoint) · X_HC,
/// stamped in the
/// wearer's map as X_WC_est = C · M · X_WC, M = at.X_WH_est · at.X_WH_true⁻¹ (the wearer's map
/// error then, E⁻¹ of slam_model.h up to jitter) and C the anchor's error (translation and rotation
/// vector normal per axis with the configured deviations, from trial_seed's own stream: nothing
/// else the trial draws changes). D from the collaborator's line of sight (CaptureGazeDistance).
/// The shared anchor's error C (see CollaboratorView), drawn from `seed`'s own stream: translation
/// and rotation vector normal per axis with the collaborator's deviations.
Eigen::Isometry3d AnchorError(const CollaboratorDisplay& collaborator, std::uint64_t seed);

ReflectiveDisplayView CollaboratorView(const TrialSetup& setup, const Eigen::Isometry3d& X_HC,
                                       const SlamSample& at, std::uint64_t trial_seed);

struct TrialOutcome {
  /// The person's (last) alignment; its duration_s is the whole alignment's, waits and interrupted
  /// attempts included.
  AlignmentResult alignment;
  PoseError registration;   ///< X_WV (map) against X_WR (truth)
  PoseError augmentation;   ///< apparent hologram against X_WR, at at_end
  SlamSample at_alignment;  ///< the sample the person started aligning with
  SlamSample at_end;        ///< the last one they aligned or waited with (= at_alignment without faults)
  std::vector<SlamSample> at_capture;  ///< the displays' frames (WalkSamples::at_capture)
  int relocalizations{0};              ///< RELOCALIZED samples during the walk (and the wait before aligning)
  TrackingFaultRecord faults;          ///< while aligning
  /// The landmark annotation: for each head position, for each landmark, real then hologram.
  std::vector<AnnotationRay> annotation;
};

/// What the person sees while aligning at the sample `at`: the real robot, the head's true and
/// estimated pose, the robot's solids, and one display per captured frame (at_capture), each with
/// the gaze distance D of CaptureGazeDistance.
ViewingContext TrialViewingContext(const TrialSetup& setup, const SlamSample& at,
                                   const std::vector<SlamSample>& at_capture);

/// Runs one trial on a fresh map that starts at the walk's first waypoint (t = 0). slam.seed and
/// trial_seed make it reproducible; X_WV_start is in map coordinates. Throws std::invalid_argument
/// naming a waypoint that the walk does not have.
TrialOutcome RunTrial(const TrialSetup& setup, const SlamConfig& slam, const EmulatedUser& user,
                      const Eigen::Isometry3d& X_WV_start, std::uint64_t trial_seed);

/// The same trial on a map already under way: `model` as it is when the person stands at the
/// walk's first waypoint at time t0_s (SessionMapAtTrial). The model is a copy: what the trial
/// does to it (the alignment's faults, the annotation) stays in this trial.
TrialOutcome RunTrialFrom(const TrialSetup& setup, SlamModel model, double t0_s, const EmulatedUser& user,
                          const Eigen::Isometry3d& X_WV_start, std::uint64_t trial_seed);

/// What the walk to the alignment gives (RunTrial's first part, also replayed by SessionMapAtTrial).
struct WalkSamples {
  SlamSample at_alignment;  ///< the sample the person starts aligning with
  /// One per capture waypoint: the first TRACKING sample from the arrival on (a frame taken while
  /// tracking is limited or lost has no pose to place it with; the display waits), else the
  /// alignment sample.
  std::vector<SlamSample> at_capture;
  int relocalizations{0};
};
/// Steps `model` along setup.walk from its first waypoint (at t0_s) to the alignment sample (after
/// settle_s, and any wait for TRACKING). Throws std::invalid_argument for an unknown waypoint.
WalkSamples WalkToAlignment(const TrialSetup& setup, double t0_s, SlamModel* model);

/// Steps `model` along a straight walk from p_W_from (at t0_s, not stepped) to p_W_to at the walk's
/// speed, looking at its target; returns the arrival time [s] (t0_s for no distance).
double WalkStraight(const Eigen::Vector3d& p_W_from, const Eigen::Vector3d& p_W_to,
                    const HeadTrajectoryConfig& walk, double t0_s, SlamModel* model);

/// The session's one continuous map as it is when trial `trial_index` begins:
/// the person puts the headset on at p_W_session_start (the map's origin, stored as the first
/// place), walks straight to the walk's first waypoint, and for each earlier trial walks the trial's
/// walk to its alignment sample and straight back to the first waypoint. Only the walks are
/// replayed: what happened while aligning and annotating stays in that trial (RunTrialFrom copies
/// the model). Deterministic in (session_slam, the walk, trial_index), so a restarted headset
/// rebuilds the same map. *t_s is the time at which the trial's walk begins.
/// With `cache`, a map at a later trial of the same session (the same SessionMapKey: every input of
/// the replay) goes on from the one remembered instead of replaying the whole session, with the
/// same result bit for bit; anything else replays. Throws std::invalid_argument for trial_index
/// outside [0, kMaxSessionTrials).
struct SessionMapCache {
  std::optional<SlamModel> model;  ///< the map when trial `trial_index` begins
  int trial_index{0};
  double t_arrived_s{0};  ///< when the person arrived at the walk's start before that trial [s]
  std::string key;        ///< SessionMapKey of the inputs it was made with
};
/// Every input the replay of SessionMapAtTrial depends on, exactly (hexadecimal floats): the SLAM
/// model's parameters and seed, the start, the walk, the alignment waypoint, settle_s, max_wait_s.
std::string SessionMapKey(const TrialSetup& setup, const SlamConfig& slam, const Eigen::Vector3d& p_W_start);
SlamModel SessionMapAtTrial(const TrialSetup& setup, const SlamConfig& session_slam,
                            const Eigen::Vector3d& p_W_session_start, int trial_index, double* t_s,
                            SessionMapCache* cache = nullptr);
/// The most trials a session's map is rebuilt for (= kMaxTrialsPerSession of
/// lcmtypes/contract/alignment_trial.h, which the headset's session enforces on the bus).
inline constexpr int kMaxSessionTrials = 1000;

}  // namespace orbed::hmd
