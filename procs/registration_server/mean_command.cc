#include "procs/registration_server/mean_command.h"

#include <fstream>
#include <iostream>
#include <sstream>
#include <vector>

#include "base/json.h"
#include "procs/registration_server/trial_file.h"

namespace orbed::registration {
namespace {

const char* Bool(bool b) { return b ? "true" : "false"; }

}  // namespace

std::string FormatMeanJson(const geometry::Se3MeanResult& result) {
  const Eigen::Quaterniond& q = result.q_WV_mean;
  const Eigen::Vector3d& p = result.p_WV_mean;
  std::vector<int> rejected;
  for (const auto& r : result.rejected) rejected.push_back(static_cast<int>(r.index));
  JsonWriter json;
  json.BeginObject();
  json.Key("rotation_wxyz").Array(std::vector<double>{q.w(), q.x(), q.y(), q.z()});
  json.Key("translation_m").Array(std::vector<double>{p.x(), p.y(), p.z()});
  json.Key("converged").Bool(result.converged);
  json.Key("unique").Bool(result.unique);
  json.Key("iterations").Int(result.iterations);
  json.Key("n_used").Int(result.dispersion.num_used);
  json.Key("rejected").Array(rejected);
  json.Key("rotation_rms_deg").Number(result.dispersion.rotation_rms_deg);
  json.Key("translation_rms_m").Number(result.dispersion.translation_rms_m);
  json.EndObject();
  return json.str();
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
