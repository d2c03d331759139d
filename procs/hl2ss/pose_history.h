#pragma once
/// @file
/// A bounded history of the headset's pose estimates (HMD_POSE), from which the remote
/// configuration answers the rig node's world pose at a client's timestamps (emulated_device.h).
///
/// Holds the newest `capacity` samples (default 600: 10 s of HMD_POSE at 60 Hz), oldest dropped
/// first, in utime order. Find(utime) answers the sample of that utime, else the nearest one
/// within `match_window_us` (default one HMD_POSE period, 16 667 µs); none there, or the nearest
/// one not located (tracking lost): nullopt, the device's "cannot locate".
/// A sample older than the newest means the headset restarted its clock: the history is cleared
/// first. A sample of the newest's utime replaces it.
///
/// Frames: W world, H head. Units: utime µs since the Unix epoch.
/// Threading: not thread-safe; one thread.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>

#include <Eigen/Geometry>

namespace orbed::hl2ss {

struct PoseSample {
  int64_t utime{0};
  Eigen::Isometry3d X_WH{Eigen::Isometry3d::Identity()};
  bool located{true};
};

class PoseHistory {
 public:
  explicit PoseHistory(size_t capacity = 600, int64_t match_window_us = 16'667)
      : capacity_(capacity < 1 ? 1 : capacity), match_window_us_(match_window_us < 0 ? 0 : match_window_us) {}

  void Add(const PoseSample& sample);
  /// The head's pose at `utime` (see the file comment), or nullopt.
  std::optional<Eigen::Isometry3d> Find(int64_t utime) const;

  size_t size() const { return samples_.size(); }

 private:
  size_t capacity_;
  int64_t match_window_us_;
  std::deque<PoseSample> samples_;
};

}  // namespace orbed::hl2ss
