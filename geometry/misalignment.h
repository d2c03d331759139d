#pragma once
/// @file
/// Misalignment between the real and the virtual robot from landmark pairs, the paper's Table 1
/// protocol (Sec. III-B): the same physical feature is located on the real robot (p_W_real) and on
/// the virtual one (p_W_virtual), typically three pairs per trial, each point triangulated from
/// gaze rays (triangulation.h).
///
/// Per pair k: the absolute per-axis error t_k = |p_W_virtual_k − p_W_real_k| (component-wise, in W)
/// [m] and its norm ‖p_W_virtual_k − p_W_real_k‖ [m].
/// Over pairs (Table 1 columns): the mean absolute per-axis error t̄ = (t̄_x, t̄_y, t̄_z) and its
/// sample standard deviation σ_t (N − 1 in the denominator; 0 for one pair) [m]; the table's last
/// column, ‖t̄‖₂ and ‖σ_t‖₂ [m]; and the mean of the per-pair norms [m] (a distance, which ‖t̄‖₂ is
/// not: the norm of a mean is at most the mean of the norms, so ‖t̄‖₂ ≤ mean_k ‖p_virtual_k − p_real_k‖,
/// equal only when every pair's error points the same way).
///
/// Validation: at least one pair, equal counts, finite coordinates; otherwise valid = false with
/// the reason. Threading: pure function, reentrant.

#include <string>
#include <vector>

#include <Eigen/Core>

namespace orbed::geometry {

struct MisalignmentResult {
  bool valid = false;
  std::string reason;
  std::vector<Eigen::Vector3d> error_W_m;  // |virtual − real| per axis, per pair
  std::vector<double> error_norm_m;        // per pair
  Eigen::Vector3d mean_error_W_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d std_error_W_m = Eigen::Vector3d::Zero();
  double mean_error_norm_m = 0.0;  // ‖t̄‖₂
  double std_error_norm_m = 0.0;   // ‖σ_t‖₂
  double mean_pair_distance_m = 0.0;
};

MisalignmentResult EvaluateMisalignment(const std::vector<Eigen::Vector3d>& p_W_real_m,
                                        const std::vector<Eigen::Vector3d>& p_W_virtual_m);

}  // namespace orbed::geometry
