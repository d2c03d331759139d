#include "procs/hl2ss/pose_history.h"

#include <algorithm>

namespace orbed::hl2ss {
namespace {

// |a − b| without overflow for any two int64.
uint64_t Distance(int64_t a, int64_t b) {
  return a > b ? static_cast<uint64_t>(a) - static_cast<uint64_t>(b)
               : static_cast<uint64_t>(b) - static_cast<uint64_t>(a);
}

}  // namespace

void PoseHistory::Add(const PoseSample& sample) {
  if (!samples_.empty() && sample.utime < samples_.back().utime) samples_.clear();
  if (!samples_.empty() && sample.utime == samples_.back().utime) samples_.pop_back();
  samples_.push_back(sample);
  while (samples_.size() > capacity_) samples_.pop_front();
}

std::optional<Eigen::Isometry3d> PoseHistory::Find(int64_t utime) const {
  if (samples_.empty()) return std::nullopt;
  // The first sample at or after utime, and the one before it: the nearest is one of the two.
  const auto after = std::lower_bound(samples_.begin(), samples_.end(), utime,
                                      [](const PoseSample& s, int64_t t) { return s.utime < t; });
  auto nearest = after;
  if (after == samples_.end() || (after != samples_.begin() &&
                                  Distance(utime, std::prev(after)->utime) <= Distance(after->utime, utime)))
    nearest = std::prev(after);
  if (Distance(nearest->utime, utime) > static_cast<uint64_t>(match_window_us_) || !nearest->located)
    return std::nullopt;
  return nearest->X_WH;
}

}  // namespace orbed::hl2ss
