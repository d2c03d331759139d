#pragma once
/// @file
/// Input validation for message handlers and files. Each Check* returns "" when the input is
/// valid, else a one-line reason naming the field ("X_WV.quaternion_wxyz: norm 0.5, expected
/// 1 +/- 1e-06"). RejectionCounter counts rejections per reason class and logs them (first few of
/// each class in full, then every 100th), so a flood of bad input can neither crash nor stall a
/// process nor drown its log.
///
/// Threading: the Check* functions are pure. RejectionCounter is thread-safe.

#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <orbed/pose_t.hpp>

namespace orbed {

/// Tolerance on |q| for a quaternion to count as unit.
inline constexpr double kUnitQuaternionTolerance = 1e-6;

std::string CheckFinite(const double* values, int count, const std::string& what);
std::string CheckFinite(const std::vector<double>& values, const std::string& what);
/// Finite and |value| <= max_abs: bounds finite-but-absurd input (1e308) that would overflow
/// sums downstream.
std::string CheckBounded(const double* values, int count, double max_abs, const std::string& what);
/// `actual` must equal `expected` (e.g. num_joints vs the arm's joint count).
std::string CheckSize(int64_t actual, int64_t expected, const std::string& what);
/// A length field must match the array it describes and lie in [0, max].
std::string CheckLength(int64_t length_field, size_t array_size, int64_t max, const std::string& what);
/// (w, x, y, z) finite with norm within `tolerance` of 1.
std::string CheckUnitQuaternion(const double q_wxyz[4], const std::string& what,
                                double tolerance = kUnitQuaternionTolerance);
/// Finite position and unit quaternion.
std::string CheckPose(const orbed::pose_t& pose, const std::string& what);
/// Any operating room, and any lab around it, lies within this of its world origin [m]; farther
/// positions are not a place but a hostile or broken message (and overflow single precision when
/// drawn).
inline constexpr double kMaxWorldDistance_m = 1e4;
/// CheckPose, and the position within kMaxWorldDistance_m of W's origin: a pose in the world frame.
std::string CheckWorldPose(const orbed::pose_t& pose, const std::string& what);
/// Integer enum value in [lo, hi].
std::string CheckEnum(int64_t value, int64_t lo, int64_t hi, const std::string& what);
/// Each value within [lower[i], upper[i]] (inclusive, plus `slack`); sizes must agree.
std::string CheckWithinLimits(const std::vector<double>& values, const std::vector<double>& lower,
                              const std::vector<double>& upper, const std::string& what, double slack = 0.0);

/// Joins several checks: the first non-empty reason, or "".
std::string FirstError(std::initializer_list<std::string> reasons);

/// Counts rejected inputs per class (a short key such as "IIWA_COMMAND/num_joints") and logs the
/// full reason.
/// At most this many reason classes are kept; further ones are counted under kOtherRejectionClass.
constexpr size_t kMaxRejectionClasses = 64;
constexpr const char* kOtherRejectionClass = "other";
/// last_reason() keeps at most this many characters of the reason text.
constexpr size_t kMaxReasonLength = 200;

class RejectionCounter {
 public:
  /// Records one rejection: `key` groups it for counting, `reason` is logged.
  void Reject(const std::string& key, const std::string& reason);
  int64_t total() const;
  std::map<std::string, int64_t> counts() const;
  std::string last_reason() const;

 private:
  mutable std::mutex mutex_;
  int64_t total_ = 0;
  std::map<std::string, int64_t> counts_;
  std::string last_reason_;
};

}  // namespace orbed
