#include "geometry/misalignment.h"

#include <cmath>

namespace orbed::geometry {

MisalignmentResult EvaluateMisalignment(const std::vector<Eigen::Vector3d>& p_W_real_m,
                                        const std::vector<Eigen::Vector3d>& p_W_virtual_m) {
  MisalignmentResult result;
  const size_t n = p_W_real_m.size();
  if (n != p_W_virtual_m.size()) {
    result.reason = "got " + std::to_string(n) + " real landmarks but " +
                    std::to_string(p_W_virtual_m.size()) + " virtual ones";
    return result;
  }
  if (n == 0) {
    result.reason = "no landmark pairs";
    return result;
  }
  for (size_t k = 0; k < n; ++k) {
    if (!p_W_real_m[k].allFinite() || !p_W_virtual_m[k].allFinite()) {
      result.reason = "landmark pair " + std::to_string(k) + " has a non-finite coordinate";
      return result;
    }
  }
  result.error_W_m.resize(n);
  result.error_norm_m.resize(n);
  for (size_t k = 0; k < n; ++k) {
    const Eigen::Vector3d e = p_W_virtual_m[k] - p_W_real_m[k];
    result.error_W_m[k] = e.cwiseAbs();
    result.error_norm_m[k] = e.norm();
    result.mean_error_W_m += result.error_W_m[k];
    result.mean_pair_distance_m += result.error_norm_m[k];
  }
  const double inv_n = 1.0 / static_cast<double>(n);
  result.mean_error_W_m *= inv_n;
  result.mean_pair_distance_m *= inv_n;
  if (n > 1) {
    Eigen::Vector3d sum_sq = Eigen::Vector3d::Zero();
    for (size_t k = 0; k < n; ++k) sum_sq += (result.error_W_m[k] - result.mean_error_W_m).cwiseAbs2();
    result.std_error_W_m = (sum_sq / static_cast<double>(n - 1)).cwiseSqrt();
  }
  result.mean_error_norm_m = result.mean_error_W_m.norm();
  result.std_error_norm_m = result.std_error_W_m.norm();
  result.valid = true;
  return result;
}

}  // namespace orbed::geometry
