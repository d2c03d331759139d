#pragma once
/// @file
/// The simulation clock a process can follow (as ROS's /clock with use_sim_time): orbed-iiwa-sim
/// publishes sim_clock_t on SIM_CLOCK once per tick, and a process started with --sim-time
/// ($ORBED_SIM_TIME) runs its timers, timeouts and message stamps on it (Process, process.h).
///
/// SimClock is the pure core: it turns the stream of SIM_CLOCK stamps into a monotonic elapsed sim
/// time. Within one sim (the same start_utime), a step forward of at most kMaxSimClockStepUs
/// advances it, a stamp behind the latest is a late datagram and ignored, and a larger step forward
/// (a stamp from nowhere) re-anchors it: the elapsed time stays where it was and later steps count
/// from the new stamp. A new start_utime (a respawned sim, which at a realtime rate R > 1 starts
/// behind the old sim time) re-anchors it too. So the processes that follow it never run
/// backwards, and a single bad or late stamp neither skips every timer nor counts time twice.
///
/// Units: utime in µs since the Unix epoch (the sim's stamps), elapsed time in µs and s since the
/// first stamp. Threading: none (the owner's thread).

#include <cstdint>
#include <string>

#include <orbed/sim_clock_t.hpp>

namespace orbed {

/// The largest realtime rate the sim runs at and a SIM_CLOCK may carry.
inline constexpr int kMaxRealtimeRate = 100;
/// The largest forward step of one SIM_CLOCK that advances the clock [µs]: 10 s of sim time, far
/// beyond a tick of the sim at its highest rate (100 × 5 ms) and a stall of a second.
inline constexpr int64_t kMaxSimClockStepUs = 10'000'000;
/// A process on the sim clock that has had no SIM_CLOCK for this long since its start fails
/// (wall seconds): the conductors' timeouts run on the clock and could not fire without it.
inline constexpr double kSimClockStartTimeoutS = 30.0;

/// "" if `msg` is a usable clock stamp, else why not (utime or start_utime ≤ 0, utime before
/// start_utime, realtime_rate outside 1..100).
std::string CheckSimClock(const orbed::sim_clock_t& msg);

class SimClock {
 public:
  enum class Step { kFirst, kAdvanced, kSame, kLate, kRestarted, kJumped };
  /// Takes the next stamp of the sim started at `start_utime` (CheckSimClock first).
  Step Advance(int64_t utime, int64_t start_utime);
  bool started() const { return started_; }
  /// Sim time since the first stamp [µs] (0 before it); never decreases.
  int64_t elapsed_us() const { return elapsed_us_; }
  double elapsed_s() const { return 1e-6 * static_cast<double>(elapsed_us_); }
  /// The latest stamp [µs since the epoch] (0 before the first).
  int64_t utime() const { return utime_; }
  /// The stamp of the sim moment `elapsed_ns` after the first stamp (≤ the elapsed time): the
  /// latest stamp minus the time between them, to the µs. A timer's deadline lies between two stamps.
  int64_t UtimeAt(int64_t elapsed_ns) const;
  /// How far the last stamp advanced the clock [µs] (0 unless kAdvanced).
  int64_t last_step_us() const { return last_step_us_; }

 private:
  bool started_{false};
  int64_t utime_{0};
  int64_t elapsed_us_{0};
  int64_t start_utime_{0};
  int64_t last_step_us_{0};
};

}  // namespace orbed
