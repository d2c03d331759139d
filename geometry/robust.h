#pragma once
/// @file
/// Robust statistics for alignment trials: geodesic L1 medians (Weiszfeld) of rotations on SO(3)
/// and of points in R³, and median + k·MAD rejection of trials whose rotation or translation lies
/// far from those medians. Used before the Karcher step in the robust registration mode, so that
/// one botched trial (a user who flipped the virtual robot) cannot drag the mean.
///
/// Frames: samples are poses X_WV_i = (R_WV_i, p_WV_i) of one frame V in W; medians are in the same
/// frames. Units: rotations [rad] internally, thresholds reported in [deg] and [m] as named.
///
/// The Weiszfeld iteration y ← Σ w_i x_i/d_i / Σ w_i/d_i (done in the tangent space at y on SO(3))
/// is undefined when y lands exactly on a sample x_k. Then the Vardi–Zhang (2000) rule applies:
/// with η = w_k and R = Σ_{i≠k} w_i (x_i − y)/d_i, y is the median when ‖R‖ ≤ η; otherwise the
/// step is scaled by (1 − η/‖R‖). So the iteration neither divides by zero nor sticks to a sample
/// that is not the median.
///
/// Rejection rule, for each of the rotation distances d_i = ∠(R_med, R_i) and the translation
/// distances e_i = ‖p_i − p_med‖: threshold = max(floor, median(d) + k·1.4826·MAD(d)), with
/// MAD(d) = median|d_i − median(d)| (1.4826 makes MAD a consistent σ for Gaussian data). A trial is
/// rejected when either distance exceeds its threshold. The floor keeps near-identical trials from
/// being rejected for sub-floor differences. With fewer than min_trials trials nothing is rejected.
///
/// Threading: pure functions, reentrant.

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace orbed::geometry {

struct L1MedianOptions {
  /// Converged when the step is below this [rad on SO(3), m in R³].
  double step_tolerance = 1e-11;
  /// Weiszfeld converges linearly; the cap leaves converged = false.
  int max_iterations = 2000;
  /// The estimate is "on" a sample closer than this [rad or m].
  double coincidence_tolerance = 1e-12;
};

struct RotationL1MedianResult {
  bool valid = false;
  std::string reason;
  /// argmin_R Σ w_i ∠(R, R_i), canonical sign.
  Eigen::Quaterniond q_WV_median = Eigen::Quaterniond::Identity();
  int iterations = 0;
  bool converged = false;
};

/// Geodesic L1 median on SO(3), started from the chordal mean. Samples/weights as in
/// rotation_mean.h (validated the same way).
RotationL1MedianResult ComputeRotationL1Median(const std::vector<Eigen::Quaterniond>& quat_WV,
                                               const std::vector<double>& weights = {},
                                               const L1MedianOptions& options = {});

struct PointL1MedianResult {
  bool valid = false;
  std::string reason;
  /// argmin_p Σ w_i ‖p − p_i‖ [m].
  Eigen::Vector3d p_W_median = Eigen::Vector3d::Zero();
  int iterations = 0;
  bool converged = false;
};

/// Geometric (L1) median of points, started from their mean. Points must be finite.
PointL1MedianResult ComputePointL1Median(const std::vector<Eigen::Vector3d>& p_W,
                                         const std::vector<double>& weights = {},
                                         const L1MedianOptions& options = {});

struct OutlierOptions {
  /// The k of median + k·MAD (MAD scaled to σ by 1.4826).
  double k_mad = 3.0;
  /// Thresholds never go below these.
  double min_rotation_threshold_deg = 1.0;
  double min_translation_threshold_m = 0.005;
  /// Below this many trials nothing is rejected (a median of two says nothing).
  int min_trials = 3;
  L1MedianOptions median;
};

struct RejectedTrial {
  /// Index into the input.
  int index = -1;
  /// Its distances to the medians [deg], [m].
  double rotation_deg = 0.0;
  double translation_m = 0.0;
  /// E.g. "rotation 120.0 deg from the L1 median exceeds the threshold 2.9 deg".
  std::string reason;
};

struct OutlierResult {
  bool valid = false;
  std::string reason;
  /// Indices kept, ascending; and the rejected trials, ascending by index.
  std::vector<int> inliers;
  std::vector<RejectedTrial> rejected;
  /// The medians the distances were measured from.
  Eigen::Quaterniond q_WV_median = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_WV_median = Eigen::Vector3d::Zero();
  /// Thresholds used [deg], [m].
  double rotation_threshold_deg = 0.0;
  double translation_threshold_m = 0.0;
};

/// Median/MAD rejection over trials X_WV_i = (quat_WV[i], p_WV[i]); sizes must match.
OutlierResult RejectOutliers(const std::vector<Eigen::Quaterniond>& quat_WV,
                             const std::vector<Eigen::Vector3d>& p_WV, const OutlierOptions& options = {});

}  // namespace orbed::geometry
