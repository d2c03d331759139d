#include "procs/registration_server/mean_command.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <iostream>
#include <sstream>

#include "procs/registration_server/trial_file.h"

namespace orbed::registration {
namespace {

// Shortest decimal that reads back to the same double; JSON has no NaN/Inf, so those become null.
std::string Number(double x) {
  if (!std::isfinite(x)) return "null";
  char buf[64];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof(buf), x);
  if (ec != std::errc()) return "null";
  return std::string(buf, ptr);
}

const char* Bool(bool b) { return b ? "true" : "false"; }

}  // namespace

std::string FormatMeanJson(const geometry::Se3MeanResult& result) {
  const Eigen::Quaterniond& q = result.q_WV_mean;
  const Eigen::Vector3d& p = result.p_WV_mean;
  std::string s = "{\"rotation_wxyz\":[" + Number(q.w()) + "," + Number(q.x()) + "," + Number(q.y()) + "," +
                  Number(q.z()) + "],\"translation_m\":[" + Number(p.x()) + "," + Number(p.y()) + "," +
                  Number(p.z()) + "],\"converged\":" + Bool(result.converged) +
                  ",\"unique\":" + Bool(result.unique) +
                  ",\"iterations\":" + std::to_string(result.iterations) +
                  ",\"n_used\":" + std::to_string(result.dispersion.num_used) + ",\"rejected\":[";
  for (size_t k = 0; k < result.rejected.size(); ++k) {
    if (k > 0) s += ",";
    s += std::to_string(result.rejected[k].index);
  }
  s += "],\"rotation_rms_deg\":" + Number(result.dispersion.rotation_rms_deg) +
       ",\"translation_rms_m\":" + Number(result.dispersion.translation_rms_m) + "}";
  return s;
}

int RunMeanCommand(const MeanCommandOptions& options, std::ostream& out, std::ostream& err) {
  const std::string name = options.input_path == "-" ? "<stdin>" : options.input_path;
  TrialFile file;
  if (options.input_path == "-") {
    file = ParseTrialFile(std::cin);
  } else {
    std::ifstream in(options.input_path);
    if (!in) {
      err << "orbed-registration mean: cannot open input file '" << options.input_path << "'\n";
      return 2;
    }
    file = ParseTrialFile(in);
  }
  if (!file.ok) {
    err << name << ":" << file.error_line << ": error: line " << file.error_line << ": " << file.error
        << "\n";
    return 2;
  }
  if (file.quat_WV.empty()) {
    err << name << ": error: no trials (expected lines qw,qx,qy,qz,tx,ty,tz)\n";
    return 2;
  }
  if (file.normalized > 0) {
    err << name << ": note: normalized " << file.normalized << " quaternion(s) (largest |norm - 1| was "
        << file.max_norm_error << ")\n";
  }

  geometry::Se3MeanOptions mean_options;
  mean_options.method =
      options.robust ? geometry::AveragingMethod::kRobust : geometry::AveragingMethod::kKarcher;
  mean_options.p_VC = options.p_VC;
  const geometry::Se3MeanResult result = geometry::ComputeSe3Mean(file.quat_WV, file.p_WV, mean_options);
  if (!result.valid) {
    err << name << ": error: " << result.reason << "\n";
    return 1;
  }
  for (const geometry::RejectedTrial& r : result.rejected) {
    err << name << ":" << file.line[r.index] << ": note: trial " << r.index << " rejected: " << r.reason
        << "\n";
  }
  if (!result.converged) {
    err << name << ": warning: the Karcher iteration hit its cap without converging\n";
  }
  if (!result.unique) {
    err << name
        << (result.method == geometry::AveragingMethod::kChordal
                ? ": warning: the chordal eigen-gap is 0; the chordal mean is not unique\n"
                : ": warning: a trial lies >= 90 deg from the mean; the mean may not be unique\n");
  }

  if (options.json) {
    out << FormatMeanJson(result) << "\n";
    return 0;
  }
  const Eigen::Quaterniond& q = result.q_WV_mean;
  const Eigen::Vector3d& p = result.p_WV_mean;
  const geometry::Se3Dispersion& d = result.dispersion;
  std::ostringstream text;
  text.precision(9);
  text << "X_WV_mean (" << geometry::AveragingMethodName(result.method) << " mean of " << d.num_used << " of "
       << result.num_trials << " trials)\n"
       << "  rotation (w, x, y, z): " << q.w() << ", " << q.x() << ", " << q.y() << ", " << q.z() << "\n"
       << "  translation [m]:       " << p.x() << ", " << p.y() << ", " << p.z() << "\n"
       << "  iterations " << result.iterations << ", converged " << Bool(result.converged) << ", unique "
       << Bool(result.unique) << ", chordal eigen-gap " << result.chordal_eigen_gap << "\n"
       << "  rotation to mean [deg]: rms " << d.rotation_rms_deg << ", median " << d.rotation_median_deg
       << ", max " << d.rotation_max_deg << "\n"
       << "  translation rms [m]:    " << d.translation_rms_m << "\n"
       << "  rejected:";
  if (result.rejected.empty()) text << " none";
  for (const geometry::RejectedTrial& r : result.rejected) text << " " << r.index;
  text << "\n";
  out << text.str();
  return 0;
}

}  // namespace orbed::registration
