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
/// What the person perceives, per look. Real points r = X_WR · X_RL(q) · p are seen as they are.
/// The target's points are seen
///  - in the headset (MODE_AR, MODE_AR_REFLECTIVE): as the hologram, h = X_WV_seen · X_RL(q_t) · p,
///    with X_WV_seen the pose at which the virtual base appears in the world (the registration and
///    the SLAM error at that moment: user_model.h's A · X_WV), perceived from the eye p_WE with
///    lateral noise ρ·σ_lat (two components across the line of sight, ρ the distance) and depth
///    noise ρ·σ_depth along it, per point and look;
///  - on the fixed monitor (MODE_FIXED_DISPLAY): as a picture rendered from the monitor's camera p_WD
///    (FIXED_VIEW's camera when orbed-fixed-display publishes one, else `monitor.camera_m`), which
///    the person must turn into their own view: a mental rotation about the vertical through the
///    base by δψ ~ N(0, σ_rot) and a scale k = exp(N(0, σ_scale)) about the base, per look, then
///    per-point noise ρ_D·σ_pic across and ρ_D·σ_pic_depth along the monitor camera's rays (a
///    picture has no depth of its own).
/// The person's noise scales by s, drawn once per person (log-normal, median 1, `user_scale_log_sigma`).
///
/// Where they stop. For a look at joint j with the arm at q_now, the person scores every angle
/// x of joint j on a grid (kGridStepDeg, within the joint's limits and `window_rad` of q_now) by
///   D(x) = Σ_p |lateral(d_p)|² / (ρ_p σ_lat)² + (n_p · d_p)² / (ρ_p σ_depth)²,
///   d_p = (r_p(x) − r_0) − (h'_p − h'_0)
/// (r_p(x): the real point with joint j at x and the others at q_now; r_0, h'_0 the joint itself on
/// the real arm and as perceived on the target: people judge which way a link points from its joint,
/// so a shift of the whole hologram is no reason to turn a joint, a tilt is; n_p the unit ray from
/// the eye to r_p; σ the configured, unscaled noises: what the person believes of their own eyes). Every x
/// with D(x) ≤ min D + `match_margin` looks right; the person turns the joint from where it is to
/// the nearest such x, and the hand puts it there with noise N(0, s·placement_noise_deg). The
/// angles that look right form `ranges` separate ranges: two for a half-turn ambiguity, one wide
/// range (no cue at all) when the joint moves nothing visible.
///
/// Time (Table 4's execution time): per joint, `joint_overhead_s`, then per look `look_s`, on the
/// fixed monitor plus the mental rotation of the picture into the person's view, at
/// `mental_rotation_deg_per_s` over the horizontal angle between the monitor's camera and the eye
/// seen from the base (Shepard & Metzler 1971: time grows linearly with the angle), and the hand's
/// travel |Δq| at `hand_speed_deg_per_s`; all of it times the person's pace p, drawn once per person
/// from its own stream (seeded by SplitMix64 of the seed, so the pace changes no other draw):
/// log-normal with mean 1, p = exp(σ z − σ²/2), σ = `pace_log_sigma`.
///
/// Frames: W world, R real base, V virtual base (as seen), L links, E eye, D monitor camera.
/// Units: m, rad inside; arcmin, deg, s where the name says so.
/// Threading: an Assistant is a value with its own random stream; one thread uses it.

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

/// Every parameter, loaded from procs/assistant/assistant.yaml (sources beside each value there;
/// docs/parameters.md lists them). The defaults here are that file's values (a test checks).
struct AssistantConfig {
  uint64_t seed{1};                                 ///< the person
  Eigen::Vector3d eye_position_m{0.9, -1.3, 1.65};  ///< p_WE when no headset pose says otherwise
  double user_scale_log_sigma{0.3};
  // Seeing the hologram (headset modes).
  double lateral_noise_arcmin{4.0};
  double depth_noise_fraction_std{0.02};
  // Seeing the fixed monitor's picture.
  Eigen::Vector3d monitor_camera_m{1.5, 0.3, 1.8};  ///< p_WD, the picture's viewpoint
  double mental_rotation_std_deg{15.0};
  double picture_scale_log_sigma{0.1};
  double picture_noise_arcmin{10.0};
  double picture_depth_fraction_std{0.1};
  // Deciding and acting.
  double match_margin{4.0};            ///< D units (a sum of squared z-scores)
  int looks_per_joint{2};              ///< the first look from anywhere, then corrections
  double correction_window_deg{30.0};  ///< how far a correcting look searches around the joint
  double placement_noise_deg{1.0};
  double flange_marker_offset_m{0.045};
  // Time.
  double joint_overhead_s{4.0};
  double look_s{3.0};
  double mental_rotation_deg_per_s{60.0};
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
  /// The fixed monitor's camera p_WD as FIXED_VIEW shows it (orbed-fixed-display: the view a user
  /// turned); none: the config's monitor_camera_m.
  std::optional<Eigen::Vector3d> p_WD;
};

/// One look at a joint and the hand's move.
struct JointLook {
  double q_rad{0};    ///< where the hand put the joint (within its limits)
  double aim_rad{0};  ///< where the person meant to put it (before the hand's noise)
  int ranges{0};      ///< separate ranges of angles that looked right
  double time_s{0};   ///< (look_s + the mental rotation on the monitor) times the pace
};

/// A point of a body's skeleton in its link frame.
struct Feature {
  int link{-1};
  Eigen::Vector3d p_L{Eigen::Vector3d::Zero()};
};

class Assistant {
 public:
  /// Throws std::invalid_argument on a config out of range (LoadAssistantConfig's ranges).
  Assistant(const sim::RobotModel& model, const AssistantConfig& config);

  /// One look at joint `joint` (0-based) with the arm at q_now, the target q_target [rad]; searches
  /// within `window_rad` of q_now (infinity: the whole range).
  JointLook Look(int joint, const Eigen::VectorXd& q_now, const Eigen::VectorXd& q_target,
                 const Viewing& view, double window_rad);

  /// The perceived discrepancy D(x) of the file comment for fixed target points (exposed for tests).
  double Discrepancy(int joint, double x_rad, const Eigen::VectorXd& q_now,
                     const std::vector<Eigen::Vector3d>& p_W_target_seen, const Viewing& view) const;

  /// The skeleton joint `joint` is judged by (B_j and B_j+1).
  const std::vector<Feature>& features(int joint) const { return features_[joint]; }
  /// features(joint) and last the joint itself (the child link's origin, on the axis): the pivot.
  std::vector<Feature> FeaturesWithPivot(int joint) const;
  /// The target's points of FeaturesWithPivot in W as this look perceives them (draws the look's
  /// noise).
  std::vector<Eigen::Vector3d> PerceiveTarget(int joint, const Eigen::VectorXd& q_target,
                                              const Viewing& view);
  /// The time of the hand's travel |delta_rad| [s].
  double TravelTime_s(double delta_rad) const;
  /// The time per joint before its looks: joint_overhead_s times the pace.
  double JointOverhead_s() const { return pace_ * config_.joint_overhead_s; }
  /// The person's pace p (the file comment): every time of theirs is p times the model's.
  double pace() const { return pace_; }
  /// Horizontal angle between the monitor's camera and the eye, seen from the base [deg].
  double MonitorDisparityDeg(const Viewing& view) const;

  const AssistantConfig& config() const { return config_; }
  double person_scale() const { return scale_; }

 private:
  const sim::RobotModel* model_;
  AssistantConfig config_;
  Random rng_;
  double scale_{1.0};
  double pace_{1.0};
  std::vector<std::vector<Feature>> features_;
};

}  // namespace orbed::assistant
