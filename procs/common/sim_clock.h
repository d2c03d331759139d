#pragma once
/// @file
/// The simulation clock a process can follow (as ROS's /clock with use_sim_time): orbed-iiwa-sim
/// publishes sim_clock_t on SIM_CLOCK once per tick, and a process started with --sim-time
/// ($ORBED_SIM_TIME) runs its timers, timeouts and message stamps on it (Process, process.h).
///
/// SimClock is the pure core: it turns the stream of SIM_CLOCK stamps into a monotonic elapsed sim
/// time. A step forward of at most kMaxSimClockStepUs advances it; a step backwards (a respawned sim
/// at a realtime rate R > 1 starts again at its own wall-clock start, behind the old sim time) or
/// a larger one forward (a stamp from nowhere) re-anchors it: the elapsed time stays where it was
/// and later steps count from the new stamp. So the processes that follow it never run backwards
/// and a single bad stamp cannot skip every timer.
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

/// "" if `msg` is a usable clock stamp, else why not (utime ≤ 0, realtime_rate outside 1..100).
std::string CheckSimClock(const orbed::sim_clock_t& msg);

class SimClock {
 public:
  enum class Step { kFirst, kAdvanced, kSame, kReanchored };
  /// Takes the next stamp (> 0; CheckSimClock first).
  Step Advance(int64_t utime);
  bool started() const { return started_; }
  /// Sim time since the first stamp [µs] (0 before it); never decreases.
  int64_t elapsed_us() const { return elapsed_us_; }
  double elapsed_s() const { return 1e-6 * static_cast<double>(elapsed_us_); }
  /// The latest stamp [µs since the epoch] (0 before the first).
  int64_t utime() const { return utime_; }
  /// The stamp of the sim moment `elapsed_ns` after the first stamp (≤ the elapsed time): the
  /// latest stamp minus the time between them, to the µs. A timer's deadline lies between two stamps.
  int64_t UtimeAt(int64_t elapsed_ns) const;

 private:
  bool started_{false};
  int64_t utime_{0};
  int64_t elapsed_us_{0};
};

}  // namespace orbed
