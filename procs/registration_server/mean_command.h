#pragma once
/// @file
/// `orbed-registration mean`: the offline SE(3) mean of a trial file (trial_file.h), on exactly the
/// code path the server uses (se3_mean.h). Kept out of the main so tests call it directly.
///
/// Output with json: one line,
///   {"rotation_wxyz":[w,x,y,z],"translation_m":[x,y,z],"converged":b,"unique":b,"iterations":n,
///    "n_used":n,"rejected":[i,...],"rotation_rms_deg":x,"translation_rms_m":x}
/// (X_WV_mean; rejected holds 0-based trial indices in file order; numbers in the shortest form that
/// reads back to the same double). Without json: a short human-readable report.
/// Notes (normalized quaternions, rejected trials with their file lines and reasons) go to `err`.
///
/// Exit codes: 0 success; 2 bad input (unreadable file, malformed line — the message names the line
/// — or no trials); 1 the mean could not be computed.
///
/// Threading: reentrant (no globals); reads the file given.

#include <optional>
#include <ostream>
#include <string>

#include <Eigen/Core>

#include "geometry/se3_mean.h"

namespace orbed::registration {

struct MeanCommandOptions {
  /// Trial file; "-" reads standard input.
  std::string input_path;
  bool robust = false;
  bool json = false;
  /// Optional model centroid C in V [m] (se3_mean.h).
  std::optional<Eigen::Vector3d> p_VC;
};

/// Runs the command; returns the process exit code.
int RunMeanCommand(const MeanCommandOptions& options, std::ostream& out, std::ostream& err);

/// The JSON object above, without a trailing newline.
std::string FormatMeanJson(const geometry::Se3MeanResult& result);

}  // namespace orbed::registration
