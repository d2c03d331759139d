#pragma once
/// @file
/// The simulation clock a process can follow (as ROS's /clock with use_sim_time): orbed-iiwa-sim
/// publishes sim_clock_t on SIM_CLOCK once per tick, and a process started with --sim-time
/// runs its timers, timeouts and message stamps on it (Process, process.h).
///
/// SimClock is the pure core: it turns the stream of SIM_CLOCK stamps into a monotonic elapsed sim
/// time. Within one sim (the same start_utime), a step forward of at most kMaxSimClockStepUs
/// advances it, a stamp behind the latest is a late datagram and ignored, and a larger step forward
/// (a stamp from nowhere) re-anchors it: the elapsed time stays where it was and later steps count
/// from the new stamp. A new start_utime (a respawned sim, which at a realtime rate R > 1 starts
/// behind the old sim time) re-anchors it too. So the processes that follow it never run
/// backwards, and a single bad or late stamp neither skips every timer nor counts time twice.
///
/// Lockstep (contract change 8): a sim in lockstep publishes each tick's SIM_CLOCK with
/// lockstep_round 1, every follower answers each round on SIM_CLOCK_ACK (sim_clock_ack_t) once the
/// timers that clock made due have run, saying whether it published anything since its previous
/// answer; the sim repeats the tick's stamp in round 2, 3, ... until a round in which every follower
/// answered and nobody (the sim included) published. LCM's multicast delivers one sender's
/// datagrams in order, and a follower sends its output before its answer, so when that round is
/// complete every message the tick caused, and every reply to one, has been handled: the next step
/// no longer depends on how fast anyone computed. LockstepBarrier is the sim's side of it.
///
/// Units: utime in µs since the Unix epoch (the sim's stamps), elapsed time in µs and s since the
/// first stamp; LockstepBarrier's now_s any monotonic clock [s] (the sim's wall clock). Threading:
/// none (the owner's thread).

#include <cstdint>
#include <string>

#include <map>
#include <vector>

#include <orbed/sim_clock_ack_t.hpp>
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
/// start_utime, realtime_rate outside 1..100, lockstep_round < 0).
std::string CheckSimClock(const orbed::sim_clock_t& msg);
/// "" if `msg` is a usable answer, else why not (the stamps as CheckSimClock, lockstep_round < 1, a
/// process name empty or longer than kMaxProcessNameLength).
std::string CheckSimClockAck(const orbed::sim_clock_ack_t& msg);
/// The longest follower name a sim keeps (a process's --name is far shorter).
inline constexpr size_t kMaxProcessNameLength = 256;
/// The most followers a sim waits for; answers from further names are refused.
inline constexpr size_t kMaxLockstepFollowers = 64;

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

/// The sim's side of lockstep: who follows, who answered the round that is out, whether anyone
/// published. A follower joins with its first answer to a round that was sent (during the hold,
/// every follower that is up answers) and is waited for from the next round on; one that has not
/// answered the round within timeout_s (killed, hung) is left out, reported once by Check() and
/// forgotten, and joins again with its next answer, so a killed follower costs one timeout and its
/// respawn takes part again.
class LockstepBarrier {
 public:
  /// `timeout_s` > 0: how long a round waits for a follower [s of the caller's clock].
  explicit LockstepBarrier(double timeout_s);

  /// A round goes out: SIM_CLOCK (utime, start_utime, round) at now_s. Nobody has answered it.
  void BeginRound(int64_t utime, int64_t start_utime, int32_t round, double now_s);
  enum class Answer { kCounted, kJoined, kOther, kUnsent, kRefused };
  /// An answer (CheckSimClockAck first). kCounted: a follower's answer to the round that is out;
  /// kJoined: a new (or left-out) follower, waited for from the next round (its answer counts if
  /// it is to this one); kOther: an answer to an earlier round or another sim (ignored); kUnsent:
  /// an answer to a round this sim has not sent (refused); kRefused: a new name beyond
  /// kMaxLockstepFollowers.
  Answer OnAck(const orbed::sim_clock_ack_t& msg);

  struct Status {
    bool complete{false};               ///< every follower answered the round or was left out
    bool published{false};              ///< some follower that answered published since its previous answer
    std::vector<std::string> left_out;  ///< followers left out by this call (timed out)
  };
  /// The round's state at now_s; followers past the timeout are left out here (once each).
  Status Check(double now_s);

  /// The followers waited for, by name.
  std::vector<std::string> followers() const;
  int32_t round() const { return round_; }

 private:
  struct Follower {
    bool answered{false};
    bool published{false};
  };
  double timeout_s_;
  int64_t utime_{0};
  int64_t start_utime_{0};
  int32_t round_{0};
  double round_start_s_{0};
  std::map<std::string, Follower> followers_;
};

}  // namespace orbed
