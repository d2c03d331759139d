// orbed-iiwa-sim's core without a bus, on clocks the test sets: options resolved and checked,
// commands accepted or refused by their age (worked out by hand against both clocks), K steps per
// tick at the URDF speed limit, the sim clock's pace (a stall's jump, lockstep's restarted pace, the
// hold), what the outputs carry, and when the state file is written.
#include "sim/arm_sim.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/units.h"

namespace orbed::sim {
namespace {

constexpr int64_t kStart = 1'700'000'000'000'000;  // start_utime [us since the epoch]
constexpr int64_t kMs = 1'000'000;                 // 1 ms of the monotonic clock [ns]

orbed::iiwa_command_t Command(int64_t utime, const std::vector<double>& q_deg) {
  orbed::iiwa_command_t cmd{};
  cmd.utime = utime;
  cmd.num_joints = static_cast<int32_t>(q_deg.size());
  for (double q : q_deg) cmd.joint_position.push_back(q * kDegToRad);
  return cmd;
}

TEST(ArmSim, ResolvesAndChecksTheOptions) {
  IiwaSimOptions o;
  o.period_s = 0.0050004;  // rounded to 5000 us
  o.realtime_rate = 4;     // K = R when steps_per_tick is 0
  o.arm = "A1";
  const IiwaSimOptions r = ResolveIiwaSimOptions(o);
  EXPECT_EQ(r.period_s, 0.005);
  EXPECT_EQ(r.steps_per_tick, 4);
  EXPECT_EQ(r.iiwa_status_channel, "IIWA_STATUS_A1");
  EXPECT_EQ(r.sim_clock_channel, "SIM_CLOCK_A1");
  EXPECT_EQ(r.robot_name, "A1");
  EXPECT_FALSE(r.urdf_path.empty());
  EXPECT_FALSE(r.scene_path.empty());

  const auto throws = [](IiwaSimOptions bad, const std::string& named) {
    try {
      ResolveIiwaSimOptions(bad);
      ADD_FAILURE() << "accepted, expected a complaint about " << named;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
    }
  };
  IiwaSimOptions bad;
  bad.period_s = 4e-7;  // rounds to 0 us
  throws(bad, "--period-s");
  bad = {};
  bad.realtime_rate = 101;
  throws(bad, "--realtime-rate");
  bad = {};
  bad.steps_per_tick = 1001;
  throws(bad, "--steps-per-tick");
  bad = {};
  bad.steps_per_tick = 1000;
  bad.period_s = 0.011;  // 11 s of sim time per tick > 10 s
  throws(bad, "--steps-per-tick x --period-s");
  bad = {};
  bad.lockstep = true;
  bad.sim_clock_channel = "";
  throws(bad, "--lockstep");
  bad = {};
  bad.stale_command_s = -1;
  throws(bad, "--stale-command-s");
  bad = {};
  bad.initial_q_deg = {0, 0, 0};
  EXPECT_THROW(ArmSim{bad}, std::invalid_argument);
}

TEST(ArmSim, RefusesACommandStaleOnBothClocks) {
  IiwaSimOptions o;
  o.realtime_rate = 10;  // K = 10: a tick is 50 ms of sim time
  ArmSim sim(o);
  sim.Start(kStart, 0);
  EXPECT_EQ(sim.NowUtime(), kStart);
  const int64_t wall = kStart + 10'000'000;  // the wall clock 10 s on
  const std::vector<double> q{0, 0, 0, 0, 0, 0, 30};
  // On the sim clock: age 0, fresh (10 s old on the wall clock).
  EXPECT_FALSE(sim.AcceptCommand(Command(kStart, q), wall));
  EXPECT_NEAR(sim.arm().command_rad()[6], 30 * kDegToRad, 1e-15);
  // 5 s of sim time behind it: 0.5 s of wall time at R = 10, fresh.
  EXPECT_FALSE(sim.AcceptCommand(Command(kStart - 5'000'000, q), wall));
  // 20 s behind the sim clock: 2 s (sim) and 30 s (wall) old.
  auto refusal = sim.AcceptCommand(Command(kStart - 20'000'000, q), wall);
  ASSERT_TRUE(refusal);
  EXPECT_EQ(refusal->key, "stale");
  EXPECT_EQ(refusal->reason, "utime " + std::to_string(kStart - 20'000'000) +
                                 " is 2.000 s older than the wall and the sim clock (limit 1.000 s)");
  // 1.5 s ahead of the wall clock, 11.5 s of sim time ahead of the sim clock: 1.15 s of wall time.
  refusal = sim.AcceptCommand(Command(wall + 1'500'000, q), wall);
  ASSERT_TRUE(refusal);
  EXPECT_NE(refusal->reason.find("is 1.150 s ahead of"), std::string::npos) << refusal->reason;
  // The wrong joint count is the contract's refusal, before the age.
  refusal = sim.AcceptCommand(Command(kStart, {0, 0, 0}), wall);
  ASSERT_TRUE(refusal);
  EXPECT_EQ(refusal->key, "num_joints");
  // A command beyond the limit is taken (ManualArm clamps it).
  EXPECT_FALSE(sim.AcceptCommand(Command(kStart, {0, 0, 0, 0, 0, 0, 200}), wall));
}

TEST(ArmSim, TicksKStepsAtTheSpeedLimitAndCarryThemInTheOutputs) {
  IiwaSimOptions o;
  o.realtime_rate = 10;  // K = 10 steps of 5 ms per tick, 5 ms of wall time apart
  ArmSim sim(o);
  EXPECT_EQ(sim.period_us(), 5000);
  EXPECT_EQ(sim.tick_us(), 50'000);
  EXPECT_EQ(sim.tick_wall_ns(), 5 * kMs);
  sim.Start(kStart, 0);
  ASSERT_FALSE(sim.AcceptCommand(Command(kStart, {0, 0, 0, 0, 0, 0, 90}), kStart));
  // Joint 7 at 180 deg/s: 10 x 0.9 deg per tick.
  const ArmSim::TickResult tick = sim.Tick(5 * kMs);
  EXPECT_EQ(tick.skipped_to_warn, 0);
  EXPECT_EQ(sim.ticks(), 1);
  EXPECT_EQ(sim.NowUtime(), kStart + 50'000);
  const orbed::iiwa_status_t status = sim.IiwaStatus(sim.NowUtime());
  EXPECT_EQ(status.utime, kStart + 50'000);
  ASSERT_EQ(status.num_joints, 7);
  EXPECT_NEAR(status.joint_position_measured[6], 9 * kDegToRad, 1e-12);
  EXPECT_NEAR(status.joint_velocity_estimated[6], 180 * kDegToRad, 1e-9);
  EXPECT_NEAR(status.joint_position_commanded[6], 90 * kDegToRad, 1e-15);
  EXPECT_EQ(status.joint_position_ipo, status.joint_position_measured);
  EXPECT_EQ(status.joint_torque_measured, std::vector<double>(7, 0.0));
  EXPECT_EQ(status.joint_torque_commanded, std::vector<double>(7, 0.0));
  EXPECT_EQ(status.joint_torque_external, std::vector<double>(7, 0.0));

  const orbed::robot_state_t state = sim.RobotState(sim.NowUtime());
  EXPECT_EQ(state.utime, kStart + 50'000);
  EXPECT_EQ(state.robot_name, "iiwa7");
  EXPECT_EQ(state.joint_position, status.joint_position_measured);
  EXPECT_EQ(state.motion_state, static_cast<int8_t>(orbed::robot_state_t::MOTION_MOVING));
  EXPECT_EQ(state.num_links, static_cast<int32_t>(state.X_RL.size()));
  EXPECT_EQ(state.link_names.size(), state.X_RL.size());

  const orbed::collision_status_t collision = sim.CollisionStatus(sim.NowUtime(), tick.closest);
  EXPECT_EQ(collision.utime, kStart + 50'000);
  EXPECT_FALSE(collision.in_collision);
  EXPECT_EQ(collision.min_distance_m, tick.closest.min_distance_m);
  EXPECT_GT(collision.num_links, 0);
  EXPECT_EQ(collision.num_links, static_cast<int32_t>(collision.link_clearance_m.size()));

  const orbed::sim_clock_t clock = sim.SimClock(sim.NowUtime(), 3);
  EXPECT_EQ(clock.utime, kStart + 50'000);
  EXPECT_EQ(clock.start_utime, kStart);
  EXPECT_EQ(clock.realtime_rate, 10);
  EXPECT_EQ(clock.lockstep_round, 3);
}

TEST(ArmSim, AStalledTickJumpsToTheLastDeadlineAndWarnsAtMostEveryTenSeconds) {
  ArmSim sim(IiwaSimOptions{});  // P = 5 ms, K = R = 1
  EXPECT_EQ(sim.MaxLagMicros(), 100'000);
  sim.Start(kStart, 0);
  EXPECT_EQ(sim.Tick(5 * kMs).skipped_to_warn, 0);
  EXPECT_EQ(sim.ticks(), 1);
  // 100 ms late is within the lag: tick 2 keeps its stamp, the loop catches up.
  EXPECT_EQ(sim.Tick(110 * kMs).skipped_to_warn, 0);
  EXPECT_EQ(sim.ticks(), 2);
  // At 500 ms deadline 100 has passed: tick 3 is 97 deadlines behind; it becomes tick 100.
  EXPECT_EQ(sim.Tick(500 * kMs).skipped_to_warn, 97);
  EXPECT_EQ(sim.ticks(), 100);
  EXPECT_EQ(sim.NowUtime(), kStart + 100 * 5000);
  // Another stall 300 ms later: tick 101 -> 160, counted but not warned of (within 10 s).
  EXPECT_EQ(sim.Tick(800 * kMs).skipped_to_warn, 0);
  EXPECT_EQ(sim.ticks(), 160);
  // 10.5 s after the first warning: 59 from before and 2100 - 161 = 1939 now.
  EXPECT_EQ(sim.Tick(10'500 * kMs).skipped_to_warn, 59 + 1939);
  EXPECT_EQ(sim.ticks(), 2100);
}

TEST(ArmSim, InLockstepALateTickRestartsThePaceInsteadOfJumping) {
  IiwaSimOptions o;
  o.lockstep = true;
  ArmSim sim(o);
  sim.Start(kStart, 0);
  EXPECT_FALSE(sim.TickDue(2 * kMs));  // tick 1 is due at 5 ms, half a tick early: 2.5 ms
  EXPECT_TRUE(sim.TickDue(2 * kMs + kMs / 2));
  // A tick 1 s late (the followers were slow): still tick 1; the pace restarts so that tick 1 was
  // due at 1 s, tick 2 at 1.005 s.
  EXPECT_EQ(sim.Tick(1000 * kMs).skipped_to_warn, 0);
  EXPECT_EQ(sim.ticks(), 1);
  EXPECT_FALSE(sim.TickDue(1002 * kMs));
  EXPECT_TRUE(sim.TickDue(1002 * kMs + kMs / 2));
}

TEST(ArmSim, HoldsTheClockUntilTheNamedProcessRunsAndFollows) {
  IiwaSimOptions o;
  o.hold_for = "orbed-scenario";
  o.lockstep = true;
  ArmSim sim(o);
  sim.Start(kStart, 0);
  EXPECT_TRUE(sim.holding());
  EXPECT_FALSE(sim.Release(true, 100 * kMs));  // not running yet
  sim.HoldForRunning();
  EXPECT_FALSE(sim.Release(false, 100 * kMs));  // running, but not answering a round yet
  EXPECT_TRUE(sim.holding());
  EXPECT_TRUE(sim.Release(true, 100 * kMs));
  EXPECT_FALSE(sim.holding());
  EXPECT_EQ(sim.ticks(), 0);
  EXPECT_EQ(sim.NowUtime(), kStart);
  // The pace runs from the release: tick 1 due at 105 ms (half a tick early: 102.5 ms).
  EXPECT_FALSE(sim.TickDue(102 * kMs));
  EXPECT_TRUE(sim.TickDue(102 * kMs + kMs / 2));
  EXPECT_FALSE(sim.Release(true, 200 * kMs));  // released once

  IiwaSimOptions free_running;
  free_running.hold_for = "orbed-scenario";
  ArmSim other(free_running);
  other.Start(kStart, 0);
  other.HoldForRunning();
  EXPECT_TRUE(other.Release(false, 0));  // outside lockstep, running is enough
}

TEST(ArmSim, AnswersPlanChecks) {
  ArmSim sim(IiwaSimOptions{});
  orbed::plan_check_request_t request{};
  request.request_id = 7;
  request.num_joints = 3;
  request.joint_position = {0, 0, 0};
  std::optional<Refusal> refusal;
  orbed::plan_check_reply_t reply = sim.PlanCheckReply(request, kStart, &refusal);
  ASSERT_TRUE(refusal);
  EXPECT_EQ(reply.request_id, 7);
  EXPECT_EQ(reply.utime, kStart);
  EXPECT_FALSE(reply.request_valid);
  EXPECT_TRUE(std::isnan(reply.min_distance_m));
  EXPECT_EQ(reply.reason, "invalid request: " + refusal->reason);

  request.num_joints = 7;
  request.joint_position.assign(7, 0.0);  // upright: within the limits, clear of everything
  refusal.reset();
  reply = sim.PlanCheckReply(request, kStart, &refusal);
  EXPECT_FALSE(refusal);
  EXPECT_TRUE(reply.request_valid);
  EXPECT_TRUE(reply.within_limits);
  EXPECT_FALSE(reply.in_collision);
  EXPECT_TRUE(reply.feasible);
  EXPECT_GT(reply.min_distance_m, 0);
  EXPECT_EQ(reply.reason, "");

  request.joint_position[0] = 200 * kDegToRad;  // beyond joint 1's 170 deg
  reply = sim.PlanCheckReply(request, kStart, &refusal);
  EXPECT_TRUE(reply.request_valid);
  EXPECT_FALSE(reply.within_limits);
  EXPECT_FALSE(reply.feasible);
  EXPECT_EQ(reply.reason.rfind("outside the limits: ", 0), 0u) << reply.reason;
}

TEST(ArmSim, SavesTheStateWhenQChangesAtMostEverySavePeriodWhileMoving) {
  IiwaSimOptions o;
  o.state_file = ::testing::TempDir() + "arm_sim_test_never_written.state";  // not there: start at q0
  o.state_save_period_s = 0.1;                                               // 20 ticks of 5 ms
  ArmSim sim(o);
  sim.Start(kStart, 0);
  EXPECT_FALSE(sim.ShouldSave(sim.IiwaStatus(kStart)));  // q as in the file (q0)
  ASSERT_FALSE(sim.AcceptCommand(Command(kStart, {0, 0, 0, 0, 0, 0, 90}), kStart));
  sim.Tick(5 * kMs);
  orbed::iiwa_status_t status = sim.IiwaStatus(sim.NowUtime());
  EXPECT_TRUE(sim.ShouldSave(status));
  sim.Saved(status);  // at tick 1: next at tick 21
  EXPECT_FALSE(sim.ShouldSave(status));
  for (int k = 2; k <= 20; ++k) {
    sim.Tick(k * 5 * kMs);
    EXPECT_FALSE(sim.ShouldSave(sim.IiwaStatus(sim.NowUtime()))) << "tick " << k;
  }
  sim.Tick(21 * 5 * kMs);
  EXPECT_TRUE(sim.ShouldSave(sim.IiwaStatus(sim.NowUtime())));
  sim.Saved(sim.IiwaStatus(sim.NowUtime()));  // at tick 21: next at tick 41
  for (int k = 22; k <= 90; ++k) sim.Tick(k * 5 * kMs);
  sim.Saved(sim.IiwaStatus(sim.NowUtime()));  // at tick 90: next at tick 110
  // 90 deg at 0.9 deg per tick: the arm comes to rest by tick 101, and is saved at once, however
  // recent the last save.
  int k = 91;
  for (; k <= 101 && sim.arm().state() == MotionState::kMoving; ++k) sim.Tick(k * 5 * kMs);
  ASSERT_EQ(sim.arm().state(), MotionState::kIdle);
  EXPECT_LT(sim.ticks(), 110);
  EXPECT_NEAR(sim.arm().q_rad()[6], 90 * kDegToRad, 1e-12);
  status = sim.IiwaStatus(sim.NowUtime());
  EXPECT_TRUE(sim.ShouldSave(status));
  sim.Saved(status);
  sim.Tick(k * 5 * kMs);
  EXPECT_FALSE(sim.ShouldSave(sim.IiwaStatus(sim.NowUtime())));  // q unchanged since the save
}

TEST(ArmSim, NoStateFileNoSave) {
  ArmSim sim(IiwaSimOptions{});
  sim.Start(kStart, 0);
  ASSERT_FALSE(sim.AcceptCommand(Command(kStart, {0, 0, 0, 0, 0, 0, 90}), kStart));
  sim.Tick(5 * kMs);
  EXPECT_FALSE(sim.ShouldSave(sim.IiwaStatus(sim.NowUtime())));
}

}  // namespace
}  // namespace orbed::sim
