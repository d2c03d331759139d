#include "runtime/sim_clock.h"

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
  if (msg.lockstep_round < 0) return "lockstep_round " + std::to_string(msg.lockstep_round) + " < 0";
  return "";
}

std::string CheckSimClockAck(const orbed::sim_clock_ack_t& msg) {
  if (msg.utime <= 0 || msg.start_utime <= 0 || msg.start_utime > msg.utime) {
    return "utime " + std::to_string(msg.utime) + " and start_utime " + std::to_string(msg.start_utime) +
           " are not a sim clock stamp";
  }
  if (msg.lockstep_round < 1) return "lockstep_round " + std::to_string(msg.lockstep_round) + " < 1";
  if (msg.process.empty() || msg.process.size() > kMaxProcessNameLength) {
    return "process name of " + std::to_string(msg.process.size()) + " characters (1.." +
           std::to_string(kMaxProcessNameLength) + ")";
  }
  return "";
}

LockstepBarrier::LockstepBarrier(double timeout_s) : timeout_s_(timeout_s) {}

void LockstepBarrier::BeginRound(int64_t utime, int64_t start_utime, int32_t round, double now_s) {
  utime_ = utime;
  start_utime_ = start_utime;
  round_ = round;
  round_start_s_ = now_s;
  for (auto& [name, f] : followers_) {
    f.answered = false;
    f.published = false;
  }
}

LockstepBarrier::Answer LockstepBarrier::OnAck(const orbed::sim_clock_ack_t& msg) {
  if (msg.start_utime != start_utime_) return Answer::kOther;
  if (msg.utime > utime_ || (msg.utime == utime_ && msg.lockstep_round > round_)) return Answer::kUnsent;
  const bool this_round = msg.utime == utime_ && msg.lockstep_round == round_;
  auto it = followers_.find(msg.process);
  Answer answer = Answer::kCounted;
  if (it == followers_.end()) {
    if (followers_.size() >= kMaxLockstepFollowers) return Answer::kRefused;
    // Not waited for in a round that went out before it was known: it may never have seen it.
    it = followers_.emplace(msg.process, Follower{true, false}).first;
    answer = Answer::kJoined;
  }
  if (!this_round) return answer == Answer::kCounted ? Answer::kOther : answer;
  it->second.answered = true;
  it->second.published = it->second.published || msg.published;
  return answer;
}

LockstepBarrier::Status LockstepBarrier::Check(double now_s) {
  Status status;
  status.complete = true;
  const bool timed_out = now_s - round_start_s_ > timeout_s_;
  for (auto it = followers_.begin(); it != followers_.end();) {
    const Follower& f = it->second;
    status.published = status.published || f.published;
    if (f.answered) {
      ++it;
    } else if (timed_out) {
      status.left_out.push_back(it->first);
      it = followers_.erase(it);
    } else {
      status.complete = false;
      ++it;
    }
  }
  return status;
}

std::vector<std::string> LockstepBarrier::followers() const {
  std::vector<std::string> names;
  for (const auto& [name, f] : followers_) names.push_back(name);
  return names;
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
