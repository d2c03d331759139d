#include "procs/common/sim_clock.h"

#include <cmath>

namespace orbed {

std::string CheckSimClock(const orbed::sim_clock_t& msg) {
  if (msg.utime <= 0) return "utime " + std::to_string(msg.utime) + " is not a time (must be > 0)";
  if (msg.start_utime <= 0 || msg.start_utime > msg.utime) {
    return "start_utime " + std::to_string(msg.start_utime) + " is not a start of utime " +
           std::to_string(msg.utime);
  }
  if (msg.realtime_rate < 1 || msg.realtime_rate > kMaxRealtimeRate) {
    return "realtime_rate " + std::to_string(msg.realtime_rate) + " outside 1.." +
           std::to_string(kMaxRealtimeRate);
  }
  return "";
}

SimClock::Step SimClock::Advance(int64_t utime, int64_t start_utime) {
  last_step_us_ = 0;
  if (!started_ || start_utime != start_utime_) {
    const bool first = !started_;
    started_ = true;
    utime_ = utime;
    start_utime_ = start_utime;
    return first ? Step::kFirst : Step::kRestarted;
  }
  const int64_t step_us = utime - utime_;
  if (step_us == 0) return Step::kSame;
  if (step_us < 0) return Step::kLate;  // the latest stays
  utime_ = utime;
  if (step_us > kMaxSimClockStepUs) return Step::kJumped;
  elapsed_us_ += step_us;
  last_step_us_ = step_us;
  return Step::kAdvanced;
}

int64_t SimClock::UtimeAt(int64_t elapsed_ns) const {
  return utime_ - std::llround(static_cast<double>(elapsed_us_ * 1000 - elapsed_ns) * 1e-3);
}

}  // namespace orbed
