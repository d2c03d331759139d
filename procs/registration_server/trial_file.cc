#include "procs/registration_server/trial_file.h"

#include <charconv>
#include <cmath>
#include <cstdio>

#include "geometry/so3.h"

namespace orbed::registration {
namespace {

constexpr int kFields = 7;
const char* const kFieldNames[kFields] = {"qw", "qx", "qy", "qz", "tx", "ty", "tz"};

std::string Trim(const std::string& s) {
  const char* ws = " \t\r\v\f";
  const size_t begin = s.find_first_not_of(ws);
  if (begin == std::string::npos) return "";
  const size_t end = s.find_last_not_of(ws);
  return s.substr(begin, end - begin + 1);
}

}  // namespace

std::string ParseTrialLine(const std::string& text, Eigen::Quaterniond* quat_WV, Eigen::Vector3d* p_WV,
                           double* norm_error) {
  const std::string content = Trim(text.substr(0, text.find('#')));
  if (content.empty()) return "skip";

  std::vector<std::string> fields;
  size_t start = 0;
  while (true) {
    const size_t comma = content.find(',', start);
    fields.push_back(
        Trim(content.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (static_cast<int>(fields.size()) != kFields) {
    return "expected 7 comma-separated numbers qw,qx,qy,qz,tx,ty,tz but found " +
           std::to_string(fields.size()) + " fields";
  }
  double v[kFields];
  for (int k = 0; k < kFields; ++k) {
    const std::string& f = fields[k];
    // from_chars takes no leading '+'; allow it as people write it.
    const char* first = f.data();
    const char* last = f.data() + f.size();
    if (first != last && *first == '+') ++first;
    const auto [ptr, ec] = std::from_chars(first, last, v[k]);
    if (f.empty() || ec != std::errc() || ptr != last) {
      return std::string("field ") + std::to_string(k + 1) + " (" + kFieldNames[k] + ") '" + f +
             "' is not a number";
    }
    if (!std::isfinite(v[k])) {
      return std::string("field ") + std::to_string(k + 1) + " (" + kFieldNames[k] + ") is not finite";
    }
  }
  const geometry::RotationCheck check =
      geometry::ValidateQuaternionWxyz(Eigen::Vector4d(v[0], v[1], v[2], v[3]));
  if (!check.valid) return check.message;
  *quat_WV = check.quat;
  *p_WV = Eigen::Vector3d(v[4], v[5], v[6]);
  *norm_error = check.error;
  return "";
}

TrialFile ParseTrialFile(std::istream& in) {
  TrialFile file;
  std::string text;
  int line_number = 0;
  while (std::getline(in, text)) {
    ++line_number;
    Eigen::Quaterniond q;
    Eigen::Vector3d p;
    double norm_error = 0.0;
    const std::string problem = ParseTrialLine(text, &q, &p, &norm_error);
    if (problem == "skip") continue;
    if (!problem.empty()) {
      file.error_line = line_number;
      file.error = problem;
      return file;
    }
    if (norm_error > geometry::RotationTolerance{}.exact) {
      ++file.normalized;
      file.max_norm_error = std::max(file.max_norm_error, norm_error);
    }
    file.quat_WV.push_back(q);
    file.p_WV.push_back(p);
    file.line.push_back(line_number);
  }
  if (in.bad()) {
    file.error_line = line_number + 1;
    file.error = "read error";
    return file;
  }
  file.ok = true;
  return file;
}

}  // namespace orbed::registration
