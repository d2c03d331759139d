#pragma once
/// @file
/// The headset's SLAM (inside-out tracking) as an error model around the true head pose: what the
/// device believes (X_WH_est, X_WC_est) given where the head truly is (X_WH_true), sample by sample
/// at 60 Hz, with white jitter, drift that grows with the path walked, and occasional tracking loss
/// followed by a relocalization jump.
///
/// Frames and the one relation everything else uses. W is the true OR world; W' is the device's
/// SLAM map, which the device takes for W (the map is initialised on W: they coincide at the first
/// sample). The map error is the pose of the map in the true world, E = X_WW'. The device reports
///     X_WH_est = E⁻¹ · X_WH_true · J_H,        X_WC_est = X_WH_est · X_HC,
/// J_H being the white jitter of this sample (in H). A hologram the device places at X_WV (map
/// coordinates: every pose the device or its user chooses is one) is drawn with the estimated
/// head pose, i.e. at X_HV = X_WH_est⁻¹ · X_WV relative to the head, and since the head is truly at
/// X_WH_true it appears in the true world at
///     X_WV_apparent = X_WH_true · X_WH_est⁻¹ · X_WV                           (ApparentPose)
/// (= E · X_WV without jitter). Consequences the tests check: head-locked content
/// (X_WV = X_WH_est · X_HV) appears exactly at X_WH_true · X_HV, whatever the error; a purely
/// translational error shifts every hologram by p_WH_true − p_WH_est; the device's projection of a
/// hologram with its believed camera pose equals the true camera's projection of the apparent one.
///
/// The error model (parameters in SlamConfig, loaded from config/slam.yaml):
///  - Drift: visual-inertial odometry leaves 4 directions unobservable (position and yaw about
///    gravity; roll and pitch are fixed by gravity), so E is a translation plus a rotation about the
///    world z axis. Each sample adds to E a translation of drift_fraction_of_distance · ds along a
///    unit direction u and a yaw of drift_yaw_deg_per_m · ds · cos φ about the current head
///    position (ds = the head's true displacement this sample [m]). u and φ are random walks whose
///    correlation decays as exp(−s / drift_direction_correlation_m) with the path s, so over short
///    paths the translation error grows at drift_fraction_of_distance per metre and over long ones
///    it wanders like a random walk. While standing still there is no drift (jitter only).
///    The drift per metre differs from session to session (a different room state, lighting,
///    texture): SessionSlamConfig draws it once per session, log-normal with median
///    drift_fraction_of_distance and log-standard deviation drift_session_log_sigma (0: every
///    session the same), at most kMaxDriftFraction.
///  - Stored places (spatial anchors, loop closure): a place where the head stands still (a sample
///    with no displacement) farther than anchor_radius_m from every stored place is stored with the
///    map error of that moment. Coming back within anchor_radius_m of a stored place while
///    TRACKING re-matches the map there: the head's position error and the yaw error (the short way
///    round) move anchor_relock_correction of the way from today's to the stored ones (1: exactly
///    the stored error; 0 or anchor_radius_m 0: no stored places). Places are stored and
///    re-matched only while TRACKING (a place left and re-entered while LIMITED or LOST is not
///    re-matched). The first sample stores the map origin (unless a fault was forced before it).
///    So a session that returns to the same places sees the errors those places were stored
///    with, and errors of trials made at the same place are correlated.
///  - Jitter: J_H = (exp(ω), v), ω ~ N(0, σ_r² I), v ~ N(0, σ_t² I), independent per sample.
///  - Tracking loss: a Poisson process at tracking_loss_rate_per_min (while TRACKING). The state goes
///    LIMITED for an exponential time (mean limited_mean_s), drifting limited_drift_multiplier times
///    faster; with probability lost_probability it then goes LOST for an exponential time (mean
///    lost_mean_s), during which the device freezes its last estimate. Then one sample is
///    RELOCALIZED: the accumulated error is shrunk by relocalization_correction (re-matching to the
///    stored map; 1 removes it), about the head, and a random jump (σ jump_translation_std_m, yaw
///    σ jump_yaw_std_deg) is applied; then TRACKING again.
///
/// The `slam:` mapping and its defaults: every key optional and checked; an absent key keeps the
/// SlamConfig default, which is the value written here and the value config/slam.yaml ships (the
/// file gives the sources; slam_model_test.cc checks that the three agree):
/// @code{.yaml}
/// slam:
///   seed: 1                  # the walk's randomness
///   rate_hz: 60              # HMD_POSE rate [Hz]
///   head_to_camera: {position_m: [0.0, -0.03, 0.06], rpy_deg: [0, 0, 0]}   # X_HC, HoloLens 1 PV camera
///   jitter: {translation_std_m: 0.0005, rotation_std_deg: 0.02}
///   drift:
///     fraction_of_distance: 0.0065     # median translation drift per metre walked
///     session_log_sigma: 0.47          # its spread over sessions (log-normal)
///     band_fraction: [0.003, 0.014]    # where the drift per metre is expected (tests only)
///     yaw_deg_per_m: 0.05              # [deg/m]
///     direction_correlation_m: 10.0    # [m]
///   anchors:
///     radius_m: 0.5                    # [m]
///     relock_correction: 0.5
///   tracking_loss:
///     rate_per_min: 0.5                # [1/min]
///     limited_mean_s: 1.0              # [s]
///     limited_drift_multiplier: 4.0
///     lost_probability: 0.2
///     lost_mean_s: 2.0                 # [s]
///     relocalization_correction: 0.5   # share of the drift removed; 1 removes it
///     jump_translation_std_m: 0.01     # [m]
///     jump_yaw_std_deg: 0.5            # [deg]
/// @endcode
///
/// Forced faults (tests and demonstrations; none by default, so config/slam.yaml has none): the
/// `slam.faults:` list schedules tracking faults in chosen trials of orbed-hmd, at times relative
/// to the moment the person starts aligning (headset_trial.h, viraal_trial.h); a later file's list
/// replaces an earlier one's as a whole. Each entry:
///   {session: ID,           # the session id ("" or absent: every session)
///    trial: N,              # the trial index within the session (from 0)
///    at_s: T,               # onset, seconds after the alignment started, in [0, 3600]
///    state: lost,           # limited | lost
///    duration_s: D,         # time in that state, in [1 / rate_hz, 60] s; then one RELOCALIZED sample
///    jump: {position_m: [x, y, z], yaw_deg: Y}}   # the relocalization jump (absent: none) [m, deg]
/// Faults of one trial (same trial, same session or either ""), in the order written, must not
/// overlap: each starts after the previous one's duration_s. A forced fault is a ForcedFault
/// (SlamModel::Force): the state holds for round(duration_s · rate_hz) samples whatever the
/// random process would do, then one RELOCALIZED sample shrinks the drift by
/// relocalization_correction as a drawn one does and applies the given jump (about the head, as
/// YawAboutPoint: yaw about the vertical through the head, then the translation) instead of a
/// random one. The fault draws nothing itself (no state, duration or jump draws); its samples draw
/// their jitter and drift as any sample does.
///
/// TrackingState values equal orbed::hmd_pose_t's TRACKING/LIMITED/LOST/RELOCALIZED constants.
/// Units: m, s, rad inside (deg only in names that say so). Threading: a SlamModel is
/// single-threaded (it owns its random stream); configs are plain data.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "base/random.h"
#include "hmd_emulator/head_trajectory.h"

namespace YAML {
class Node;  // yaml-cpp, declared only: the .cc files that read YAML include it
}  // namespace YAML

namespace orbed::hmd {

enum class TrackingState : std::int8_t { kTracking = 0, kLimited = 1, kLost = 2, kRelocalized = 3 };
const char* TrackingStateName(TrackingState state);

/// A tracking fault forced at a chosen sample instead of drawn (see the file comment).
struct ForcedFault {
  TrackingState state{TrackingState::kLost};  ///< kLimited or kLost
  double duration_s{1.0};
  Eigen::Vector3d jump_W_m{Eigen::Vector3d::Zero()};  ///< relocalization jump, translation [m]
  double jump_yaw_deg{0};                             ///< relocalization jump, yaw about the head [deg]
};

/// A forced fault at_s after the person started aligning [s].
struct TimedFault {
  double at_s{0};
  ForcedFault fault;
};

/// One entry of `slam.faults`: a TimedFault in trial trial_index of session_id ("" = every session).
struct ScheduledFault {
  std::string session_id;
  int trial_index{0};
  TimedFault timed;

  bool AppliesTo(const std::string& session, int index) const {
    return index == trial_index && (session_id.empty() || session_id == session);
  }
};

/// The largest drift per metre a config or a session's draw can have (20 %).
inline constexpr double kMaxDriftFraction = 0.2;

struct SlamConfig {
  std::uint64_t seed{1};
  double rate_hz{60.0};
  /// X_HC: the photo/video camera in the head frame, ~3 cm above and ~6 cm in front of the eyes,
  /// looking the same way (H: x right, y down, z forward) [m].
  Eigen::Isometry3d X_HC{Eigen::Translation3d(0.0, -0.03, 0.06)};
  double jitter_translation_std_m{0.0005};
  double jitter_rotation_std_deg{0.02};
  double drift_fraction_of_distance{0.0065};
  /// Log-standard deviation of the per-session drift per metre (SessionSlamConfig).
  double drift_session_log_sigma{0.47};
  double drift_yaw_deg_per_m{0.05};
  double drift_direction_correlation_m{10.0};
  /// The band the drift per metre is expected in (documentation and tests; not used by the model).
  double drift_band_min_fraction{0.003};
  double drift_band_max_fraction{0.014};
  /// Stored places (see the file comment): radius [m] (0: none) and the share re-matched.
  double anchor_radius_m{0.5};
  double anchor_relock_correction{0.5};
  double tracking_loss_rate_per_min{0.5};
  double limited_mean_s{1.0};
  double limited_drift_multiplier{4.0};
  double lost_probability{0.2};
  double lost_mean_s{2.0};
  double relocalization_correction{0.5};
  double jump_translation_std_m{0.01};
  double jump_yaw_std_deg{0.5};
  /// Forced faults (`faults:`, see the file comment); none by default.
  std::vector<ScheduledFault> faults;
};

/// Reads the `slam:` mapping (the node itself) over `base`, key by key: a key the mapping does not
/// have keeps base's value (the defaults above unless given). Every key is optional and
/// checked; errors name `source`, the line and the key.
SlamConfig ParseSlamConfig(const YAML::Node& node, const std::string& source, const std::string& key = "slam",
                           const SlamConfig& base = SlamConfig{});
/// The map of one session: `base` with `seed` = session_seed and the drift per metre drawn from
/// the per-session log-normal (file comment), from its own stream of session_seed.
SlamConfig SessionSlamConfig(const SlamConfig& base, std::uint64_t session_seed);
/// Loads the `slam:` mapping of a YAML file (e.g. hmd_emulator/config/slam.yaml).
SlamConfig LoadSlamConfigFile(const std::string& path);
/// The shipped defaults, relative to the repository root.
inline constexpr const char* kDefaultSlamConfigRelativePath = "hmd_emulator/config/slam.yaml";

/// One 60 Hz sample. seq starts at 0.
struct SlamSample {
  double t_s{0};
  std::int64_t seq{0};
  double path_m{0};  ///< true path walked so far [m]
  Eigen::Isometry3d X_WH_true{Eigen::Isometry3d::Identity()};
  Eigen::Isometry3d X_WC_true{Eigen::Isometry3d::Identity()};
  Eigen::Isometry3d X_WH_est{Eigen::Isometry3d::Identity()};
  Eigen::Isometry3d X_WC_est{Eigen::Isometry3d::Identity()};
  /// The drift part of the map error E = X_WW' (without this sample's jitter).
  Eigen::Isometry3d X_WWmap{Eigen::Isometry3d::Identity()};
  TrackingState state{TrackingState::kTracking};
};

/// X_WV_apparent = X_WH_true · X_WH_est⁻¹ · X_WV: where a hologram placed at X_WV in map
/// coordinates appears in the true world when the device draws it with X_WH_est.
inline Eigen::Isometry3d ApparentPose(const Eigen::Isometry3d& X_WH_true, const Eigen::Isometry3d& X_WH_est,
                                      const Eigen::Isometry3d& X_WV) {
  return X_WH_true * X_WH_est.inverse() * X_WV;
}

class SlamModel {
 public:
  explicit SlamModel(const SlamConfig& config);

  /// Advances to the next sample with the head truly at X_WH_true at time t_s (non-decreasing).
  /// The first call initialises the map on W (E = I).
  SlamSample Step(const Eigen::Isometry3d& X_WH_true, double t_s);

  /// Forces `fault` from the next Step() on, whatever the state: that sample and the next
  /// round(duration_s · rate_hz) − 1 are in fault.state, the one after is RELOCALIZED with the
  /// fault's jump (see the file comment). Throws std::invalid_argument unless the state is
  /// kLimited or kLost and the duration is positive.
  void Force(const ForcedFault& fault);
  /// Whether a forced fault is under way: from Force() until the Step() that returns its
  /// RELOCALIZED sample (false after that Step()).
  bool forcing() const { return pending_force_.has_value() || forced_.has_value(); }
  /// Turns the drawn (Poisson) tracking losses off or on (on by default); forced ones happen anyway.
  void set_random_losses(bool on) { random_losses_ = on; }

  const SlamConfig& config() const { return config_; }
  /// The current drift part of the map error E = X_WW'.
  const Eigen::Isometry3d& X_WWmap() const { return E_; }
  /// Places stored so far, and how many times the map was re-matched at one.
  int anchors() const { return static_cast<int>(anchors_.size()); }
  int relocks() const { return relocks_; }

 private:
  struct Anchor {
    Eigen::Vector3d p_W;  // the head's true position when stored [m]
    Eigen::Isometry3d E;  // the map error then
    bool inside{true};    // the head within anchor_radius_m at the last sample
  };
  void Drift(const Eigen::Vector3d& p_WH, double ds_m, double multiplier);
  void UpdateAnchors(const Eigen::Vector3d& p_WH, double ds_m);
  void AdvanceState(double dt_s);

  SlamConfig config_;
  Random rng_;
  bool started_{false};
  std::int64_t seq_{0};
  double last_t_s_{0};
  double path_m_{0};
  Eigen::Vector3d last_p_WH_{Eigen::Vector3d::Zero()};
  Eigen::Isometry3d E_{Eigen::Isometry3d::Identity()};
  Eigen::Vector3d drift_dir_{Eigen::Vector3d::UnitX()};
  double yaw_phase_rad_{0};
  TrackingState state_{TrackingState::kTracking};
  double state_left_s_{0};
  bool lost_follows_{false};
  Eigen::Isometry3d frozen_X_WH_est_{Eigen::Isometry3d::Identity()};
  bool random_losses_{true};
  std::optional<ForcedFault> pending_force_;  // Force() called, not yet applied by Step()
  std::optional<ForcedFault> forced_;         // under way: its jump is applied at RELOCALIZED
  long long forced_samples_left_{0};          // samples still in forced_->state after this one
  std::vector<Anchor> anchors_;
  int relocks_{0};
};

/// Samples a trajectory at config.rate_hz from t = 0 to t_end_s (inclusive of 0): one SlamModel
/// with config's seed.
std::vector<SlamSample> SimulateWalk(const HeadTrajectory& trajectory, const SlamConfig& config,
                                     double t_end_s);

}  // namespace orbed::hmd
