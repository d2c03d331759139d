#pragma once
/// @file
/// The SE(3) mean of N alignment trials (paper Sec. II-A): rotation by the chordal or Karcher mean
/// (eq. 2), translation by the arithmetic mean (eq. 3), optionally after robust rejection of
/// outlying trials (robust.h), with the dispersion of the used trials about the mean.
///
/// Frames: every trial is X_WV_i = (R_WV_i, p_WV_i), the virtual robot base V in the world W as a
/// user placed it; the result is X_WV_mean in the same frames.
///
/// Translation about the model centroid (optional): eq. 3 averages the base origins p_WV_i, so a
/// rotation error of a trial, acting about V's origin (often far from the visible robot), moves
/// the model more than its translation says. With p_VC (the model's centroid C in V [m]) given,
/// the centroids p_WC_i = p_WV_i + R_WV_i·p_VC are averaged instead and the base is placed so that
/// the mean rotation carries C to that average: p_WV_mean = mean(p_WC_i) − R_WV_mean·p_VC. With
/// p_VC = 0 this is eq. 3 exactly. Translation residuals are then p_WC_i − mean(p_WC_i).
///
/// Dispersion (of the used trials): rotation residuals r_i = log(R_meanᵀ R_i) [rad]; their angles'
/// RMS, median and max [deg]; covariance Σ r_i r_iᵀ / N [rad²] (population, about the mean);
/// translation residuals e_i [m], RMS √(Σ‖e_i‖²/N) and covariance Σ e_i e_iᵀ / N [m²].
///
/// Threading: pure function, reentrant.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "geometry/robust.h"
#include "geometry/rotation_mean.h"

namespace orbed::geometry {

/// The chordal mean counts as unique when its eigen-gap exceeds this (rounding of the 4x4
/// eigensolver lies far below it).
inline constexpr double kChordalGapMargin = 1e-9;

/// Values match orbed::registration_t::METHOD_*.
enum class AveragingMethod : int { kChordal = 0, kKarcher = 1, kRobust = 2 };

/// "chordal", "karcher", "robust".
const char* AveragingMethodName(AveragingMethod method);

struct Se3MeanOptions {
  AveragingMethod method = AveragingMethod::kKarcher;
  /// The model centroid C in V [m]; unset = eq. 3 about V's origin.
  std::optional<Eigen::Vector3d> p_VC;
  KarcherOptions karcher;
  /// Used when method == kRobust.
  OutlierOptions outlier;
};

struct Se3Dispersion {
  int num_used = 0;
  double rotation_rms_deg = 0.0;
  double rotation_median_deg = 0.0;
  double rotation_max_deg = 0.0;
  Eigen::Matrix3d rotation_covariance_rad2 = Eigen::Matrix3d::Zero();
  double translation_rms_m = 0.0;
  Eigen::Matrix3d translation_covariance_m2 = Eigen::Matrix3d::Zero();
};

struct Se3MeanResult {
  bool valid = false;
  std::string reason;
  AveragingMethod method = AveragingMethod::kKarcher;
  /// X_WV_mean: rotation (canonical sign) and translation [m].
  Eigen::Quaterniond q_WV_mean = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_WV_mean = Eigen::Vector3d::Zero();
  /// Trials given; indices used (ascending) and rejected (robust mode only).
  int num_trials = 0;
  std::vector<int> used;
  std::vector<RejectedTrial> rejected;
  /// Rotation solver: Karcher iterations (0 for chordal), converged (true for chordal, a closed
  /// form), the ambiguity flag of rotation_mean.h, the chordal eigen-gap. `unique` certifies the
  /// mean that was computed: for Karcher and robust, rotation_mean.h's certificate (every used
  /// residual below π/2, so the L2 mean is the unique minimizer); for chordal, that the largest
  /// eigenvalue of the quaternion matrix M is simple (eigen-gap > kChordalGapMargin), which is when
  /// the chordal mean is unique (a residual test would say nothing about it: the chordal mean is not
  /// the minimizer of the geodesic cost).
  int iterations = 0;
  bool converged = false;
  bool unique = false;
  bool ambiguous = false;
  double chordal_eigen_gap = 0.0;
  Se3Dispersion dispersion;
};

/// Averages trials X_WV_i = (quat_WV[i], p_WV[i]). Validates sizes, finiteness and unit quaternions;
/// on failure valid = false with the reason.
Se3MeanResult ComputeSe3Mean(const std::vector<Eigen::Quaterniond>& quat_WV,
                             const std::vector<Eigen::Vector3d>& p_WV, const Se3MeanOptions& options = {});

}  // namespace orbed::geometry
