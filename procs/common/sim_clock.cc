#include "procs/common/sim_clock.h"

#include <cmath>

namespace orbed {

std::string CheckSimClock(const orbed::sim_clock_t& msg) {
  if (msg.utime <= 0) return "utime " + std::to_string(msg.utime) + " is not a time (must be > 0)";
  if (msg.realtime_rate < 1 || msg.realtime_rate > kMaxRealtimeRate) {
    return "realtime_rate " + std::to_string(msg.realtime_rate) + " outside 1.." +
           std::to_string(kMaxRealtimeRate);
  }
  return "";
}

SimClock::Step SimClock::Advance(int64_t utime) {
  if (!started_) {
    started_ = true;
    utime_ = utime;
    return Step::kFirst;
  }
  const int64_t step_us = utime - utime_;
  utime_ = utime;
  if (step_us == 0) return Step::kSame;
  if (step_us < 0 || step_us > kMaxSimClockStepUs) return Step::kReanchored;
  elapsed_us_ += step_us;
  return Step::kAdvanced;
}

int64_t SimClock::UtimeAt(int64_t elapsed_ns) const {
  return utime_ - std::llround(static_cast<double>(elapsed_us_ * 1000 - elapsed_ns) * 1e-3);
}

}  // namespace orbed
