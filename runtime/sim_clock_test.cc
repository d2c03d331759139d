// The sim clock: its pure core (SimClock, CheckSimClock) with hand-computed stamps, and a Process
// on memq:// that follows it (timers on sim deadlines, in deadline order, nothing before the first
// SIM_CLOCK, bad and jumping stamps counted). The "sim" is a wall timer of the same process that
// publishes SIM_CLOCK, so the sim deadlines the timers see are exact whatever the machine's load.
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <orbed/sim_clock_ack_t.hpp>
#include <orbed/sim_clock_t.hpp>

#include "lcmtypes/contract/channels.h"
#include "runtime/flags.h"
#include "runtime/process.h"
#include "runtime/sim_clock.h"

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

orbed::sim_clock_ack_t Ack(const std::string& process, int64_t utime, int32_t round, bool published) {
  orbed::sim_clock_ack_t ack{};
  ack.utime = utime;
  ack.start_utime = kStart;
  ack.lockstep_round = round;
  ack.process = process;
  ack.published = published;
  return ack;
}

TEST(SimClockAck, CheckRefusesNonStampsRoundsBelowOneAndBadNames) {
  EXPECT_EQ(CheckSimClockAck(Ack("hmd", kStart + 5000, 1, false)), "");
  EXPECT_NE(CheckSimClockAck(Ack("hmd", kStart - 1, 1, false)), "");  // before its start
  EXPECT_NE(CheckSimClockAck(Ack("hmd", kStart, 0, false)), "");      // round 0 wants no answer
  EXPECT_NE(CheckSimClockAck(Ack("", kStart, 1, false)), "");
  EXPECT_NE(CheckSimClockAck(Ack(std::string(kMaxProcessNameLength + 1, 'x'), kStart, 1, false)), "");
  orbed::sim_clock_t clock{};
  clock.utime = clock.start_utime = kStart;
  clock.realtime_rate = 1;
  clock.lockstep_round = -1;
  EXPECT_NE(CheckSimClock(clock), "");
}

// The sim's side of lockstep, round by round with a hand-made clock [s]: who is waited for, when a
// round is complete, whether anyone published, and a follower left out after the timeout.
TEST(LockstepBarrier, WaitsForEveryFollowerLeavesOutTheSilentAndTakesThemBack) {
  LockstepBarrier barrier(/*timeout_s=*/2.0);
  const int64_t t1 = kStart + 50'000;
  barrier.BeginRound(kStart, kStart, 1, 0.0);  // a held clock's round: followers join
  EXPECT_TRUE(barrier.Check(0.0).complete);    // nobody to wait for
  EXPECT_EQ(barrier.OnAck(Ack("hmd", kStart, 1, false)), LockstepBarrier::Answer::kJoined);
  EXPECT_EQ(barrier.OnAck(Ack("guidance", kStart, 1, false)), LockstepBarrier::Answer::kJoined);
  EXPECT_EQ(barrier.followers(), (std::vector<std::string>{"guidance", "hmd"}));

  // Round 1 of the next tick: both are waited for; one answer is not enough.
  barrier.BeginRound(t1, kStart, 1, 10.0);
  EXPECT_FALSE(barrier.Check(10.0).complete);
  EXPECT_EQ(barrier.OnAck(Ack("hmd", t1, 1, true)), LockstepBarrier::Answer::kCounted);
  EXPECT_EQ(barrier.OnAck(Ack("guidance", kStart, 1, false)),
            LockstepBarrier::Answer::kOther);  // an old round
  EXPECT_FALSE(barrier.Check(10.5).complete);
  EXPECT_EQ(barrier.OnAck(Ack("guidance", t1, 1, false)), LockstepBarrier::Answer::kCounted);
  LockstepBarrier::Status status = barrier.Check(10.5);
  EXPECT_TRUE(status.complete);
  EXPECT_TRUE(status.published);  // hmd sent something: another round
  EXPECT_TRUE(status.left_out.empty());

  // Round 2: a quiet one. A follower met only now (it started during round 1) is not waited for
  // in this round, and an answer from another sim changes nothing.
  barrier.BeginRound(t1, kStart, 2, 11.0);
  EXPECT_EQ(barrier.OnAck(Ack("assistant", t1, 1, true)), LockstepBarrier::Answer::kJoined);
  orbed::sim_clock_ack_t other = Ack("hmd", t1, 2, true);
  other.start_utime = kStart - 1;
  EXPECT_EQ(barrier.OnAck(other), LockstepBarrier::Answer::kOther);
  EXPECT_EQ(barrier.OnAck(Ack("hmd", t1, 2, false)), LockstepBarrier::Answer::kCounted);
  EXPECT_EQ(barrier.OnAck(Ack("guidance", t1, 2, false)), LockstepBarrier::Answer::kCounted);
  status = barrier.Check(11.1);
  EXPECT_TRUE(status.complete);
  EXPECT_FALSE(status.published);

  // The next tick: the assistant is waited for now. hmd goes silent: complete only after 2 s,
  // when it is left out (once), not before.
  const int64_t t2 = t1 + 50'000;
  barrier.BeginRound(t2, kStart, 1, 20.0);
  EXPECT_EQ(barrier.OnAck(Ack("guidance", t2, 1, false)), LockstepBarrier::Answer::kCounted);
  EXPECT_FALSE(barrier.Check(20.1).complete);
  EXPECT_EQ(barrier.OnAck(Ack("assistant", t2, 1, false)), LockstepBarrier::Answer::kCounted);
  EXPECT_FALSE(barrier.Check(22.0).complete);  // exactly the timeout: still waiting
  status = barrier.Check(22.01);
  EXPECT_TRUE(status.complete);
  EXPECT_EQ(status.left_out, std::vector<std::string>{"hmd"});
  EXPECT_TRUE(barrier.Check(22.02).left_out.empty());
  EXPECT_EQ(barrier.followers(), (std::vector<std::string>{"assistant", "guidance"}));
  // Its next answer (to any round sent) takes it back; it is waited for from the next round on.
  // An answer to a round not sent yet is refused.
  barrier.BeginRound(t2, kStart, 2, 23.0);
  EXPECT_EQ(barrier.OnAck(Ack("hmd", t2, 3, false)), LockstepBarrier::Answer::kUnsent);
  EXPECT_EQ(barrier.OnAck(Ack("hmd", t2 + 50'000, 1, false)), LockstepBarrier::Answer::kUnsent);
  EXPECT_EQ(barrier.OnAck(Ack("hmd", t1, 2, false)), LockstepBarrier::Answer::kJoined);
  EXPECT_EQ(barrier.OnAck(Ack("guidance", t2, 2, false)), LockstepBarrier::Answer::kCounted);
  EXPECT_EQ(barrier.OnAck(Ack("assistant", t2, 2, false)), LockstepBarrier::Answer::kCounted);
  EXPECT_TRUE(barrier.Check(23.0).complete);
  barrier.BeginRound(t2 + 50'000, kStart, 1, 24.0);
  EXPECT_EQ(barrier.OnAck(Ack("guidance", t2 + 50'000, 1, false)), LockstepBarrier::Answer::kCounted);
  EXPECT_EQ(barrier.OnAck(Ack("assistant", t2 + 50'000, 1, false)), LockstepBarrier::Answer::kCounted);
  EXPECT_FALSE(barrier.Check(24.0).complete);  // hmd again
}

TEST(LockstepBarrier, RefusesNamesBeyondTheMost) {
  LockstepBarrier barrier(1.0);
  barrier.BeginRound(kStart, kStart, 1, 0.0);
  for (size_t i = 0; i < kMaxLockstepFollowers; ++i) {
    EXPECT_EQ(barrier.OnAck(Ack("p" + std::to_string(i), kStart, 1, false)),
              LockstepBarrier::Answer::kJoined);
  }
  EXPECT_EQ(barrier.OnAck(Ack("one-too-many", kStart, 1, false)), LockstepBarrier::Answer::kRefused);
  EXPECT_EQ(barrier.followers().size(), kMaxLockstepFollowers);
}

// A process with sim_time answers each lockstep round on SIM_CLOCK_ACK after the timers that clock
// made due have run, saying whether it published since its previous answer (a timer's output, a
// handler's reply), not counting its heartbeat. The "sim" is the test: it sends the next round
// only when the answer to the last one is in (as orbed-iiwa-sim does), over memq://.
TEST(ProcessSimTime, AnswersEachLockstepRoundAfterItsDueTimers) {
  CommonFlags flags("orbed-follower");
  flags.lcm_url = "memq://";
  flags.duration_s = 20;  // a safety limit only
  flags.sim_time = true;
  Process process(flags);
  int a_runs = 0;
  process.AddTimer(0.02, [&] {
    ++a_runs;
    orbed::sim_clock_t out{};  // any message: the timer's output
    process.Publish("OUTPUT", out);
  });
  // A reply in a handler, as the registration server answers a trial.
  process.Subscribe<orbed::sim_clock_t>("PING", [&](const orbed::sim_clock_t& msg, const std::string&,
                                                    int64_t) { process.Publish("PONG", msg); });
  struct Answer {
    int64_t t_us;
    int32_t round;
    bool published;
    int a_runs;
    std::string process;
  };
  std::vector<Answer> answers;
  // The rounds the "sim" sends: (sim µs since start, round), and a PING before one.
  // (0.05, 1) twice: the sim's repeat of a round whose answer it lost.
  const std::vector<std::pair<int64_t, int32_t>> rounds = {
      {0, 1}, {50'000, 1}, {50'000, 1}, {50'000, 2}, {100'000, 1}, {100'000, 2}, {100'000, 3}};
  size_t next = 0;
  auto send = [&] {
    if (next == rounds.size()) return process.RequestStop();
    if (next == 5) {
      orbed::sim_clock_t ping{};
      process.lcm().publish("PING", &ping);
    }
    orbed::sim_clock_t clock{};
    clock.utime = kStart + rounds[next].first;
    clock.start_utime = kStart;
    clock.realtime_rate = 10;
    clock.lockstep_round = rounds[next].second;
    ++next;
    process.lcm().publish(channels::kSimClock, &clock);
  };
  process.SubscribeRaw(channels::kSimClockAck, [&](const lcm::ReceiveBuffer& rbuf, const std::string&) {
    orbed::sim_clock_ack_t ack;
    ASSERT_EQ(ack.decode(rbuf.data, 0, rbuf.data_size), static_cast<int>(rbuf.data_size));
    answers.push_back(
        {ack.utime - kStart, ack.lockstep_round, static_cast<bool>(ack.published), a_runs, ack.process});
    send();
  });
  send();
  EXPECT_EQ(process.Run(), 0);
  // 0 s: no timer due, nothing published. 0.05 s round 1: a ran at 0.02 and 0.04 and published;
  // its repeat says so again (the first answer may be the one that was lost); round 2: nothing new. 0.10 s
  // round 1: a at 0.06, 0.08, 0.10; round 2: the PING (sent before it) was answered in its handler; round 3:
  // quiet.
  const std::vector<Answer> expected = {{0, 1, false, 0, ""},      {50'000, 1, true, 2, ""},
                                        {50'000, 1, true, 2, ""},  {50'000, 2, false, 2, ""},
                                        {100'000, 1, true, 5, ""}, {100'000, 2, true, 5, ""},
                                        {100'000, 3, false, 5, ""}};
  ASSERT_EQ(answers.size(), expected.size());
  for (size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(answers[k].t_us, expected[k].t_us) << k;
    EXPECT_EQ(answers[k].round, expected[k].round) << k;
    EXPECT_EQ(answers[k].published, expected[k].published) << k;
    EXPECT_EQ(answers[k].a_runs, expected[k].a_runs) << k;
    EXPECT_EQ(answers[k].process, "orbed-follower") << k;
  }
}

// The sim re-sends a round it still waits on; a follower that answered it already, and has
// published since (a reply to another follower's request), answers the repeat as the first time and
// says "published" in its answer to the next round. The order is one a loaded machine gives, played
// here against the sim's LockstepBarrier: "hmd" (this process, over memq://) answers round 2 of a
// tick; "setup" (the test) sends it a REQUEST and is slow to answer; the sim re-sends round 2;
// setup's answer (it published) closes round 2 and round 3 goes out; only then does hmd's answer to
// the repeat reach the sim, which ignores it (an earlier round). Round 3 must not look quiet: hmd's
// REPLY is still to be handled, and the arm would step on without it, at a moment the load decides.
TEST(ProcessSimTime, APublicationAfterAnAnswerIsSaidInTheNextRoundNotInARepeat) {
  CommonFlags flags("hmd");
  flags.lcm_url = "memq://";
  flags.duration_s = 20;  // a safety limit only
  flags.sim_time = true;
  Process process(flags);
  process.Subscribe<orbed::sim_clock_t>("REQUEST", [&](const orbed::sim_clock_t& msg, const std::string&,
                                                       int64_t) { process.Publish("REPLY", msg); });
  const int64_t t1 = kStart + 50'000;
  auto send_clock = [&](int64_t utime, int32_t round) {
    orbed::sim_clock_t clock{};
    clock.utime = utime;
    clock.start_utime = kStart;
    clock.realtime_rate = 8;
    clock.lockstep_round = round;
    process.lcm().publish(channels::kSimClock, &clock);
  };
  // The sim's side, [s] a hand-made wall clock. The held clock's round: setup joins first.
  LockstepBarrier barrier(/*timeout_s=*/10.0);
  barrier.BeginRound(kStart, kStart, 1, 0.0);
  ASSERT_EQ(barrier.OnAck(Ack("setup", kStart, 1, false)), LockstepBarrier::Answer::kJoined);
  struct Answer {
    int64_t t_us;
    int32_t round;
    bool published;
    LockstepBarrier::Answer taken;
  };
  std::vector<Answer> answers;
  LockstepBarrier::Status last{};
  process.SubscribeRaw(channels::kSimClockAck, [&](const lcm::ReceiveBuffer& rbuf, const std::string&) {
    orbed::sim_clock_ack_t ack;
    ASSERT_EQ(ack.decode(rbuf.data, 0, rbuf.data_size), static_cast<int>(rbuf.data_size));
    answers.push_back(
        {ack.utime - kStart, ack.lockstep_round, static_cast<bool>(ack.published), barrier.OnAck(ack)});
    switch (answers.size()) {
      case 1:  // hmd joined during the hold. Tick 1, round 1: the clock alone.
        barrier.BeginRound(t1, kStart, 1, 1.0);
        return send_clock(t1, 1);
      case 2:  // setup answers too, nobody published: the sim's state and round 2.
        ASSERT_EQ(barrier.OnAck(Ack("setup", t1, 1, false)), LockstepBarrier::Answer::kCounted);
        ASSERT_TRUE(barrier.Check(1.1).complete);
        barrier.BeginRound(t1, kStart, 2, 2.0);
        return send_clock(t1, 2);
      case 3: {
        // hmd has answered round 2. setup, handling the state, sends its REQUEST and is descheduled;
        // the sim re-sends round 2; setup's answer then closes it, and round 3 goes out.
        orbed::sim_clock_t request{};
        process.lcm().publish("REQUEST", &request);
        send_clock(t1, 2);
        EXPECT_FALSE(barrier.Check(2.1).complete);
        EXPECT_EQ(barrier.OnAck(Ack("setup", t1, 2, true)), LockstepBarrier::Answer::kCounted);
        const LockstepBarrier::Status closed = barrier.Check(2.15);
        EXPECT_TRUE(closed.complete);
        EXPECT_TRUE(closed.published);
        barrier.BeginRound(t1, kStart, 3, 2.2);
        return send_clock(t1, 3);
      }
      case 4:  // hmd's answer to the repeat: too late for round 2.
        return;
      case 5:  // hmd's answer to round 3; setup published nothing since.
        EXPECT_EQ(barrier.OnAck(Ack("setup", t1, 3, false)), LockstepBarrier::Answer::kCounted);
        last = barrier.Check(2.3);
        return process.RequestStop();
      default:
        return process.RequestStop();
    }
  });
  send_clock(kStart, 1);
  EXPECT_EQ(process.Run(), 0);
  // The repeat says what the first answer to round 2 said (nothing), and the REPLY, published
  // between them, is said in round 3: complete, but not quiet, so the sim sends round 4 instead of
  // stepping the arm.
  const std::vector<Answer> expected = {{0, 1, false, LockstepBarrier::Answer::kJoined},
                                        {50'000, 1, false, LockstepBarrier::Answer::kCounted},
                                        {50'000, 2, false, LockstepBarrier::Answer::kCounted},
                                        {50'000, 2, false, LockstepBarrier::Answer::kOther},
                                        {50'000, 3, true, LockstepBarrier::Answer::kCounted}};
  ASSERT_EQ(answers.size(), expected.size());
  for (size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(answers[k].t_us, expected[k].t_us) << k;
    EXPECT_EQ(answers[k].round, expected[k].round) << k;
    EXPECT_EQ(answers[k].published, expected[k].published) << k;
    EXPECT_EQ(answers[k].taken, expected[k].taken) << k;
  }
  EXPECT_TRUE(last.complete);
  EXPECT_TRUE(last.published);
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

// One of several arms (sim_clock_arm "a1"): the process follows SIM_CLOCK_A1 and answers its rounds
// on SIM_CLOCK_ACK_A1; the single arm's SIM_CLOCK does not move its clock and gets no answer.
TEST(ProcessSimTime, AFollowerOfOneArmOfSeveralUsesThatArmsClock) {
  CommonFlags flags("orbed-follower");
  flags.lcm_url = "memq://";
  flags.duration_s = 20;  // a safety limit only
  flags.sim_time = true;
  flags.sim_clock_arm = "a1";
  Process process(flags);
  std::vector<std::pair<std::string, int64_t>> answers;  // (channel, utime - kStart)
  for (const char* channel : {"SIM_CLOCK_ACK", "SIM_CLOCK_ACK_A1"}) {
    process.SubscribeRaw(channel, [&](const lcm::ReceiveBuffer& rbuf, const std::string& ch) {
      orbed::sim_clock_ack_t ack;
      ASSERT_EQ(ack.decode(rbuf.data, 0, rbuf.data_size), static_cast<int>(rbuf.data_size));
      answers.emplace_back(ch, ack.utime - kStart);
      if (answers.size() == 2) process.RequestStop();
    });
  }
  auto tick = [&](const char* channel, int64_t t_us) {
    orbed::sim_clock_t clock{};
    clock.utime = kStart + t_us;
    clock.start_utime = kStart;
    clock.realtime_rate = 10;
    clock.lockstep_round = 1;
    process.lcm().publish(channel, &clock);
  };
  tick("SIM_CLOCK", 900'000);  // another arm's clock, far ahead: ignored
  tick("SIM_CLOCK_A1", 0);
  tick("SIM_CLOCK_A1", 50'000);
  EXPECT_EQ(process.Run(), 0);
  const std::vector<std::pair<std::string, int64_t>> expected = {{"SIM_CLOCK_ACK_A1", 0},
                                                                 {"SIM_CLOCK_ACK_A1", 50'000}};
  EXPECT_EQ(answers, expected);
  EXPECT_NEAR(process.ClockSeconds(), 0.05, 1e-9);
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
