#pragma once
/// @file
/// Means of rotations on SO(3): the chordal (quaternion-eigenvector) mean and the geodesic L2
/// (Karcher) mean of the paper's eq. 2, argmin_R Σ w_i‖log(R_iᵀ R)‖², by the fixed-point iteration
///   R ← R · exp( Σ w_i log(Rᵀ R_i) / Σ w_i ),
/// always started from the chordal mean (never from the identity, which may sit near the cut locus
/// of the samples).
///
/// Frames: the samples are rotations R_WV_i of one frame V in one frame W (e.g. the user's
/// virtual-robot base in the OR world, one per alignment trial); the mean is R_WV_mean in the same
/// frames. The mean is bi-invariant: mean(R_A·R_i·R_B) = R_A·mean(R_i)·R_B.
/// Units: radians everywhere in this header.
///
/// Input: unit quaternions of either sign (q and −q give the same mean), optional non-negative
/// weights (empty = all 1). Validation (finite, |‖q‖ − 1| ≤ 1e-6, weights finite ≥ 0 with a
/// positive sum, sizes equal, N ≥ 1) happens here; a failure gives valid = false and a reason that
/// names the offending index. Nothing throws.
///
/// Uniqueness: if every residual angle ∠(R_mean, R_i) is below π/2 the samples lie in an open ball
/// of radius π/2 around the result, where the L2 cost is strictly convex, so the stationary point
/// found is the unique global mean (Karcher 1977; Afsari 2011; Hartley et al., IJCV 2013). The
/// certificate `unique` is that test, made conservative by a margin of 1e-9 rad against rounding.
/// A residual at π (within 1e-6 rad), at the result or at any iterate on the way, has no unique
/// log, so the direction taken was arbitrary: flagged `ambiguous`.
///
/// Threading: pure functions, reentrant; no allocation inside the Karcher loop.

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace orbed::geometry {

/// Checks samples and weights as described above. Returns "" when usable, else the reason.
std::string ValidateRotationSamples(const std::vector<Eigen::Quaterniond>& quat_WV,
                                    const std::vector<double>& weights);

/// The chordal L2 mean: the unit eigenvector of the largest eigenvalue of M = Σ w_i q_i q_iᵀ / Σ w_i
/// (the rotation closest, in the Frobenius norm of the matrices, to the weighted sum).
struct ChordalMeanResult {
  bool valid = false;
  std::string reason;
  /// R_WV_mean, canonical sign (w ≥ 0).
  Eigen::Quaterniond q_WV_mean = Eigen::Quaterniond::Identity();
  /// λ1 − λ2 of M (normalized, so in [0, 1]); near 0 the chordal mean is ill-defined (e.g. two
  /// rotations π apart), 1 when all samples coincide.
  double eigen_gap = 0.0;
};

ChordalMeanResult ComputeChordalMean(const std::vector<Eigen::Quaterniond>& quat_WV,
                                     const std::vector<double>& weights = {});

struct KarcherOptions {
  /// Converged when the update step ‖Σ w_i log(Rᵀ R_i)‖/Σ w_i is below this [rad].
  double step_tolerance_rad = 1e-12;
  /// Iteration cap; reaching it leaves converged = false.
  int max_iterations = 100;
  /// A residual angle within this of π is flagged ambiguous [rad].
  double ambiguity_tolerance_rad = 1e-6;
  /// The uniqueness certificate requires max residual < π/2 − this margin [rad].
  double certificate_margin_rad = 1e-9;
};

struct KarcherMeanResult {
  bool valid = false;
  std::string reason;
  /// R_WV_mean, canonical sign (w ≥ 0).
  Eigen::Quaterniond q_WV_mean = Eigen::Quaterniond::Identity();
  /// The chordal start and its eigen-gap (see ChordalMeanResult).
  Eigen::Quaterniond q_WV_start = Eigen::Quaterniond::Identity();
  double chordal_eigen_gap = 0.0;
  /// Updates applied (the final, sub-tolerance step counts as one).
  int iterations = 0;
  /// True when the last step fell below step_tolerance_rad before the cap.
  bool converged = false;
  /// Norm of the last step [rad].
  double last_step_rad = 0.0;
  /// Largest residual angle ∠(R_mean, R_i) [rad], in [0, π].
  double max_residual_rad = 0.0;
  /// Certificate: max_residual_rad < π/2 − margin (the mean is the unique global minimizer).
  bool unique = false;
  /// Some residual, at the result or at an iterate, lay at π (within tolerance): its log direction,
  /// hence the path to the mean, was an arbitrary choice.
  bool ambiguous = false;
};

KarcherMeanResult ComputeKarcherMean(const std::vector<Eigen::Quaterniond>& quat_WV,
                                     const std::vector<double>& weights = {},
                                     const KarcherOptions& options = {});

}  // namespace orbed::geometry
