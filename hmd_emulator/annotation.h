#pragma once
/// @file
/// Landmark annotation by head gaze (paper Sec. III-B): how a person wearing the headset marks a
/// point so that it can be triangulated. The cursor is head-locked at the display centre, on the
/// head's line of sight z. To annotate a point Q the person turns the head until the cursor covers
/// Q, with a pointing error (two angles about the head's x and y axes, N(0, σ²) each), holds it for
/// the dwell time and air-taps. The device records the ray from where it believes the head is:
/// origin p_WH_est, direction the estimated head's z axis, in map coordinates (slam_model.h: the
/// SLAM model is stepped through the dwell, jitter and drift included). Two rays from head
/// positions a step apart give the point by least squares (geometry/triangulation.h, which the
/// registration server runs for LANDMARK_REQUEST).
///
/// A point of the real world is aimed at where it is. A point of a hologram placed at X_WV (map
/// coordinates) is aimed at where it appears, ApparentPose(X_WH_true, X_WH_est, X_WV) · p_VQ with
/// the latest sample's poses; its recorded ray therefore passes (up to the pointing error and the
/// jitter of the dwell) through X_WV · p_VQ in the map, and a real point's ray through the map
/// coordinates of the real point. What the triangulated pairs measure is the hologram's offset in
/// the headset's own map, not the registration against the truth.
///
/// Sources: the pointing error and the step are documented with their keys in docs/parameters.md
/// (hmd.annotation_*); the SLAM parameters in config/slam.yaml.
///
/// Frames: W the true world (z up), W' the device map (the rays, named _W as on the bus). Head H:
/// z the line of sight, x right and horizontal, y down. Units: m, rad, s; _deg where named.
/// Threading: an AnnotatingPerson is used from one thread; the SlamModel it steps is not owned and
/// must outlive it.

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "base/random.h"
#include "hmd_emulator/slam_model.h"

namespace orbed::hmd {

/// The head at p_WH looking at p_WQ: z along the line of sight, x to the right and horizontal, y
/// down (world z is up). p_WQ must not lie straight above or below p_WH.
Eigen::Isometry3d HeadLookingAt(const Eigen::Vector3d& p_WH, const Eigen::Vector3d& p_WQ);

/// One recorded gaze ray, in map coordinates.
struct GazeRayRecord {
  Eigen::Vector3d origin_W{Eigen::Vector3d::Zero()};      ///< [m]
  Eigen::Vector3d direction_W{Eigen::Vector3d::UnitZ()};  ///< unit
};

/// How a person annotates (the hmd.annotation_* keys of config/hmd.yaml).
struct AnnotationStyle {
  double pointing_std_deg{0.2};  ///< per axis of the head
  double dwell_s{1.0};           ///< cursor held on the point before the tap
  double walk_speed_m_per_s{0.5};
};

class AnnotatingPerson {
 public:
  /// Steps `slam` (random tracking losses switched off) from time t_s on, one sample per 1 /
  /// rate_hz; the pointing errors are drawn from Random(pointing_seed).
  AnnotatingPerson(SlamModel* slam, double t_s, const AnnotationStyle& style, std::uint64_t pointing_seed);

  /// Stands at p_WH, aims at the real point p_WQ, holds and taps: the ray the device records.
  GazeRayRecord Annotate(const Eigen::Vector3d& p_WH, const Eigen::Vector3d& p_WQ);
  /// The same for the point p_VQ of a hologram placed at X_WV (map): aimed where it appears with the
  /// latest sample's poses (the first call after construction needs `last` set: see set_last()).
  GazeRayRecord AnnotateHologram(const Eigen::Vector3d& p_WH, const Eigen::Isometry3d& X_WV,
                                 const Eigen::Vector3d& p_VQ);
  /// Walks straight from `from` to `to` at the style's speed, looking at `look_at`.
  void Walk(const Eigen::Vector3d& from, const Eigen::Vector3d& to, const Eigen::Vector3d& look_at);

  /// The latest sample (the one the person's view comes from); set it when the model was stepped
  /// before this person took over.
  const SlamSample& last() const { return last_; }
  void set_last(const SlamSample& s) { last_ = s; }
  double t_s() const { return t_s_; }

 private:
  SlamSample Step(const Eigen::Isometry3d& X_WH_true);

  SlamModel* slam_;
  AnnotationStyle style_;
  Random rng_;
  double t_s_;
  SlamSample last_;
};

}  // namespace orbed::hmd
