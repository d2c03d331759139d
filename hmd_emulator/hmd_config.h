#pragma once
/// @file
/// The configuration of the orbed-hmd process, read from one or more YAML files. Each file may hold
/// any of four top-level mappings (unknown top-level keys are errors naming the file):
///   slam:            the SLAM error model          (slam_model.h,      config/slam.yaml)
///   user:            the emulated ViRAAl user      (user_model.h,      config/user.yaml)
///   head_trajectory: the wearer's walk             (head_trajectory.h, config/viraal_walk.yaml)
///   hmd:             the process itself (below)    (this file,         config/hmd.yaml)
/// Files are applied in order over the compiled-in defaults (which equal the shipped files, except
/// the waypoint names of hmd: below; a walk comes from a file only). The
/// slam:, user: and hmd: mappings merge key by key: a later file changes only the keys it has, so
/// `user: {seed: 7}` makes a different person and keeps the start offset, the beliefs and all the
/// rest of the earlier files (a list value, such as hmd.displays, is replaced as a whole). A
/// head_trajectory: mapping replaces the walk as a whole (its speed, target and waypoints belong
/// together). orbed-hmd loads the four shipped files first, then every --config file.
///
/// The `hmd:` mapping: every key optional and checked; an absent key keeps the HmdConfig default,
/// which is the value written here and the value config/hmd.yaml ships (hmd_config_test.cc checks
/// that the three agree), except the two that name waypoints of a walk: the defaults follow
/// whatever walk is loaded, config/hmd.yaml names the shipped walk's (align_waypoint: head_end,
/// its last, and two displays: `displays: [{capture_waypoint: foot_end}, {capture_waypoint:
/// head_end}]`, the second being the negative control that adds no viewpoint).
/// @code{.yaml}
/// hmd:
///   name: hololens1              # hmd_name on HMD_POSE and GAZE_RAY
///   gaze_hz: 10                  # GAZE_RAY rate [Hz], 0.1 .. 1000
///   reflective_hz: 30            # REFLECTIVE_VIEW rate per display [Hz], 0.1 .. 1000 (above what
///                                #   the renderer keeps up with, requests are dropped and counted)
///   ar_view_hz: 5                # AR_VIEW rate [Hz], 0.1 .. 1000 (likewise)
///   align_waypoint: ""           # where the emulated user aligns ("" = the walk's last waypoint)
///   settle_s: 0.5                # standing time at the alignment waypoint before aligning [s]
///   max_wait_s: 30               # longest wait for tracking to recover before aligning [s]
///   max_repeats: 2               # alignments re-done at most per trial after a hologram jump
///   recapture_period_s: 0.5      # a display re-captures at most this often after the robot moved [s]
///   gaze_fallback_distance_m: 1.5  # D when the gaze ray misses the robot [m]
///   max_gaze_distance_m: 10      # ray-casting range [m]
///   # Landmark annotation after each emulated trial (viraal_trial.h, annotation.h): the links
///   # whose origins the person marks on the real robot and on the hologram ([] = none), in order.
///   annotation_landmarks: [iiwa_link_4, iiwa_link_6, iiwa_link_ee]
///   annotation_pointing_std_deg: 0.2   # head-gaze pointing error per axis [deg]
///   annotation_dwell_s: 1.0            # cursor held on a landmark before the tap [s]
///   annotation_view_angle_deg: 40      # between the lines of sight of the two positions [deg]
///   annotation_walk_speed_m_per_s: 0.5 # speed of that step [m/s]
///   session_start_m: [2.6, 0.3, 1.7]  # where the person puts the headset on: the map's origin [m]
///   # displays: a list of {capture_waypoint: NAME}, where each reflective display captures its
///   # frame, in order; default (absent): one display at the walk's first waypoint.
///   # collaborator: {waypoint: NAME, colocalization_translation_mm: T, colocalization_rotation_deg: R}
///   #   a second person's headset, standing at that waypoint of the walk, serves as the first
///   #   reflective display with its live frames (CollaboratorDisplay, viraal_trial.h; the mapping
///   #   is replaced as a whole); default (absent): none.
/// @endcode
/// Display i is placed at (captures its frame from) the camera pose at the arrival at its waypoint of
/// the walk: live, and in every emulated trial that uses >= i + 1 displays.
///
/// Threading: plain data; the loaders are reentrant.

#include <string>
#include <vector>

#include "hmd_emulator/head_trajectory.h"
#include "hmd_emulator/slam_model.h"
#include "hmd_emulator/user_model.h"
#include "hmd_emulator/viraal_trial.h"

namespace YAML {
class Node;  // yaml-cpp, declared only: the .cc files that read YAML include it
}  // namespace YAML

namespace orbed::hmd {

struct DisplayPlacement {
  std::string capture_waypoint;  ///< a waypoint name of the walk
};

struct HmdConfig {
  std::string name{"hololens1"};
  double gaze_hz{10.0};
  double reflective_hz{30.0};
  double ar_view_hz{5.0};
  std::string align_waypoint;  ///< "" = the walk's last waypoint
  double settle_s{0.5};
  double max_wait_s{30.0};
  int max_repeats{2};  ///< TrialSetup::max_repeats (viraal_trial.h)
  double recapture_period_s{0.5};
  double gaze_fallback_distance_m{1.5};
  double max_gaze_distance_m{10.0};
  /// Empty after parsing a file without `displays` = one display at the walk's first waypoint.
  std::vector<DisplayPlacement> displays;
  /// Landmark annotation (TrialSetup::p_RL, annotation_*): link names of the robot model.
  std::vector<std::string> annotation_landmarks{"iiwa_link_4", "iiwa_link_6", "iiwa_link_ee"};
  double annotation_pointing_std_deg{0.2};
  double annotation_dwell_s{1.0};
  double annotation_view_angle_deg{40.0};
  double annotation_walk_speed_m_per_s{0.5};
  /// Where the person puts the headset on, the session map's origin (SessionMapAtTrial) [m, W].
  Eigen::Vector3d session_start_m{2.6, 0.3, 1.7};
  CollaboratorDisplay collaborator;  ///< waypoint "" = none
};

/// The most landmarks a person annotates per trial (ALIGNMENT_TRIAL carries 4 rays per landmark).
inline constexpr int kMaxAnnotationLandmarks = 16;

/// Reads the `hmd:` mapping (the node itself) over `base`, key by key (a `displays` list replaces
/// base's list); errors name `source`, the line and the key.
HmdConfig ParseHmdConfig(const YAML::Node& node, const std::string& source, const std::string& key = "hmd",
                         const HmdConfig& base = HmdConfig{});

/// Everything orbed-hmd is configured by.
struct HmdConfigSet {
  SlamConfig slam;
  UserConfig user;
  HeadTrajectoryConfig walk;
  HmdConfig hmd;
  std::vector<std::string> sources;  ///< files read, in order
};

/// The same person around another arm: every point of the config in W (the walk's waypoints and
/// look-at targets, the session map's origin) carried by the rigid motion X_WW' (p -> X p), e.g.
/// X_WR_arm X_WR_single^-1 to walk around the arm at X_WR_arm the walk written for X_WR_single.
HmdConfigSet MovedBy(const Eigen::Isometry3d& X, HmdConfigSet config);

/// Loads `paths` in order (see the file comment: merged key by key), then resolves and
/// checks the cross references: an empty display list becomes one display at the walk's first
/// waypoint, an empty align_waypoint the walk's last; every waypoint named must exist in the walk
/// (std::runtime_error naming the file that set it). A walk must come from some file.
HmdConfigSet LoadHmdConfigs(const std::vector<std::string>& paths);

/// The shipped files, relative to the repository root, in load order.
std::vector<std::string> DefaultHmdConfigRelativePaths();

/// `relative` under $ORBED_SOURCE_DIR if set, else under the source tree this library was built from.
std::string HmdSourcePath(const std::string& relative);

}  // namespace orbed::hmd
