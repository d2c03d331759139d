#pragma once
/// @file
/// The live head of orbed-hmd without a bus or a clock: the wearer walks the configured path
/// (head_trajectory.h) while the SLAM model (slam_model.h) tracks it, one sample per Step(walk time
/// t); each sample becomes HMD_POSE (the estimate) and HMD_POSE_TRUTH (the truth), same seq and
/// utime; the latest sample's line of sight becomes GAZE_RAY.
///
/// Gaze: the TRUE ray from the head along its z axis (toward the walk's look-at target) is cast
/// against the scene objects and, when known, the real robot at (q, X_WR) (up to
/// max_gaze_distance_m; the nearer hit wins); the ray is reported from the ESTIMATED head, in map
/// coordinates: origin_est, direction_est, hit = origin_est + t · direction_est.
///
/// Forced faults (ScheduleFault): the live SLAM model plays a tracking fault from a chosen walk
/// time (SlamModel::Force), so that HMD_POSE shows the LIMITED / LOST and RELOCALIZED samples of a
/// fault that an emulated trial met (hmd_process.h); one at a time, in the order scheduled (a fault
/// due while another is still playing starts after it).
///
/// Frames: W world (= the SLAM map for estimates), H head, C camera, R real robot base.
/// Units: m, s; utime µs (the caller's stamp).
/// Threading: not synchronised; one thread (the Process::Run() thread).

#include <cstdint>
#include <deque>
#include <optional>
#include <string>

#include <orbed/gaze_ray_t.hpp>
#include <orbed/hmd_pose_t.hpp>

#include "hmd_emulator/hmd_config.h"
#include "hmd_emulator/robot_state.h"
#include "render/scene_geometry.h"
#include "sim/robot_model.h"
#include "sim/scene.h"

namespace orbed::hmd {

class PoseStream {
 public:
  /// `robot` must outlive the stream. Throws std::invalid_argument on a bad walk (head_trajectory.h).
  PoseStream(const HmdConfigSet& config, const sim::Scene& scene, const sim::RobotModel& robot);

  struct Poses {
    orbed::hmd_pose_t estimate;  ///< X_WH_est, X_WC_est, tracking state
    orbed::hmd_pose_t truth;     ///< X_WH_true, X_WC_true; the rest as the estimate
  };
  /// Steps head and SLAM to walk time t_s (non-decreasing) and stamps the sample `utime`.
  Poses Step(double t_s, int64_t utime);

  /// Plays `fault` from the first Step() at walk time >= t_s on.
  void ScheduleFault(double t_s, const ForcedFault& fault);
  /// Whether a scheduled fault has not yet produced its RELOCALIZED sample.
  bool playing_faults() const { return !scheduled_.empty() || slam_.forcing(); }

  /// GAZE_RAY of the latest sample (stamped with its utime); nothing before the first Step().
  /// Poses this stream's copy of the real robot at `robot` when known.
  std::optional<orbed::gaze_ray_t> Gaze(const RobotState& robot);

  bool have_sample() const { return have_sample_; }
  const SlamSample& sample() const { return sample_; }
  int64_t sample_utime() const { return sample_utime_; }
  double t_s() const { return t_s_; }
  const HeadTrajectory& trajectory() const { return trajectory_; }
  /// The scene objects (no robot), as the headset's spatial map holds them.
  const render::SceneGeometry& scene_objects() const { return scene_objects_; }

 private:
  std::string hmd_name_;
  double max_gaze_distance_m_;
  HeadTrajectory trajectory_;
  SlamModel slam_;
  render::SceneGeometry scene_objects_;   // read-only after construction
  render::SceneGeometry robot_geometry_;  // the real robot only, handle 0; posed per Gaze()
  bool have_sample_{false};
  SlamSample sample_;
  int64_t sample_utime_{0};
  double t_s_{0};
  std::deque<TimedFault> scheduled_;  // at_s: walk time
};

}  // namespace orbed::hmd
