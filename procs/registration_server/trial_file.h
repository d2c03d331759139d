#pragma once
/// @file
/// The offline trial file of `orbed-registration mean`: one alignment trial X_WV_i per line,
///   qw,qx,qy,qz,tx,ty,tz
/// a unit quaternion R_WV (w, x, y, z) and the translation p_WV [m], comma separated, spaces
/// around fields allowed. '#' starts a comment (whole line or after the numbers); blank lines are
/// skipped. Line numbers are 1-based. Numbers are parsed locale-independently.
///
/// Quaternions off unit norm by at most 1e-3 are normalized (counted in `normalized`, so the caller
/// can say so); anything else wrong — a wrong field count, a field that is not a finite number, a
/// quaternion norm farther from 1 — stops parsing with an error naming the line.
///
/// Threading: pure functions, reentrant.

#include <istream>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace orbed::registration {

struct TrialFile {
  /// False on the first malformed line; then error_line and error say where and why.
  bool ok = false;
  int error_line = 0;
  std::string error;
  /// The trials in file order, and the 1-based line each came from.
  std::vector<Eigen::Quaterniond> quat_WV;
  std::vector<Eigen::Vector3d> p_WV;
  std::vector<int> line;
  /// Quaternions that were normalized, and the largest |‖q‖ − 1| among them.
  int normalized = 0;
  double max_norm_error = 0.0;
};

/// Parses the whole stream. An empty (or comment-only) stream is ok with zero trials.
TrialFile ParseTrialFile(std::istream& in);

/// Parses one line (without the newline) into q and p. Returns "" on success, "skip" for a blank or
/// comment-only line, else the reason. `norm_error` receives |‖q‖ − 1| before normalization.
std::string ParseTrialLine(const std::string& text, Eigen::Quaterniond* quat_WV, Eigen::Vector3d* p_WV,
                           double* norm_error);

}  // namespace orbed::registration
