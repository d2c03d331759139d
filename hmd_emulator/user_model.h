#pragma once
/// @file
/// The emulated ViRAAl user (paper Sec. II-A, III-B): a person wearing the headset who nudges the
/// virtual robot V until it looks aligned with the real robot R in everything they can see, and
/// returns the pose they settled on (an alignment trial).
///
/// Frames (docs/design.md; the SLAM relation of slam_model.h). W is the true world, the user's chosen
/// X_WV is in map coordinates (the device's W'). The real robot is at X_WR (truth) at joint vector q;
/// the virtual robot is the same model at the same q at X_WV. Model points p_RQ (= p_VQ) come from
/// forward kinematics (RobotModelPoints). The head is truly at X_WH_true; the device believes
/// X_WH_est, so the hologram appears at A · X_WV with A = X_WH_true · X_WH_est⁻¹ (ApparentPose).
///
/// What the person perceives, per look (one look before each nudge):
///  - Direct view (see-through display, from the eye at X_WH_true's origin). For each model point,
///    the discrepancy d = h − r between where the hologram point appears (h = A·X_WV·p) and the real
///    point (r = X_WR·p), split along the viewing ray n (eye → r, distance ρ) and across it:
///      lateral (2 components):  a·d + ρ·(α_trial + σ_lat·N)        [angular acuity, small]
///      along the ray:           n·d + ρ·(β_trial + s·σ_depth·N)     [depth matching, poor]
///    α_trial (per trial, 2D) and β_trial = s·(β_user + σ_β·N) (per trial) are biases held during a
///    trial: a person misjudges the depth of a virtual object consistently, as a fraction of the
///    viewing distance (AR depth-matching studies), more or less so depending on who they are:
///    s (log-normal, median 1) and β_user are drawn once per person from the user seed, so the
///    errors are heavy-tailed from person to person.
///  - Each reflective display: the frame was captured earlier with the camera truly at X_WC_true and
///    is stamped with the device's estimate X_WC_est; the overlay projects the virtual robot with
///    the estimate, so the display carries the SLAM error of its capture time. The reversed frustum
///    P_m (camera_model.h) only re-places and y-flips that image (the paper: D "does not affect the
///    rendering content"; the flip is an isometry of the image), so the 2D discrepancy the person
///    sees is, up to the sign of v, Δu = Π(K, X_WC_est, X_WV·p) − Π(K, X_WC_true, X_WR·p) [px] for
///    the points inside the captured frame, perceived with a per-trial common offset and per-point
///    noise. Both are the direct view's angular acuity (lateral_bias/noise_arcmin: the same eye on
///    the same HoloLens pixels) carried onto the panel: the panel shows pixel (u, v) at
///    s·((u − cx)/fx, (v − cy)/fy) from its centre, s = D/2 (reflective.h), and the person sees it
///    face on from L away, so one radian at the eye is L·fx/s camera px. A small or far panel
///    therefore shows the robot coarsely; the person's belief and stop threshold for a display are
///    the same angles (assumed_lateral_arcmin, stop_lateral_arcmin) converted the same way.
/// Perception limits (perception:):
///  - Field of view: the see-through display shows holograms only inside fov_h_deg × fov_v_deg
///    (HoloLens 1: 30 × 17.5 deg) about the head's line of sight (z of X_WH_true, which the walk turns toward
///    its look-at point). A model point whose hologram is outside it is not compared. A display is
///    looked at on its own (display_look_s), with the head turned to the panel's centre: the parts
///    of a panel wider than the field of view are not seen.
///  - Occlusion: a model point counts only where the line of sight from the eye (direct view) or
///    from the capture camera (display) to the real point meets no solid of the robot other than
///    those containing the point (RobotSightSolids: each collision primitive as a swept segment).
///  If nothing is in view the person cannot align and stops ("nothing_in_view").
/// How the person acts: they combine everything by weighted least squares over the 6 DOF of a
/// nudge (a twist ξ = (ω, v) of the hologram about its centroid, in map coordinates), weighting each
/// perceived component by the reliability they believe it has (assumed_* parameters), take one
/// Gauss–Newton step, and carry out a fraction `gain` of it with motor noise. Size blindness
/// (size_blind): moving the hologram a distance t along the line of sight also rescales its image
/// by ~t/ρ (1.2 % for 24 mm at 2 m), below what people discriminate in size (a few per cent), so the
/// person's fit carries a nuisance image scale σ about the centroid's line of sight, which they
/// cannot act on: depth in the direct view then rests on depth perception alone. A display is a
/// picture too, and the same person is as blind to size in it: each display j has its own nuisance
/// scale σ_j of the image about the real centroid's pixel u_c,j (Jacobian column u_real,k − u_c,j),
/// so a shift along that camera's line of sight is not read from the display either, and the
/// perceived display discrepancy is judged net of σ_j. They stop when every perceived discrepancy
/// (net of the scales) is below their thresholds (lateral and display [arcmin], depth [fraction of
/// ρ]), when the step they would take is too small to bother (min_step_*), when patience_nudges
/// nudges in a row made nothing look better (the hand's own noise, motor_noise_*, can keep them
/// from ever meeting the thresholds), or after max_nudges.
/// Nothing about "the mirror helps" is written in: the display's image plane, seen from another
/// viewpoint, contains the direct view's ray direction, so it constrains the depth that the direct
/// view leaves ambiguous, with its own (SLAM) error; a display captured from the alignment
/// viewpoint itself adds no second viewpoint and gives (almost) nothing (the negative control in
/// user_model_test.cc).
///
/// Every parameter is in UserConfig, loaded from hmd_emulator/config/user.yaml (sources beside each
/// default there). Units: m, rad inside; arcmin/deg/px/fraction only where the name says so.
///
/// The `user:` mapping and its defaults: every key optional and checked; an absent key keeps the
/// UserConfig default, which is the value written here and the value config/user.yaml ships
/// (user_model_test.cc checks that the three agree):
/// @code{.yaml}
/// user:
///   seed: 1                    # the person
///   start_offset: {position_m: [0.10, -0.08, 0.05], rpy_deg: [2.0, -1.5, 4.0]}   # X_RV_start
///   direct_view:
///     lateral_noise_arcmin: 1.5
///     lateral_bias_arcmin: 1.0
///     depth_bias_fraction_std: 0.014        # of the viewing distance, per trial
///     depth_user_bias_fraction_std: 0.006   # per person
///     depth_noise_fraction_std: 0.004       # per look, per point
///     user_scale_log_sigma: 0.45
///     size_blind: true
///   perception: {fov_h_deg: 30.0, fov_v_deg: 17.5, occlusion: true}
///   belief: {lateral_arcmin: 2.0, depth_fraction: 0.02}
///   nudging:
///     gain: 0.6
///     motor_noise_fraction: 0.15
///     motor_noise_translation_mm: 0.5       # per axis, per nudge, whatever its size
///     motor_noise_rotation_deg: 0.5
///     max_nudges: 40
///     stop_lateral_arcmin: 3.0
///     stop_depth_fraction: 0.01
///     min_step_m: 0.001
///     min_step_deg: 0.1
///     patience_nudges: 2                    # nudges without a better look before giving up (0: never)
///   time: {look_s: 2.0, display_look_s: 4.0, nudge_s: 5.5}   # [s]
/// @endcode
/// Threading: an EmulatedUser is immutable after construction; Align is const and draws its
/// randomness from the trial seed, so trials may run on several threads.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "geometry/camera_model.h"
#include "sim/robot_model.h"

namespace YAML {
class Node;  // yaml-cpp, declared only: the .cc files that read YAML include it
}  // namespace YAML

namespace orbed::hmd {

/// The default X_RV_start: the virtual robot shown 10-15 cm and a few degrees from the real base,
/// position [0.10, -0.08, 0.05] m, roll-pitch-yaw [2.0, -1.5, 4.0] deg (sim::RotationFromRpyDeg).
Eigen::Isometry3d DefaultStartOffset();

struct UserConfig {
  std::uint64_t seed{1};  ///< the person
  // Direct view (see-through display).
  double lateral_noise_arcmin{1.5};
  double lateral_bias_arcmin{1.0};
  double depth_bias_fraction_std{0.014};
  double depth_user_bias_fraction_std{0.006};
  double depth_noise_fraction_std{0.004};
  double user_scale_log_sigma{0.45};
  /// The person does not see small differences in the hologram's overall size, in the direct view
  /// and in each display: the perspective scale change that a shift along the line of sight causes
  /// is not taken as misalignment.
  bool size_blind{true};
  // Perception limits: the see-through display's field of view (horizontal, vertical) [deg] and
  // whether the robot hides parts of itself.
  double fov_h_deg{30.0};
  double fov_v_deg{17.5};
  bool occlusion{true};
  // What the person believes their perception is worth (weights of the least squares).
  double assumed_lateral_arcmin{2.0};
  double assumed_depth_fraction{0.02};
  // Nudging.
  double gain{0.6};
  double motor_noise_fraction{0.15};
  /// Hand-motor noise that does not scale with the nudge: each nudge lands this far off per axis
  /// (translation [mm], rotation [deg] about the pivot), e.g. the jitter of releasing a drag.
  double motor_noise_translation_mm{0.5};
  double motor_noise_rotation_deg{0.5};
  int max_nudges{40};
  double stop_lateral_arcmin{3.0};
  double stop_depth_fraction{0.01};
  double min_step_m{0.001};
  double min_step_deg{0.1};
  /// The person gives up ("gave_up") after this many nudges in a row that did not
  /// make what they see better (the largest perceived discrepancy over its threshold); 0: never.
  int patience_nudges{2};
  // Time.
  double look_time_s{2.0};
  double display_look_time_s{4.0};
  double nudge_time_s{5.5};
  // The virtual robot's known starting offset from the real base, X_RV0 (used by StartPose).
  Eigen::Isometry3d X_RV_start{DefaultStartOffset()};
};

/// Reads the `user:` mapping over `base` (key by key: a key that the mapping does not have keeps
/// base's value, e.g. a start_offset with only rpy_deg keeps base's position); every key optional
/// and checked. The default base is the defaults above.
UserConfig ParseUserConfig(const YAML::Node& node, const std::string& source, const std::string& key = "user",
                           const UserConfig& base = UserConfig{});
/// Loads the `user:` mapping of a YAML file (e.g. hmd_emulator/config/user.yaml).
UserConfig LoadUserConfigFile(const std::string& path);
inline constexpr const char* kDefaultUserConfigRelativePath = "hmd_emulator/config/user.yaml";

/// A solid of the robot as a line of sight meets it: the segment [p_RA, p_RB] swept by a ball of
/// radius_m, in R. Spheres, capsules and cylinders are exact or (cylinders) rounded at the ends;
/// a box is its centre segment along its longest axis swept by half its middle extent.
struct SightSolid {
  Eigen::Vector3d p_RA{Eigen::Vector3d::Zero()};
  Eigen::Vector3d p_RB{Eigen::Vector3d::Zero()};
  double radius_m{0};
};
/// The collision primitives of every link at q as sight solids. Throws on a wrong q size.
std::vector<SightSolid> RobotSightSolids(const sim::RobotModel& model, const Eigen::VectorXd& q_rad);
/// Whether p_R can be seen from p_R_eye (both in R): the sight line between them passes through no
/// solid that does not itself contain p_R (a point inside a link is seen on that link's surface).
bool SeenPast(const std::vector<SightSolid>& solids_R, const Eigen::Vector3d& p_R_eye,
              const Eigen::Vector3d& p_R);

/// The reversed frustum's D for a frame captured with the camera at X_WC: the depth in front of the
/// camera of the model points' centroid [m] (at least 0.1 m). The live display takes the gaze ray's
/// hit on the robot instead (image_pipeline.h); toward the robot's middle they differ by about a
/// link's radius.
double CaptureGazeDistance(const Eigen::Isometry3d& X_WC, const Eigen::Isometry3d& X_WR,
                           const std::vector<Eigen::Vector3d>& p_RQ);

/// Points on the robot in its base frame R at joint vector q: each link origin and the centre and
/// axis end points of each collision primitive. Throws std::invalid_argument on a wrong q size.
std::vector<Eigen::Vector3d> RobotModelPoints(const sim::RobotModel& model, const Eigen::VectorXd& q_rad);

/// One reflective display as it stands during the trial: the frame it shows was captured with the
/// camera truly at X_WC_true and stamped X_WC_est (the estimate at capture time).
struct ReflectiveDisplayView {
  geometry::Intrinsics intrinsics;
  Eigen::Isometry3d X_WC_true{Eigen::Isometry3d::Identity()};
  Eigen::Isometry3d X_WC_est{Eigen::Isometry3d::Identity()};
  /// Gaze distance D of the reversed frustum [m]: the panel stands D/2 in front of the capture
  /// camera and shows the image at scale s = D/2 (its size and, with the eye's distance, its
  /// angular resolution).
  double D_m{1.5};
};

/// How an eye at p_W_eye sees a display's panel, turned toward its centre: the panel stands D/2 in
/// front of the capture camera as the device places it (at A · X_WC_est, A the apparent-pose map
/// of ViewingContext), faces the eye L = distance_m away and shows pixel offsets at s / f metres
/// per px (s = D/2), so one radian at the eye is L·f/s camera px; the field of view (fov_*_deg)
/// takes in tan(fov/2)·L·f/s px either side of the image centre.
struct PanelView {
  double distance_m{0};                                   ///< L [m]
  Eigen::Vector2d px_per_rad{Eigen::Vector2d::Zero()};    ///< (u, v) [camera px / rad]
  Eigen::Vector2d half_view_px{Eigen::Vector2d::Zero()};  ///< (u, v) [camera px]
};
/// Throws std::invalid_argument unless D is finite and > 0.
PanelView SeePanel(const ReflectiveDisplayView& display, const Eigen::Isometry3d& A,
                   const Eigen::Vector3d& p_W_eye, double fov_h_deg, double fov_v_deg);

/// Everything that decides what the person sees during one trial.
struct ViewingContext {
  Eigen::Isometry3d X_WR{Eigen::Isometry3d::Identity()};       ///< real robot base (truth)
  Eigen::Isometry3d X_WH_true{Eigen::Isometry3d::Identity()};  ///< head while aligning
  Eigen::Isometry3d X_WH_est{Eigen::Isometry3d::Identity()};   ///< the device's estimate then
  std::vector<ReflectiveDisplayView> displays;                 ///< empty: AR only
  /// The robot's solids in R at the trial's q (RobotSightSolids); empty: nothing is hidden.
  std::vector<SightSolid> solids_R;
};

/// The hologram's pose (map coordinates) from t_s on, t_s from the start of an alignment [s].
struct TimedPose {
  double t_s{0};
  Eigen::Isometry3d X_WV{Eigen::Isometry3d::Identity()};
};

struct AlignmentResult {
  Eigen::Isometry3d X_WV{Eigen::Isometry3d::Identity()};  ///< chosen pose, map coordinates
  double duration_s{0};
  /// The hologram through the alignment: X_WV_start at 0, then each nudge's result from the time
  /// it was done (ascending t_s; the last one is X_WV).
  std::vector<TimedPose> poses;
  /// Where the hologram is t_s into the alignment (the last of `poses` at or before t_s).
  Eigen::Isometry3d X_WV_at(double t_s) const;
  int nudges{0};
  /// "aligned" (thresholds met), "no_visible_improvement" (step below min_step), "gave_up"
  /// (patience_nudges nudges in a row without a better look), "max_nudges", "nothing_in_view" (no
  /// model point in the field of view, unhidden).
  std::string stop_reason;
  /// At the last look: RMS of the perceived lateral [arcmin] and depth [fraction of ρ] discrepancy in
  /// the direct view, and of the display discrepancy as the eye sees it on the panels [arcmin] (0
  /// without displays).
  double perceived_lateral_arcmin{0};
  double perceived_depth_fraction{0};
  double perceived_display_arcmin{0};
  int direct_points_seen{0};   ///< model points compared in the direct view at the last look
  int display_points_seen{0};  ///< model points compared in the display(s) at the last look
};

class EmulatedUser {
 public:
  /// Draws the person (depth-error scale and personal depth bias) from config.seed.
  explicit EmulatedUser(const UserConfig& config);

  /// One trial from X_WV_start (map coordinates). p_RQ: model points (RobotModelPoints), the same on
  /// the real and the virtual robot. trial_seed: the trial's own randomness.
  AlignmentResult Align(const ViewingContext& context, const std::vector<Eigen::Vector3d>& p_RQ,
                        const Eigen::Isometry3d& X_WV_start, std::uint64_t trial_seed) const;

  /// Whether the person sees the hologram move when it jumps from where it appeared
  /// (X_WV_apparent_before) to X_WV_apparent_after (e.g. at a relocalization), looking from
  /// p_W_eye: the model centroid moved across the line of sight by more than stop_lateral_arcmin
  /// or along it by more than stop_depth_fraction of the viewing distance, the very discrepancies
  /// at which the person would not have stopped aligning.
  bool SeesHologramMove(const Eigen::Isometry3d& X_WV_apparent_before,
                        const Eigen::Isometry3d& X_WV_apparent_after,
                        const std::vector<Eigen::Vector3d>& p_RQ, const Eigen::Vector3d& p_W_eye) const;

  /// X_WV_start = X_WR_nominal · X_RV_start: the virtual robot shown at its known offset.
  Eigen::Isometry3d StartPose(const Eigen::Isometry3d& X_WR_nominal) const {
    return X_WR_nominal * config_.X_RV_start;
  }

  const UserConfig& config() const { return config_; }
  double depth_scale() const { return depth_scale_; }                   ///< s
  double depth_user_bias_fraction() const { return depth_user_bias_; }  ///< β_user

 private:
  UserConfig config_;
  double depth_scale_{1};
  double depth_user_bias_{0};
};

/// The error of a virtual robot pose X_WV_cmp (map coordinates, or an apparent pose) against the
/// real one, on the model points: the centroid's displacement e [m] split along the viewing ray from
/// p_W_eye to the real centroid and across it, the base origin's displacement, the rotation angle,
/// and the mean point displacement.
struct PoseError {
  Eigen::Vector3d centroid_error_W_m{Eigen::Vector3d::Zero()};
  double translation_error_m{0};       ///< ‖e‖ at the model centroid
  double along_ray_m{0};               ///< |e · n|
  double lateral_m{0};                 ///< ‖e − (e · n) n‖
  double base_translation_error_m{0};  ///< ‖p_WV − p_WR‖
  double rotation_error_deg{0};
  double mean_point_error_m{0};
};
PoseError EvaluatePose(const Eigen::Isometry3d& X_WV_cmp, const Eigen::Isometry3d& X_WR,
                       const std::vector<Eigen::Vector3d>& p_RQ, const Eigen::Vector3d& p_W_eye);

}  // namespace orbed::hmd
