#pragma once
/// @file
/// The emulated set-up assistant (paper Sec. II-B, IV-B, Fig. 4 c-e): a person who moves the real
/// arm joint by joint, from the base to the flange, until it looks like the target configuration
/// shown to them. The core, without a bus or a clock: what the person sees, where they stop a
/// joint, and how long it takes them.
///
/// What is visible. The person judges joint j by the bodies it moves nearest: the rigid body it
/// drives (B_j) and the next one (B_j+1), each drawn as its collision skeleton: sphere centres,
/// cylinder and capsule end centres, box corners, plus an off-axis mark on the flange
/// (`flange_marker_offset_m`: the iiwa's media flange has its connector at one side). A body whose
/// skeleton lies on the joint's axis shows nothing of that joint's angle: the iiwa's links 1, 3, 5
/// and 7 are such bodies, so their twisting joints show only through B_j+1, which sticks out of the
/// axis only as far as the next (revolving) joint is bent. Nothing here says "twisting joints are
/// harder": the geometry does. With the next joint bent the other way in the real arm than in the
/// target, the best match of a twisting joint is half a turn away from the target (the iiwa's
/// q_j + π, −q_j+1 gives the same elbow line): the wrong-way errors of 180° and more.
///
/// What the person perceives, per look (PerceiveTarget). Real points r = X_WR · X_RL(q) · p are
/// seen as they are; the noise of comparing a real point with a target point is put on the target
/// point. The target's points are seen
///  - in the headset (MODE_AR, MODE_AR_REFLECTIVE): as the hologram, h = X_WV_seen · X_RL(q_t) · p,
///    with X_WV_seen the pose at which the virtual base appears in the world (the registration the
///    person was given times the SLAM error at that moment: user_model.h's A · X_WV), perceived
///    from the eye p_WE with lateral noise ρ·σ_lat (two components across the line of sight, ρ the
///    distance) and depth noise ρ·σ_depth along it, per point and look;
///  - in MODE_AR_REFLECTIVE also in the reflective display (hmd_emulator/reflective.h), when the
///    view names one (Viewing::p_WC_display): the display shows the live arm (orbed-hmd re-renders
///    its frame from the frozen capture pose at most every hmd.recapture_period_s after the arm
///    moved; the person looks with the arm at rest) and the hologram at the target drawn at the
///    registration (Viewing::X_WV_display), both as the capture camera at p_WC saw them. A look
///    reads each point there with noise ρ_C·σ_disp across the capture camera's rays and
///    ρ_C·σ_disp_depth along them (ρ_C the distance from p_WC: a picture has no depth of its own);
///    what is depth from the eye is lateral there;
///  - on the fixed monitor (MODE_FIXED_DISPLAY): as a picture rendered from the monitor's camera p_WD
///    (FIXED_VIEW's camera when orbed-fixed-display publishes one, else `monitor.camera_m`; turned
///    by the person, below), which the person must turn into their own view: a mental rotation
///    about the vertical through the base by δψ ~ N(0, σ_rot(θ)) and a scale k = exp(N(0, σ_scale))
///    about the base, per look, then per-point noise ρ_D·σ_pic across and ρ_D·σ_pic_depth along
///    the monitor camera's rays. θ is the horizontal angle between the monitor's camera and the eye
///    seen from the base (MonitorDisparityDeg); σ_rot(θ) = `rotation_error_base_deg` +
///    `rotation_error_per_deg` · θ (perspective taking errs more the further the imagined
///    viewpoint is from one's own: Kozhevnikov & Hegarty, Mem. Cogn. 29(5), 2001).
/// The person's noise scales by s, drawn once per person (log-normal, median 1, `user_scale_log_sigma`).
///
/// Turning the monitor's view (PlanMonitorView, once per set-up before the first joint). When θ
/// exceeds `turn_view_above_deg` the person orbits the monitor's view about the vertical through
/// the base towards their own side until `turn_view_leaves_deg` is left, at `view_turn_deg_per_s`;
/// when the camera is farther from the base than the eye they zoom it in to the eye's distance
/// (`view_zoom_s`): the picture's noise ρ_D shrinks with it.
///
/// Where they stop. For a look at joint j with the arm at q_now, the person scores every angle
/// x of joint j on a grid (kGridStepDeg, within the joint's limits and `window_rad` of q_now) by
///   D(x) = Σ_p d_pᵀ W_p d_p  (+ the same sum over the display's points, with W_p^C),
///   d_p = r_p(x) − h'_p,   W_p = (I − n_p n_pᵀ)/(ρ_p σ_lat)² + n_p n_pᵀ/(ρ_p σ_depth)²
/// (r_p(x): the real point with joint j at x and the others at q_now; h'_p the target point as
/// perceived, where it appears; n_p the unit ray from the eye to r_p, ρ_p its length; W_p^C the
/// same with the capture camera's ray and σ_disp, σ_disp_depth; σ the configured, unscaled noises:
/// what the person believes of their own eyes). Every x with D(x) ≤ min D + `match_margin` looks
/// right; the person aims at the nearest such x to where the joint is (`choice: nearest`) or at
/// the best one (`choice: best`), and the hand puts it there with noise N(0, s·placement_noise_deg).
/// The angles that look right form `ranges` separate ranges: two for a half-turn ambiguity, one
/// wide range (no cue at all) when the joint moves nothing visible.
///
/// The registration, to first order. The person compares the real arm with the hologram where it
/// appears, so an error of the registration reaches the joints. Take joint j with the others at
/// the target q_t, the hologram displaced by e_p: h'_p = r_p(q_t) + e_p (e_p = t for a translation
/// t; e_p = (R − I)(h_p − c) ≈ θ × (h_p − c) for a small rotation θ (axis times angle) about a
/// point c). For x = q_t + δ, r_p(x) = r_p(q_t) + a_p δ + ½ b_p δ² + O(δ³) with
/// a_p = w_j × (r_p − o_j) (w_j the joint's unit axis in W, o_j a point on it: the point's velocity
/// per radian) and b_p = w_j × a_p (|b_p| = |a_p|). So d_p = a_p δ − e_p + ½ b_p δ², and
///   dD/dδ = 2 Σ_p (a_p + b_p δ)ᵀ W_p (a_p δ − e_p + ½ b_p δ²) + Σ_p d_pᵀ (dW_p/dδ) d_p = 0.
/// Keeping the terms of first order in (δ, e):
///   δ_j = Σ_p a_pᵀ W_p e_p / Σ_p a_pᵀ W_p a_p.
/// The remainder: the b_p terms add δ Σ b_pᵀ W_p (a_p δ − e_p) + ½ δ² Σ a_pᵀ W_p b_p to the
/// numerator; with |b_p| = |a_p| = L_p (the point's distance from the axis) they move δ by at most
/// about |δ_j| (|δ_j| + max_p |e_p| / L_min) (L_min the smallest lever of a point with weight),
/// and W_p changes along the path by a relative O(|e|/ρ), second order once multiplied by the
/// residual d_p. A translation along w_j, or any e_p the joint cannot produce, leaves a residual
/// but moves δ only through these terms. Then the grid (half a step) and the margin: with noises
/// made tiny the looks-right set is one grid point. assistant_test checks δ_j on every joint.
///
/// Time (Table 4's execution time): per joint, `joint_overhead_s`, then per look `look_s`; on the
/// fixed monitor plus the mental rotation of the picture into the person's view at
/// `mental_rotation_deg_per_s` over θ (Shepard & Metzler 1971: time grows linearly with the angle)
/// and, once per set-up, the view's turn and zoom (above); in MODE_AR_REFLECTIVE with a display plus
/// `display_consult_s` per look (the gaze to the display panel, its fixations and back); and the
/// hand's travel |Δq| at `hand_speed_deg_per_s`; all of it times the person's pace p, drawn once
/// per person from its own stream (seeded by SplitMix64 of the seed, so the pace changes no other
/// draw): log-normal with mean 1, p = exp(σ z − σ²/2), σ = `pace_log_sigma`.
///
/// Frames: W world, R real base, V virtual base (as seen), L links, E eye, C the reflective
/// display's capture camera, D monitor camera. Units: m, rad inside; arcmin, deg, s where the name
/// says so. Threading: an Assistant is a value with its own random stream; one thread uses it.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "base/random.h"
#include "sim/robot_model.h"

namespace orbed::assistant {

/// Grid of the angles a person considers [deg] (finer than anyone turns a joint by hand).
inline constexpr double kGridStepDeg = 0.25;

/// Which of the angles that look right the person turns the joint to (file comment).
enum class Choice { kNearest, kBest };

/// Every parameter, loaded from procs/assistant/assistant.yaml (sources beside each value there;
/// docs/parameters.md lists them). The defaults here are that file's values (a test checks).
struct AssistantConfig {
  uint64_t seed{1};                                 ///< the person
  Eigen::Vector3d eye_position_m{0.9, -1.3, 1.65};  ///< p_WE when no headset pose says otherwise
  double user_scale_log_sigma{0.3};
  // Seeing the hologram (headset modes).
  double lateral_noise_arcmin{4.0};
  double depth_noise_fraction_std{0.02};
  // Seeing the reflective display (MODE_AR_REFLECTIVE).
  Eigen::Vector3d display_capture_m{1.45, -1.20, 1.70};  ///< p_WC of display 0 (hmd.yaml, viraal_walk.yaml)
  double display_noise_arcmin{4.0};
  double display_depth_fraction_std{0.1};
  // Seeing the fixed monitor's picture.
  Eigen::Vector3d monitor_camera_m{1.5, 0.3, 1.8};  ///< p_WD, the picture's viewpoint
  double rotation_error_base_deg{3.0};              ///< σ_rot at θ = 0
  double rotation_error_per_deg{0.15};              ///< σ_rot's growth per degree of θ
  double picture_scale_log_sigma{0.1};
  double picture_noise_arcmin{10.0};
  double picture_depth_fraction_std{0.1};
  double turn_view_above_deg{45.0};   ///< the person turns the monitor's view when θ exceeds this
  double turn_view_leaves_deg{15.0};  ///< ... until this much is left
  // Deciding and acting.
  double match_margin{4.0};            ///< D units (a sum of squared z-scores)
  int looks_per_joint{2};              ///< the first look from anywhere, then corrections
  double correction_window_deg{30.0};  ///< how far a correcting look searches around the joint
  double placement_noise_deg{1.0};
  double flange_marker_offset_m{0.045};
  Choice choice{Choice::kNearest};
  // Time.
  double joint_overhead_s{4.0};
  double look_s{3.0};
  double mental_rotation_deg_per_s{60.0};
  double view_turn_deg_per_s{90.0};
  double view_zoom_s{1.0};
  double display_consult_s{1.5};
  double hand_speed_deg_per_s{15.0};
  double pace_log_sigma{0.59};  ///< person-to-person spread of every time (log-normal, mean 1)
};

/// Reads the `assistant:` mapping of a YAML file (every key optional, checked: ranges, units);
/// throws std::runtime_error naming the file and key.
AssistantConfig LoadAssistantConfig(const std::string& path);
/// The shipped file, relative to the repository root.
inline constexpr char kDefaultConfigRelativePath[] = "procs/assistant/assistant.yaml";

/// Where the person looks from and where the target appears.
struct Viewing {
  int8_t mode{0};  ///< guidance_t::MODE_AR, MODE_AR_REFLECTIVE or MODE_FIXED_DISPLAY
  Eigen::Isometry3d X_WR{Eigen::Isometry3d::Identity()};       ///< the real base (truth)
  Eigen::Isometry3d X_WV_seen{Eigen::Isometry3d::Identity()};  ///< headset modes: the hologram's base
  Eigen::Vector3d p_WE{Eigen::Vector3d::Zero()};               ///< the eye
  /// MODE_AR_REFLECTIVE: the reflective display's capture viewpoint p_WC; none: no display to
  /// consult (the look is the headset's alone, as in MODE_AR).
  std::optional<Eigen::Vector3d> p_WC_display;
  /// The hologram's base as the display draws it: the registration (the SLAM error at the frame's
  /// capture is not on the bus; the headset's error now is not the display's).
  Eigen::Isometry3d X_WV_display{Eigen::Isometry3d::Identity()};
  /// The fixed monitor's camera p_WD as FIXED_VIEW shows it (orbed-fixed-display: the view a user
  /// turned) or as the person turned it (PlanMonitorView); none: the config's monitor_camera_m.
  std::optional<Eigen::Vector3d> p_WD;
};

/// One look at a joint and the hand's move.
struct JointLook {
  double q_rad{0};    ///< where the hand put the joint (within its limits)
  double aim_rad{0};  ///< where the person meant to put it (before the hand's noise)
  int ranges{0};      ///< separate ranges of angles that looked right
  /// (look_s + the mental rotation on the monitor + the display's consult) times the pace.
  double time_s{0};
};

/// A point of a body's skeleton in its link frame.
struct Feature {
  int link{-1};
  Eigen::Vector3d p_L{Eigen::Vector3d::Zero()};
};

/// The target's points of features(joint) in W as one look perceives them.
struct Perceived {
  std::vector<Eigen::Vector3d> eye;      ///< the hologram from the eye, or the monitor's picture
  std::vector<Eigen::Vector3d> display;  ///< the hologram in the reflective display; empty: none
};

/// How the person set the monitor's view before the first joint (PlanMonitorView).
struct MonitorTurn {
  Eigen::Vector3d p_WD{Eigen::Vector3d::Zero()};  ///< the camera after the turn and zoom
  double turned_deg{0};                           ///< the orbit about the vertical through the base
  bool zoomed{false};
  double time_s{0};  ///< (turned_deg / view_turn_deg_per_s + view_zoom_s if zoomed) times the pace
};

class Assistant {
 public:
  /// Throws std::invalid_argument on a config out of range (LoadAssistantConfig's ranges).
  Assistant(const sim::RobotModel& model, const AssistantConfig& config);

  /// One look at joint `joint` (0-based) with the arm at q_now, the target q_target [rad]; searches
  /// within `window_rad` of q_now (infinity: the whole range).
  JointLook Look(int joint, const Eigen::VectorXd& q_now, const Eigen::VectorXd& q_target,
                 const Viewing& view, double window_rad);

  /// The perceived discrepancy D(x) of the file comment (exposed for tests).
  double Discrepancy(int joint, double x_rad, const Eigen::VectorXd& q_now, const Perceived& seen,
                     const Viewing& view) const;

  /// The skeleton joint `joint` is judged by (B_j and B_j+1).
  const std::vector<Feature>& features(int joint) const { return features_[joint]; }
  /// The target's points of features(joint) as this look perceives them (draws the look's noise).
  Perceived PerceiveTarget(int joint, const Eigen::VectorXd& q_target, const Viewing& view);
  /// The time of the hand's travel |delta_rad| [s].
  double TravelTime_s(double delta_rad) const;
  /// The time per joint before its looks: joint_overhead_s times the pace.
  double JointOverhead_s() const { return pace_ * config_.joint_overhead_s; }
  /// The person's pace p (the file comment): every time of theirs is p times the model's.
  double pace() const { return pace_; }
  /// Horizontal angle θ between the monitor's camera and the eye, seen from the base [deg].
  double MonitorDisparityDeg(const Viewing& view) const;
  /// σ_rot(θ) of the mental rotation, before the person's scale [deg].
  double RotationErrorStdDeg(double disparity_deg) const;
  /// The turn and zoom of the monitor's view the person makes (file comment); none needed: the
  /// camera as it is, time 0.
  MonitorTurn PlanMonitorView(const Viewing& view) const;

  const AssistantConfig& config() const { return config_; }
  double person_scale() const { return scale_; }

 private:
  const sim::RobotModel* model_;
  AssistantConfig config_;
  Random rng_;
  double scale_{1.0};
  double pace_{1.0};
  std::vector<std::vector<Feature>> features_;
  std::vector<int> last_link_;  // per joint: the highest link index of its features

  // D(x) of the file comment from the link poses X_RL of x (Discrepancy's sum).
  double DiscrepancyAt(int joint, const std::vector<Eigen::Isometry3d>& X_RL, const Perceived& seen,
                       const Viewing& view) const;
};

}  // namespace orbed::assistant
