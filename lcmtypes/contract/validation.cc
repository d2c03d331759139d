#include "lcmtypes/contract/validation.h"

#include <cmath>
#include <sstream>

#include "base/log.h"

namespace orbed {

std::string CheckFinite(const double* values, int count, const std::string& what) {
  for (int i = 0; i < count; ++i) {
    if (!std::isfinite(values[i])) {
      std::ostringstream out;
      out << what << "[" << i << "] is " << values[i] << ", expected a finite number";
      return out.str();
    }
  }
  return "";
}

std::string CheckFinite(const std::vector<double>& values, const std::string& what) {
  return CheckFinite(values.data(), static_cast<int>(values.size()), what);
}

std::string CheckBounded(const double* values, int count, double max_abs, const std::string& what) {
  const std::string finite = CheckFinite(values, count, what);
  if (!finite.empty()) return finite;
  for (int i = 0; i < count; ++i) {
    if (std::abs(values[i]) > max_abs) {
      std::ostringstream out;
      out << what << "[" << i << "] is " << values[i] << ", expected |x| <= " << max_abs;
      return out.str();
    }
  }
  return "";
}

std::string CheckSize(int64_t actual, int64_t expected, const std::string& what) {
  if (actual == expected) return "";
  std::ostringstream out;
  out << what << " is " << actual << ", expected " << expected;
  return out.str();
}

std::string CheckLength(int64_t length_field, size_t array_size, int64_t max, const std::string& what) {
  std::ostringstream out;
  if (length_field < 0 || length_field > max) {
    out << what << " is " << length_field << ", expected 0.." << max;
    return out.str();
  }
  if (static_cast<size_t>(length_field) != array_size) {
    out << what << " is " << length_field << " but the array holds " << array_size;
    return out.str();
  }
  return "";
}

std::string CheckUnitQuaternion(const double q_wxyz[4], const std::string& what, double tolerance) {
  std::string finite = CheckFinite(q_wxyz, 4, what);
  if (!finite.empty()) return finite;
  const double norm = std::sqrt(q_wxyz[0] * q_wxyz[0] + q_wxyz[1] * q_wxyz[1] + q_wxyz[2] * q_wxyz[2] +
                                q_wxyz[3] * q_wxyz[3]);
  if (std::abs(norm - 1.0) <= tolerance) return "";
  std::ostringstream out;
  out << what << ": norm " << norm << ", expected 1 +/- " << tolerance;
  return out.str();
}

std::string CheckPose(const orbed::pose_t& pose, const std::string& what) {
  return FirstError({CheckFinite(pose.position_m, 3, what + ".position_m"),
                     CheckUnitQuaternion(pose.quaternion_wxyz, what + ".quaternion_wxyz")});
}

std::string CheckWorldPose(const orbed::pose_t& pose, const std::string& what) {
  std::string error = CheckPose(pose, what);
  if (!error.empty()) return error;
  const double d =
      std::sqrt(pose.position_m[0] * pose.position_m[0] + pose.position_m[1] * pose.position_m[1] +
                pose.position_m[2] * pose.position_m[2]);
  if (d > kMaxWorldDistance_m) {
    std::ostringstream out;
    out << what << ".position_m is " << d << " m from the world origin, beyond " << kMaxWorldDistance_m
        << " m";
    return out.str();
  }
  return "";
}

std::string CheckEnum(int64_t value, int64_t lo, int64_t hi, const std::string& what) {
  if (value >= lo && value <= hi) return "";
  std::ostringstream out;
  out << what << " is " << value << ", expected " << lo << ".." << hi;
  return out.str();
}

std::string CheckWithinLimits(const std::vector<double>& values, const std::vector<double>& lower,
                              const std::vector<double>& upper, const std::string& what, double slack) {
  if (values.size() != lower.size() || values.size() != upper.size()) {
    return CheckSize(static_cast<int64_t>(values.size()), static_cast<int64_t>(lower.size()), what + " size");
  }
  std::string finite = CheckFinite(values, what);
  if (!finite.empty()) return finite;
  for (size_t i = 0; i < values.size(); ++i) {
    if (values[i] < lower[i] - slack || values[i] > upper[i] + slack) {
      std::ostringstream out;
      out << what << "[" << i << "] = " << values[i] << " outside [" << lower[i] << ", " << upper[i] << "]";
      return out.str();
    }
  }
  return "";
}

std::string FirstError(std::initializer_list<std::string> reasons) {
  for (const std::string& reason : reasons) {
    if (!reason.empty()) return reason;
  }
  return "";
}

void RejectionCounter::Reject(const std::string& key, const std::string& reason) {
  int64_t count = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++total_;
    // Keys can carry channel names from the bus: past kMaxRejectionClasses they share one class, so
    // a flood of made-up channels cannot grow the table (or PROCESS_STATUS) without bound.
    const bool known = counts_.count(key) > 0 || counts_.size() < kMaxRejectionClasses - 1;
    count = ++counts_[known ? key : kOtherRejectionClass];
    last_reason_ = key + ": " + reason.substr(0, kMaxReasonLength);
  }
  // The first five of each class in full, then every 100th, so floods stay readable.
  if (count <= 5 || count % 100 == 0) {
    ORBED_LOG(kWarn) << "rejected " << key << " (#" << count << "): " << reason;
  }
}

int64_t RejectionCounter::total() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return total_;
}

std::map<std::string, int64_t> RejectionCounter::counts() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counts_;
}

std::string RejectionCounter::last_reason() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_reason_;
}

}  // namespace orbed
