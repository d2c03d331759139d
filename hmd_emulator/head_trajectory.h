#pragma once
/// @file
/// The wearer's head path through the OR: waypoints walked at a constant speed, a dwell (standing
/// still) at each, and the head always turned toward a look-at target (the robot by default).
///
/// Frames: W is the OR world (floor z = 0, z up; sim/scene.h). H is the head: origin at the midpoint
/// between the eyes (the cyclopean eye), axes like the camera C: z forward along the line of sight,
/// x to the wearer's right, y down. "Looking at" p_WT means z_H points from p_WH to p_WT with x_H
/// horizontal (roll 0), so y_H points down. Units: m, s.
///
/// Timing: the head starts at waypoint 0 at t = 0, dwells there, walks the straight segment to the
/// next waypoint at speed_m_per_s, dwells, and so on. The look-at target is the waypoint's own
/// (look_at_m) or the trajectory's, and is interpolated linearly along a segment so the head turns
/// smoothly. After the last waypoint the head stays there, or, with loop: true, walks back to
/// waypoint 0 and starts again (period duration_s()).
///
/// YAML (a `head_trajectory:` mapping in a scenario or config file; unknown keys are errors). A
/// mapping read from a file replaces the walk as a whole: speed_m_per_s, look_at_m and waypoints
/// are required there. HeadTrajectoryConfig's initial speed and target are those of the shipped walk
/// below (config/viraal_walk.yaml; slam_model_test.cc checks that they agree):
/// @code{.yaml}
/// head_trajectory:
///   speed_m_per_s: 0.8                # required, > 0 [m/s]
///   look_at_m: [0.25, -0.45, 1.25]    # required: the target the head turns to [m]
///   loop: false                       # optional (default false)
///   waypoints:                        # required, >= 1; name optional (default "waypoint<i>")
///     - {name: foot_end, position_m: [1.45, -1.20, 1.70], dwell_s: 2.0}   # dwell_s optional (0) [s]
///     - {name: head_end, position_m: [-0.75, -1.40, 1.70], dwell_s: 60.0}  # look_at_m optional
/// @endcode
///
/// Threading: immutable after construction; const methods are thread-safe.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "geometry/camera_model.h"  // geometry::LookAt

namespace YAML {
class Node;  // yaml-cpp, declared only: the .cc files that read YAML include it
}  // namespace YAML

namespace orbed::hmd {

struct HeadWaypoint {
  std::string name;
  Eigen::Vector3d p_WH{Eigen::Vector3d::Zero()};  ///< head position [m]
  double dwell_s{0.0};                            ///< time standing here [s], >= 0
  std::optional<Eigen::Vector3d> p_W_look_at;     ///< overrides the trajectory's target
};

struct HeadTrajectoryConfig {
  double speed_m_per_s{0.8};  ///< [m/s], > 0: a slow walk in a crowded OR
  Eigen::Vector3d p_W_look_at{Eigen::Vector3d(0.25, -0.45, 1.25)};  ///< [m]: the robot's middle in trocar_or
  bool loop{false};
  std::vector<HeadWaypoint> waypoints;
};

/// Reads a `head_trajectory` mapping (the node itself, not its parent). `yaml` names the source in
/// errors; `key` is the node's dotted path (e.g. "head_trajectory").
HeadTrajectoryConfig ParseHeadTrajectory(const YAML::Node& node, const std::string& source,
                                         const std::string& key = "head_trajectory");
/// Loads the `head_trajectory:` mapping of a YAML file.
HeadTrajectoryConfig LoadHeadTrajectoryFile(const std::string& path);

class HeadTrajectory {
 public:
  /// Validates (>= 1 waypoint, speed > 0, dwell >= 0, the look-at target neither within 1 mm of
  /// nor straight above or below the head at a waypoint or anywhere along a segment walked, the
  /// loop's closing segment included), so that X_WH() never throws. std::invalid_argument names
  /// the waypoint (or the segment's two waypoints) at fault.
  explicit HeadTrajectory(HeadTrajectoryConfig config);

  /// X_WH_true at time t [s]; t < 0 gives the start; beyond the end the last pose (or, when looping,
  /// t modulo duration_s()).
  Eigen::Isometry3d X_WH(double t_s) const;
  /// The path length walked up to time t [m] (counting every lap when looping).
  double PathLength(double t_s) const;
  /// One pass: dwell + walk times [s], and its path length [m] (including the closing segment when
  /// looping).
  double duration_s() const { return duration_s_; }
  double length_m() const { return length_m_; }
  /// Times at which the head arrives at and leaves waypoint i (first pass) [s].
  double ArrivalTime(int i) const { return arrive_s_.at(i); }
  double DepartureTime(int i) const { return arrive_s_.at(i) + config_.waypoints.at(i).dwell_s; }
  /// Index of the waypoint with this name, or -1.
  int FindWaypoint(const std::string& name) const;
  const HeadTrajectoryConfig& config() const { return config_; }

 private:
  Eigen::Vector3d Target(int i) const;
  HeadTrajectoryConfig config_;
  std::vector<double> arrive_s_;   // per waypoint; plus the loop's return to 0 at the end
  std::vector<double> seg_len_m_;  // segment i: waypoint i -> i+1 (or -> 0 when looping)
  std::vector<double> cum_len_m_;  // path length at arrival at waypoint i
  double duration_s_{0};
  double length_m_{0};
};

}  // namespace orbed::hmd
