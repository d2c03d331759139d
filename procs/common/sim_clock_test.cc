// The sim clock: its pure core (SimClock, CheckSimClock) with hand-computed stamps, and a Process
// on memq:// that follows it (timers on sim deadlines, in deadline order, nothing before the first
// SIM_CLOCK, bad and jumping stamps counted). The "sim" is a wall timer of the same process that
// publishes SIM_CLOCK, so the sim deadlines the timers see are exact whatever the machine's load.
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <orbed/sim_clock_t.hpp>

#include "procs/common/channels.h"
#include "procs/common/flags.h"
#include "procs/common/process.h"
#include "procs/common/sim_clock.h"

namespace orbed {
namespace {

constexpr int64_t kStart = 1'700'000'000'000'000;  // a stamp [µs since the epoch]

TEST(SimClock, AdvancesByTheStampsAndNeverRunsBackwards) {
  SimClock clock;
  EXPECT_FALSE(clock.started());
  EXPECT_EQ(clock.elapsed_us(), 0);
  EXPECT_EQ(clock.Advance(kStart, kStart), SimClock::Step::kFirst);
  EXPECT_EQ(clock.elapsed_us(), 0);
  EXPECT_EQ(clock.Advance(kStart + 50'000, kStart), SimClock::Step::kAdvanced);
  EXPECT_EQ(clock.last_step_us(), 50'000);
  EXPECT_EQ(clock.Advance(kStart + 50'000, kStart), SimClock::Step::kSame);
  EXPECT_EQ(clock.last_step_us(), 0);
  EXPECT_EQ(clock.Advance(kStart + 100'000, kStart), SimClock::Step::kAdvanced);
  EXPECT_EQ(clock.elapsed_us(), 100'000);
  EXPECT_DOUBLE_EQ(clock.elapsed_s(), 0.1);
  // A deadline between two stamps: 0.07 s after the first is kStart + 70 000 µs.
  EXPECT_EQ(clock.UtimeAt(70'000'000), kStart + 70'000);
  // A late datagram of the same sim is ignored: the next stamp counts from the latest, not twice.
  EXPECT_EQ(clock.Advance(kStart + 50'000, kStart), SimClock::Step::kLate);
  EXPECT_EQ(clock.utime(), kStart + 100'000);
  EXPECT_EQ(clock.Advance(kStart + 150'000, kStart), SimClock::Step::kAdvanced);
  EXPECT_EQ(clock.elapsed_us(), 150'000);
  // A respawned sim (a new start) behind the old stamps: re-anchored, the elapsed time stays, later
  // steps count on.
  const int64_t restart = kStart - 5'000'000;
  EXPECT_EQ(clock.Advance(restart, restart), SimClock::Step::kRestarted);
  EXPECT_EQ(clock.elapsed_us(), 150'000);
  EXPECT_EQ(clock.Advance(restart + 10'000, restart), SimClock::Step::kAdvanced);
  EXPECT_EQ(clock.elapsed_us(), 160'000);
  // A stamp from nowhere (an hour ahead) moves nothing; exactly the largest step does.
  EXPECT_EQ(clock.Advance(restart + 3'600'000'000, restart), SimClock::Step::kJumped);
  EXPECT_EQ(clock.elapsed_us(), 160'000);
  EXPECT_EQ(clock.Advance(restart + 3'600'000'000 + kMaxSimClockStepUs, restart), SimClock::Step::kAdvanced);
  EXPECT_EQ(clock.elapsed_us(), 160'000 + kMaxSimClockStepUs);
}

TEST(SimClock, CheckRefusesNonTimesAndRatesOutsideTheSims) {
  orbed::sim_clock_t msg{};
  msg.utime = kStart;
  msg.start_utime = kStart;
  msg.realtime_rate = 1;
  EXPECT_EQ(CheckSimClock(msg), "");
  msg.start_utime = kStart + 1;  // after its stamp
  EXPECT_NE(CheckSimClock(msg), "");
  msg.start_utime = 0;
  EXPECT_NE(CheckSimClock(msg), "");
  msg.start_utime = kStart;
  msg.realtime_rate = kMaxRealtimeRate;
  EXPECT_EQ(CheckSimClock(msg), "");
  for (int bad : {0, -1, kMaxRealtimeRate + 1}) {
    msg.realtime_rate = bad;
    EXPECT_NE(CheckSimClock(msg), "") << bad;
  }
  msg.realtime_rate = 1;
  for (int64_t bad : {int64_t{0}, int64_t{-5}}) {
    msg.utime = bad;
    EXPECT_NE(CheckSimClock(msg), "") << bad;
  }
}

// A process with sim_time: its "sim" (a wall timer of its own) publishes SIM_CLOCK 50 ms of sim
// time apart, as orbed-iiwa-sim does at R = 10, first one bad message and a restart 1 s behind,
// later one late datagram.
// A 20 ms and a 30 ms sim timer run at exactly their deadlines, in the order of the deadlines, with
// the clock reading each deadline; none ran before the first SIM_CLOCK.
TEST(ProcessSimTime, TimersRunAtSimDeadlinesInDeadlineOrder) {
  CommonFlags flags("orbed-test");
  flags.lcm_url = "memq://";
  flags.duration_s = 20;  // a safety limit only: the test stops itself
  flags.sim_time = true;
  Process process(flags);
  ASSERT_TRUE(process.sim_time());
  std::vector<std::pair<std::string, double>> runs;  // (timer, ClockSeconds)
  std::vector<int64_t> stamps;
  int published = 0;
  // The stamps the "sim" sends: a bad rate, the start, a restart 1 s behind (a respawned sim),
  // then 50 ms steps, one datagram of which arrives again late.
  const int64_t restart = kStart - 1'000'000;
  int64_t next = restart;
  process.AddWallTimer(0.002, [&] {
    orbed::sim_clock_t msg{};
    msg.realtime_rate = 10;
    msg.utime = msg.start_utime = kStart;
    if (published == 0) {
      msg.realtime_rate = 0;  // refused: not a clock
    } else if (published >= 2) {
      msg.start_utime = restart;
      msg.utime = published == 5 ? restart + 50'000 : next;  // late: the first step again
      if (published != 5) next += 50'000;
    }
    ++published;
    process.lcm().publish(channels::kSimClock, &msg);
  });
  // b is added first: run by index, b's 0.03 would come before a's 0.02 after the first step.
  process.AddTimer(0.03, [&] {
    runs.emplace_back("b", process.ClockSeconds());
    if (process.ClockSeconds() >= 0.3 - 1e-9) process.RequestStop();
  });
  process.AddTimer(0.02, [&] {
    runs.emplace_back("a", process.ClockSeconds());
    stamps.push_back(process.ClockUtime());
  });
  EXPECT_EQ(process.Run(), 0);

  // Deadlines: a at 0.02 k, b at 0.03 k, up to b's 0.30 s; ties (0.06, 0.12, ...) in the order the
  // timers were added (b first).
  std::vector<std::pair<std::string, double>> expected;
  for (int i = 1, j = 1; j <= 10;) {
    if (3 * j <= 2 * i) {
      expected.emplace_back("b", 0.03 * j++);
    } else {
      expected.emplace_back("a", 0.02 * i++);
    }
  }
  ASSERT_GE(runs.size(), expected.size());
  for (size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(runs[k].first, expected[k].first) << k;
    EXPECT_NEAR(runs[k].second, expected[k].second, 1e-9) << k;
  }
  // a's stamps: the anchor after the restart (kStart - 1 s) + its deadline; the late datagram
  // did not count its step twice.
  for (size_t k = 0; k < 10; ++k) EXPECT_EQ(stamps[k], restart + 20'000 * (k + 1)) << k;
  const auto rejections = process.rejections().counts();
  EXPECT_EQ(rejections.at(std::string(channels::kSimClock) + "/field"), 1);
  EXPECT_EQ(rejections.at(std::string(channels::kSimClock) + "/late"), 1);
  EXPECT_EQ(rejections.count(std::string(channels::kSimClock) + "/jump"), 0u);
  EXPECT_EQ(process.dropped(), 0);  // 50 ms steps are 2.5 and 1.7 periods: caught up, not skipped
}

// Without sim_time the process clock is the monotonic one and SIM_CLOCK is not even subscribed.
TEST(ProcessSimTime, WithoutItTheClockIsTheWallsAndSimClockIsIgnored) {
  CommonFlags flags("orbed-test");
  flags.lcm_url = "memq://";
  flags.duration_s = 0.3;
  Process process(flags);
  EXPECT_FALSE(process.sim_time());
  int ticks = 0;
  process.AddTimer(0.1, [&] { ++ticks; });
  orbed::sim_clock_t msg{};
  msg.utime = kStart;
  msg.realtime_rate = 1;
  process.lcm().publish(channels::kSimClock, &msg);
  EXPECT_EQ(process.Run(), 0);
  EXPECT_GE(ticks, 2);
  EXPECT_EQ(process.messages_in(), 0);
  EXPECT_FALSE(process.sim_clock().started());
  EXPECT_GT(process.ClockSeconds(), 0.25);
}

}  // namespace
}  // namespace orbed
