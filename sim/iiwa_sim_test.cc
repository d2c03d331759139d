// orbed-iiwa-sim in-process on memq:// (the sim's own LCM instance delivers what the test publishes
// on it): bad commands rejected and counted per class, plan checks answered (invalid ones too), a
// command beyond a limit stops on the limit along positions worked out by hand, the outputs stamped
// on the sim clock (tick k at start + k P, late or not) so that speeds read from the stamps stay
// within the iiwa 7's published joint speeds, and the published frames against the
// scene file and the DH facts.
#include "sim/iiwa_sim.h"
#include "sim/iiwa_sim_cli.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <orbed/collision_status_t.hpp>
#include <orbed/iiwa_status_t.hpp>
#include <orbed/plan_check_reply_t.hpp>
#include <orbed/plan_check_request_t.hpp>
#include <orbed/robot_state_t.hpp>
#include <orbed/sim_clock_ack_t.hpp>
#include <orbed/sim_clock_t.hpp>

#include "base/test_command.h"
#include "base/units.h"
#include "lcmtypes/contract/conversions.h"

namespace orbed::sim {
namespace {

const double kSpeedDegPerS[7] = {98, 98, 100, 130, 140, 180, 180};  // iiwa 7 R800 data sheet

// Everything the sim publishes, as received on the same memq instance.
struct Collector {
  std::vector<orbed::iiwa_status_t> status;
  std::vector<orbed::robot_state_t> state;
  std::vector<orbed::collision_status_t> collision;
  std::map<int64_t, orbed::plan_check_reply_t> replies;
  std::vector<orbed::plan_check_reply_t> every_reply;
  void OnStatus(const lcm::ReceiveBuffer*, const std::string&, const orbed::iiwa_status_t* m) {
    status.push_back(*m);
  }
  void OnState(const lcm::ReceiveBuffer*, const std::string&, const orbed::robot_state_t* m) {
    state.push_back(*m);
  }
  void OnCollision(const lcm::ReceiveBuffer*, const std::string&, const orbed::collision_status_t* m) {
    collision.push_back(*m);
  }
  void OnReply(const lcm::ReceiveBuffer*, const std::string&, const orbed::plan_check_reply_t* m) {
    replies[m->request_id] = *m;
    every_reply.push_back(*m);
  }
  void Attach(lcm::LCM& lcm) {
    lcm.subscribe("IIWA_STATUS", &Collector::OnStatus, this);
    lcm.subscribe("ROBOT_STATE", &Collector::OnState, this);
    lcm.subscribe("COLLISION_STATUS", &Collector::OnCollision, this);
    lcm.subscribe("PLAN_CHECK_REPLY", &Collector::OnReply, this);
  }
};

CommonFlags MemqFlags(double duration_s) {
  CommonFlags flags("orbed-iiwa-sim");
  flags.lcm_url = "memq://";
  flags.duration_s = duration_s;
  return flags;
}

orbed::iiwa_command_t Command(const std::vector<double>& q_deg) {
  orbed::iiwa_command_t cmd{};
  cmd.utime = NowMicros();
  cmd.num_joints = static_cast<int32_t>(q_deg.size());
  for (double q : q_deg) cmd.joint_position.push_back(q * kDegToRad);
  cmd.num_torques = 0;
  return cmd;
}

orbed::plan_check_request_t Request(int64_t id, const std::vector<double>& q_deg) {
  orbed::plan_check_request_t req{};
  req.utime = NowMicros();
  req.request_id = id;
  req.num_joints = static_cast<int32_t>(q_deg.size());
  for (double q : q_deg) req.joint_position.push_back(q * kDegToRad);
  return req;
}

TEST(IiwaSim, RejectsBadCommandsPerReasonAndKeepsRunning) {
  IiwaSim sim(MemqFlags(0.3), IiwaSimOptions{});
  Collector got;
  got.Attach(sim.process().lcm());
  lcm::LCM& lcm = sim.process().lcm();

  orbed::iiwa_command_t six = Command({10, 0, 0, 0, 0, 0});
  lcm.publish("IIWA_COMMAND", &six);
  orbed::iiwa_command_t nan = Command({10, 0, 0, 0, 0, 0, 0});
  nan.joint_position[3] = std::nan("");
  lcm.publish("IIWA_COMMAND", &nan);
  orbed::iiwa_command_t inf_torque = Command({10, 0, 0, 0, 0, 0, 0});
  inf_torque.num_torques = 7;
  inf_torque.joint_torque.assign(7, 0.0);
  inf_torque.joint_torque[6] = INFINITY;
  lcm.publish("IIWA_COMMAND", &inf_torque);
  orbed::iiwa_command_t stale = Command({10, 0, 0, 0, 0, 0, 0});
  stale.utime -= 5'000'000;  // 5 s old, limit 1 s
  lcm.publish("IIWA_COMMAND", &stale);
  orbed::iiwa_command_t future = Command({10, 0, 0, 0, 0, 0, 0});
  future.utime += 60'000'000;
  lcm.publish("IIWA_COMMAND", &future);
  orbed::iiwa_command_t torques = Command({10, 0, 0, 0, 0, 0, 0});
  torques.num_torques = 3;
  torques.joint_torque.assign(3, 0.0);
  lcm.publish("IIWA_COMMAND", &torques);
  lcm.publish("IIWA_COMMAND", "garbage", 7);
  // One good command: 2 deg on joint 1 (at 98 deg/s it arrives in ~4 ticks).
  orbed::iiwa_command_t good = Command({2, 0, 0, 0, 0, 0, 0});
  lcm.publish("IIWA_COMMAND", &good);

  EXPECT_EQ(sim.Run(), 0);
  const std::map<std::string, int64_t> counts = sim.process().rejections().counts();
  EXPECT_EQ(counts.at("IIWA_COMMAND/num_joints"), 1);
  EXPECT_EQ(counts.at("IIWA_COMMAND/non_finite"), 2);
  EXPECT_EQ(counts.at("IIWA_COMMAND/stale"), 2);
  EXPECT_EQ(counts.at("IIWA_COMMAND/num_torques"), 1);
  EXPECT_EQ(counts.at("IIWA_COMMAND/decode/truncated"), 1);  // 7 bytes: not even a fingerprint
  EXPECT_EQ(sim.process().rejections().total(), 7);
  const orbed::process_status_t heartbeat = sim.process().MakeStatus();
  EXPECT_EQ(heartbeat.rejected_inputs, 7);
  EXPECT_EQ(heartbeat.num_reasons, 5);

  // Still ticking, and the good command was executed.
  ASSERT_GT(got.status.size(), 20u);
  const orbed::iiwa_status_t& last = got.status.back();
  EXPECT_NEAR(last.joint_position_measured[0], 2 * kDegToRad, 1e-12);
  EXPECT_NEAR(last.joint_position_commanded[0], 2 * kDegToRad, 1e-15);
  for (int i = 1; i < 7; ++i) EXPECT_EQ(last.joint_position_measured[i], 0.0);
}

// Replies for a free pose, an elbow in the patient, an out-of-limit pose and malformed requests.
TEST(IiwaSim, AnswersPlanChecksIncludingInvalidOnes) {
  IiwaSim sim(MemqFlags(0.2), IiwaSimOptions{});
  Collector got;
  got.Attach(sim.process().lcm());
  lcm::LCM& lcm = sim.process().lcm();
  const orbed::plan_check_request_t upright = Request(11, {0, 0, 0, 0, 0, 0, 0});
  // Joint 2 at 110 deg tips the upper arm toward the table (+y in W): the elbow (joint 4 axis,
  // 0.4 m from the shoulder at z = 0.75 + 0.34) lands at y = -0.55 + 0.4 sin 110 = -0.174,
  // z = 1.09 + 0.4 cos 110 = 0.953, x = 0.25: inside the patient torso box
  // (|x| < 0.325, |y| < 0.21, 0.80 < z < 1.02 from the scene file).
  const orbed::plan_check_request_t elbow_in_patient = Request(12, {0, 110, 0, 0, 0, 0, 0});
  const orbed::plan_check_request_t beyond_limit = Request(13, {0, 0, 0, 130, 0, 0, 0});
  const orbed::plan_check_request_t six = Request(14, {0, 0, 0, 0, 0, 0});
  orbed::plan_check_request_t nan_request = Request(15, {0, 0, 0, 0, 0, 0, 0});
  nan_request.joint_position[2] = std::nan("");
  const std::vector<orbed::plan_check_request_t> requests{upright, elbow_in_patient, beyond_limit, six,
                                                          nan_request};
  for (const orbed::plan_check_request_t& req : requests) {
    lcm.publish("PLAN_CHECK_REQUEST", &req);
  }
  sim.Run();
  ASSERT_EQ(got.replies.size(), 5u);

  const orbed::plan_check_reply_t& free = got.replies.at(11);
  EXPECT_TRUE(free.request_valid);
  EXPECT_TRUE(free.within_limits);
  EXPECT_FALSE(free.in_collision);
  EXPECT_TRUE(free.feasible);
  EXPECT_GT(free.min_distance_m, 0.0);
  EXPECT_EQ(free.reason, "");
  EXPECT_EQ(free.num_pairs, static_cast<int32_t>(free.pairs.size()));

  const orbed::plan_check_reply_t& hit = got.replies.at(12);
  EXPECT_TRUE(hit.request_valid);
  EXPECT_TRUE(hit.within_limits);
  EXPECT_TRUE(hit.in_collision);
  EXPECT_FALSE(hit.feasible);
  EXPECT_LT(hit.min_distance_m, 0.0);
  bool torso = false;
  for (const auto& pair : hit.pairs) torso |= pair.body_b == "patient_torso" && pair.distance_m < 0;
  EXPECT_TRUE(torso) << hit.reason;
  EXPECT_NE(hit.reason.find("patient_torso"), std::string::npos) << hit.reason;

  const orbed::plan_check_reply_t& limit = got.replies.at(13);
  EXPECT_TRUE(limit.request_valid);
  EXPECT_FALSE(limit.within_limits);
  EXPECT_FALSE(limit.feasible);
  EXPECT_NE(limit.reason.find("iiwa_joint_4"), std::string::npos) << limit.reason;

  for (int64_t id : {14, 15}) {
    const orbed::plan_check_reply_t& bad = got.replies.at(id);
    EXPECT_FALSE(bad.request_valid) << id;
    EXPECT_FALSE(bad.feasible) << id;
    EXPECT_NE(bad.reason, "") << id;
  }
  EXPECT_EQ(sim.process().rejections().counts().at("PLAN_CHECK_REQUEST/num_joints"), 1);
  EXPECT_EQ(sim.process().rejections().counts().at("PLAN_CHECK_REQUEST/non_finite"), 1);
}

// A retried request (the same message again) gets the same answer: the check is a pure function of
// q and the static scene. Only the reply's utime (when it was computed) differs.
TEST(IiwaSim, AnswersARepeatedPlanCheckTheSame) {
  IiwaSim sim(MemqFlags(0.1), IiwaSimOptions{});
  Collector got;
  got.Attach(sim.process().lcm());
  const orbed::plan_check_request_t request = Request(21, {0, 110, 0, 0, 0, 0, 0});
  for (int i = 0; i < 3; ++i) sim.process().lcm().publish("PLAN_CHECK_REQUEST", &request);
  sim.Run();
  ASSERT_EQ(got.every_reply.size(), 3u);
  for (orbed::plan_check_reply_t reply : got.every_reply) {
    reply.utime = got.every_reply[0].utime;
    std::vector<uint8_t> bytes(reply.getEncodedSize()), first(got.every_reply[0].getEncodedSize());
    reply.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    got.every_reply[0].encode(first.data(), 0, static_cast<int>(first.size()));
    EXPECT_EQ(bytes, first);
  }
  EXPECT_EQ(sim.process().rejections().total(), 0);
}

// Joint 7 commanded to 200 deg (limit 175) and joint 1 to -30 deg, at P = 5 ms. Worked out by hand
// from the motion law (manual_arm.h): the target is clamped to 175 deg; joint 7 sets the pace
// (175/180 s vs 30/98 s), so every tick it moves 180 deg/s x 5 ms = 0.9 deg and joint 1 moves
// 0.9 x 30/175 deg, on the straight line; after tick n of the move joint 7 is at 0.9 n deg, until
// tick 195 (0.9 x 195 = 175.5 > 175) lands on 175 exactly. memq delivers every tick's status, so
// status n of the move is tick n. Each is stamped on the sim clock, start + k P: a whole number of
// periods after the previous one (exactly one but after a stall of more than 100 ms), so the speed
// read from the stamps never exceeds the limit. A step off the law, or a stamp off the sim clock
// (e.g. the wall clock at the tick), fails here.
TEST(IiwaSim, CommandBeyondALimitStopsAtTheLimitWithinTheJointSpeeds) {
  IiwaSimOptions options;
  options.period_s = 0.005;
  IiwaSim sim(MemqFlags(2.0), options);
  ASSERT_EQ(sim.period_us(), 5000);
  Collector got;
  got.Attach(sim.process().lcm());
  const orbed::iiwa_command_t cmd = Command({-30, 0, 0, 0, 0, 0, 200});
  sim.process().lcm().publish("IIWA_COMMAND", &cmd);
  sim.Run();

  ASSERT_GT(got.status.size(), 250u);  // ~400 ticks in 2 s; 195 are needed to arrive
  ASSERT_LE(static_cast<int64_t>(got.status.size()), sim.ticks());
  ASSERT_EQ(got.state.size(), got.status.size());
  ASSERT_EQ(got.collision.size(), got.status.size());
  // The sim clock: start + k P, k increasing (by one per tick but after a stall).
  int64_t previous_k = 0;
  for (size_t k = 0; k < got.status.size(); ++k) {
    const int64_t since_start = got.status[k].utime - sim.start_utime();
    EXPECT_EQ(since_start % sim.period_us(), 0) << "status " << k << ": utime off the sim clock";
    EXPECT_GT(since_start / sim.period_us(), previous_k) << "status " << k;
    previous_k = since_start / sim.period_us();
    EXPECT_EQ(got.state[k].utime, got.status[k].utime);
    EXPECT_EQ(got.collision[k].utime, got.status[k].utime);
  }

  // The move by hand: n = ticks since the command took effect (the first tick that moved joint 7).
  size_t first = 0;  // status index
  while (first < got.status.size() && got.status[first].joint_position_measured[6] == 0.0) ++first;
  ASSERT_LT(first, 5u) << "the command took effect late";
  const double step7_deg = 180 * 0.005;
  for (size_t k = first; k < got.status.size(); ++k) {
    const orbed::iiwa_status_t& s = got.status[k];
    const double n = static_cast<double>(k - first + 1);
    const double q7_deg = std::min(175.0, step7_deg * n);
    EXPECT_NEAR(s.joint_position_measured[6], q7_deg * kDegToRad, 1e-10) << "tick " << k + 1;
    EXPECT_NEAR(s.joint_position_measured[0], -30.0 * q7_deg / 175.0 * kDegToRad, 1e-10) << "tick " << k + 1;
    for (int i = 1; i < 6; ++i) EXPECT_EQ(s.joint_position_measured[i], 0.0) << "tick " << k + 1;
    // The estimate is the step over P: joint 7 at its full 180 deg/s while under way (the last,
    // shortened step excepted), 0 once there.
    const double v7_deg = s.joint_velocity_estimated[6] / kDegToRad;
    if (step7_deg * n <= 175.0) {
      EXPECT_NEAR(v7_deg, 180.0, 1e-6) << "tick " << k + 1;
    } else if (step7_deg * (n - 1) >= 175.0) {
      EXPECT_EQ(v7_deg, 0.0) << "tick " << k + 1;
    }
  }
  ASSERT_GT(got.status.size(), first + 200);
  EXPECT_LT(got.status[first + 193].joint_position_measured[6], 175 * kDegToRad);  // tick 194 of the move
  // Tick 195 lands exactly on the limit (175 deg as the URDF states it).
  EXPECT_EQ(got.status[first + 194].joint_position_measured[6], sim.arm().model().joints()[6].upper_rad);
  EXPECT_NEAR(sim.arm().model().joints()[6].upper_rad, 175 * kDegToRad, 1e-12);
  // Speeds read from the stamps, as a client sees them: within the limits, with joint 7 at its limit.
  double peak7_deg_per_s = 0;
  for (size_t k = 1; k < got.status.size(); ++k) {
    const double dt_s = (got.status[k].utime - got.status[k - 1].utime) * 1e-6;
    for (int i = 0; i < 7; ++i) {
      const double speed_deg_per_s =
          std::abs(got.status[k].joint_position_measured[i] - got.status[k - 1].joint_position_measured[i]) /
          dt_s / kDegToRad;
      EXPECT_LE(speed_deg_per_s, kSpeedDegPerS[i] * (1 + 1e-9)) << "tick " << k + 1 << " joint " << i + 1;
      if (i == 6) peak7_deg_per_s = std::max(peak7_deg_per_s, speed_deg_per_s);
    }
  }
  EXPECT_NEAR(peak7_deg_per_s, 180.0, 1e-6);

  const orbed::iiwa_status_t& last = got.status.back();
  EXPECT_NEAR(last.joint_position_measured[6], 175 * kDegToRad, 1e-12);
  EXPECT_NEAR(last.joint_position_measured[0], -30 * kDegToRad, 1e-12);
  EXPECT_NEAR(last.joint_position_commanded[6], 200 * kDegToRad, 1e-15);
  EXPECT_EQ(last.joint_velocity_estimated[6], 0.0);
  const orbed::robot_state_t& state = got.state.back();
  EXPECT_EQ(state.motion_state, +orbed::robot_state_t::MOTION_STOPPED_AT_LIMIT);
  EXPECT_NE(state.stop_reason.find("iiwa_joint_7"), std::string::npos) << state.stop_reason;
  EXPECT_EQ(state.joint_limit_hit, (std::vector<int8_t>{0, 0, 0, 0, 0, 0, 1}));
  // While under way it said MOVING.
  EXPECT_EQ(got.state[5].motion_state, +orbed::robot_state_t::MOTION_MOVING);
  EXPECT_FALSE(got.collision.back().in_collision);
}

// The sim clock driven by hand (Tick(), no loop). P is period_s rounded to whole microseconds
// (12.344 ms here, so a tick may run up to max(100 ms, 20 P) = 246.88 ms late before the clock
// skips). Tick k is stamped start_utime + k P: tick 5, run 30 ms (2.4 periods) late, keeps its
// stamp, exactly P after tick 4; tick 8, run after a 400 ms stall, jumps to the last deadline
// passed (a whole number of periods, not ahead of the wall clock), and ticks 9 and 10 follow it by
// P. Every tick steps joint 1 (toward 30 deg at 98 deg/s) by 98 deg/s x P, worked out by hand: the
// speed read from the stamps is 98 deg/s at most, however late the tick.
TEST(IiwaSim, StampsTicksOnTheSimClockHoweverLateTheyRun) {
  IiwaSimOptions options;
  options.period_s = 0.0123444;
  const int64_t before = NowMicros();
  IiwaSim sim(MemqFlags(0.1), options);
  const int64_t after = NowMicros();
  constexpr int64_t kP = 12344;
  EXPECT_EQ(sim.period_us(), kP);
  EXPECT_EQ(sim.options().period_s, 0.012344);
  EXPECT_EQ(sim.MaxLagMicros(), 20 * kP);
  EXPECT_GE(sim.start_utime(), before);
  EXPECT_LE(sim.start_utime(), after);
  Collector got;
  lcm::LCM& lcm = sim.process().lcm();
  got.Attach(lcm);
  const orbed::iiwa_command_t cmd = Command({30, 0, 0, 0, 0, 0, 0});
  lcm.publish("IIWA_COMMAND", &cmd);
  while (lcm.handleTimeout(0) > 0) {
  }
  int64_t wall_before_8 = 0, wall_after_8 = 0;
  for (int n = 1; n <= 10; ++n) {
    if (n == 5) std::this_thread::sleep_for(std::chrono::milliseconds(30));
    if (n == 8) {
      std::this_thread::sleep_for(std::chrono::milliseconds(400));
      wall_before_8 = NowMicros();
    }
    sim.Tick();
    if (n == 8) wall_after_8 = NowMicros();
    while (lcm.handleTimeout(0) > 0) {
    }
  }
  ASSERT_EQ(got.status.size(), 10u);
  for (int n = 1; n <= 7; ++n) EXPECT_EQ(got.status[n - 1].utime, sim.start_utime() + n * kP) << "tick " << n;
  const int64_t jumped = got.status[7].utime - sim.start_utime();
  EXPECT_EQ(jumped % kP, 0);
  EXPECT_GT(jumped / kP, 7 + 20) << "tick 8 did not skip the stalled deadlines";
  EXPECT_LE(got.status[7].utime, wall_after_8 + 1000) << "the jump ran ahead of the wall clock";
  EXPECT_GT(got.status[7].utime, wall_before_8 - kP - 1000) << "the jump fell short of the current deadline";
  EXPECT_EQ(got.status[8].utime, got.status[7].utime + kP);
  EXPECT_EQ(got.status[9].utime, got.status[7].utime + 2 * kP);
  EXPECT_EQ(sim.ticks(), jumped / kP + 2);
  for (int n = 1; n <= 10; ++n) {
    const orbed::iiwa_status_t& s = got.status[n - 1];
    EXPECT_NEAR(s.joint_position_measured[0], n * 98 * 0.012344 * kDegToRad, 1e-12) << "tick " << n;
    EXPECT_NEAR(s.joint_velocity_estimated[0], 98 * kDegToRad, 1e-9) << "tick " << n;
    if (n > 1) {
      const double dq = s.joint_position_measured[0] - got.status[n - 2].joint_position_measured[0];
      EXPECT_LE(dq / ((s.utime - got.status[n - 2].utime) * 1e-6), 98 * kDegToRad * (1 + 1e-9))
          << "tick " << n;
    }
  }
  EXPECT_EQ(got.state.back().utime, got.status.back().utime);
  EXPECT_EQ(got.collision.back().utime, got.status.back().utime);
}

// Faster than real time (realtime_rate R = 4, P = 10 ms): tick k steps the arm 4 times and is
// stamped start_utime + 4 k P; joint 1 (toward 30 deg at 98 deg/s) is at 4 k x 98 deg/s x P after
// tick k, worked out by hand: four times as far per tick as at R = 1, and still 98 deg/s read from
// the stamps.
TEST(IiwaSim, ARealtimeRateStepsTheArmThatManyTimesPerTickOnTheSimClock) {
  IiwaSimOptions options;
  options.period_s = 0.01;
  options.realtime_rate = 4;
  IiwaSim sim(MemqFlags(0.1), options);
  Collector got;
  lcm::LCM& lcm = sim.process().lcm();
  got.Attach(lcm);
  const orbed::iiwa_command_t cmd = Command({30, 0, 0, 0, 0, 0, 0});
  lcm.publish("IIWA_COMMAND", &cmd);
  while (lcm.handleTimeout(0) > 0) {
  }
  for (int n = 1; n <= 3; ++n) {
    sim.Tick();
    while (lcm.handleTimeout(0) > 0) {
    }
  }
  ASSERT_EQ(got.status.size(), 3u);
  for (int n = 1; n <= 3; ++n) {
    const orbed::iiwa_status_t& s = got.status[n - 1];
    EXPECT_EQ(s.utime, sim.start_utime() + n * 4 * 10000) << "tick " << n;
    EXPECT_NEAR(s.joint_position_measured[0], n * 4 * 98 * 0.01 * kDegToRad, 1e-12) << "tick " << n;
    EXPECT_NEAR(s.joint_velocity_estimated[0], 98 * kDegToRad, 1e-9) << "tick " << n;
    EXPECT_EQ(got.state[n - 1].utime, s.utime);
  }
  for (int bad : {0, -1, 101}) {
    options.realtime_rate = bad;
    EXPECT_THROW(IiwaSim(MemqFlags(0.1), options), std::invalid_argument) << bad;
  }
}

// The published frames against independent facts: X_WR from the scene file (position
// (0.25, -0.55, 0.75), yaw 90 deg), the upright flange at z = 0.34 + 0.4 + 0.4 + 0.126 = 1.266 m
// in R (the data sheet's DH d), the tool tip 0.25 m (scene tool_length_m) above it.
// The sim clock's source (R = 4, P = 10 ms, held for "setup"): while held, a tick sends SIM_CLOCK
// at the start stamp only and the arm does not step; heartbeats of another process, or of "setup"
// not yet running, do not release it; "setup" running does. Then each tick's SIM_CLOCK goes out
// before its IIWA_STATUS with the same stamp, start + 4 k P. A command stamped on the sim clock is
// fresh within R x 1 s of sim time, whatever the wall clock says.
TEST(IiwaSim, SendsItsClockFirstAndHoldsItUntilTheNamedProcessRuns) {
  IiwaSimOptions options;
  options.period_s = 0.01;
  options.realtime_rate = 4;
  options.hold_for = "setup";
  IiwaSim sim(MemqFlags(0.1), options);
  lcm::LCM& lcm = sim.process().lcm();
  std::vector<std::pair<std::string, int64_t>> order;  // (channel, utime) as received
  struct Recorder {
    std::vector<std::pair<std::string, int64_t>>* order;
    void OnClock(const lcm::ReceiveBuffer*, const std::string& ch, const orbed::sim_clock_t* m) {
      EXPECT_EQ(m->realtime_rate, 4);
      order->emplace_back(ch, m->utime);
    }
    void OnStatus(const lcm::ReceiveBuffer*, const std::string& ch, const orbed::iiwa_status_t* m) {
      order->emplace_back(ch, m->utime);
    }
  } recorder{&order};
  lcm.subscribe("SIM_CLOCK", &Recorder::OnClock, &recorder);
  lcm.subscribe("IIWA_STATUS", &Recorder::OnStatus, &recorder);
  auto drain = [&] {
    while (lcm.handleTimeout(0) > 0) {
    }
  };
  const orbed::iiwa_command_t cmd = Command({30, 0, 0, 0, 0, 0, 0});
  lcm.publish("IIWA_COMMAND", &cmd);
  auto heartbeat = [&](const std::string& name, int8_t state) {
    orbed::process_status_t status{};
    status.utime = 1;
    status.name = name;
    status.state = state;
    lcm.publish("PROCESS_STATUS", &status);
  };
  heartbeat("guidance", orbed::process_status_t::STATE_RUNNING);
  heartbeat("setup", orbed::process_status_t::STATE_STARTING);
  drain();
  for (int n = 0; n < 2; ++n) {
    sim.Tick();
    drain();
  }
  EXPECT_TRUE(sim.holding());
  ASSERT_EQ(order.size(), 2u);
  for (const auto& [channel, utime] : order) {
    EXPECT_EQ(channel, "SIM_CLOCK");
    EXPECT_EQ(utime, sim.start_utime());
  }
  EXPECT_EQ(sim.arm().q_rad()[0], 0.0);

  heartbeat("setup", orbed::process_status_t::STATE_RUNNING);
  drain();
  EXPECT_FALSE(sim.holding());
  order.clear();
  for (int n = 1; n <= 2; ++n) {
    sim.Tick();
    drain();
  }
  ASSERT_EQ(order.size(), 4u);
  for (int n = 1; n <= 2; ++n) {
    const int64_t stamp = sim.start_utime() + n * 4 * 10000;
    EXPECT_EQ(order[2 * (n - 1)], std::make_pair(std::string("SIM_CLOCK"), stamp)) << n;
    EXPECT_EQ(order[2 * (n - 1) + 1], std::make_pair(std::string("IIWA_STATUS"), stamp)) << n;
  }
  EXPECT_NEAR(sim.arm().q_rad()[0], 2 * 4 * 98 * 0.01 * kDegToRad, 1e-12);

  // Stamped 3 s of sim time ahead of the sim clock (0.75 s of wall time at R = 4; 3 s ahead of the
  // wall clock): fresh. 5 s ahead (1.25 s at R = 4): stale.
  const int64_t sim_now = sim.start_utime() + 2 * 4 * 10000;
  orbed::iiwa_command_t ahead = cmd;
  ahead.utime = sim_now + 3'000'000;
  lcm.publish("IIWA_COMMAND", &ahead);
  drain();
  EXPECT_EQ(sim.process().rejections().total(), 0);
  ahead.utime = sim_now + 5'000'000;
  lcm.publish("IIWA_COMMAND", &ahead);
  drain();
  EXPECT_EQ(sim.process().rejections().counts().at("IIWA_COMMAND/stale"), 1);
}

// Lockstep, driven by hand over memq:// (Advance() is what the poll and each answer call): round
// 1 is the clock alone, the tick's state opens round 2 once every follower has answered, rounds
// repeat while anyone (the sim too: a PLAN_CHECK_REPLY) published, the next tick comes only after
// a quiet round, and a follower that stops answering is left out after the timeout, counted.
TEST(IiwaSim, InLockstepStepsOnlyAfterAQuietRoundOfEveryFollower) {
  IiwaSimOptions options;
  options.period_s = 1e-6;
  options.realtime_rate = 100;  // ticks 20 ns of wall time apart: always due here
  options.steps_per_tick = 2;
  options.lockstep = true;
  options.lockstep_timeout_s = 2.0;
  options.lockstep_resend_s = 1e6;  // no re-sent rounds here (the next test has them)
  IiwaSim sim(MemqFlags(0.1), options);
  ASSERT_EQ(sim.tick_us(), 2);
  lcm::LCM& lcm = sim.process().lcm();
  std::vector<std::string> got;  // "<channel> <sim us since start> [r<round>]", as received
  struct Recorder {
    std::vector<std::string>* got;
    int64_t start;
    void OnClock(const lcm::ReceiveBuffer*, const std::string&, const orbed::sim_clock_t* m) {
      got->push_back("SIM_CLOCK " + std::to_string(m->utime - start) + " r" +
                     std::to_string(m->lockstep_round));
    }
    void OnStatus(const lcm::ReceiveBuffer*, const std::string& ch, const orbed::iiwa_status_t* m) {
      got->push_back(ch + " " + std::to_string(m->utime - start));
    }
    void OnReply(const lcm::ReceiveBuffer*, const std::string& ch, const orbed::plan_check_reply_t*) {
      got->push_back(ch);
    }
  } recorder{&got, sim.start_utime()};
  lcm.subscribe("SIM_CLOCK", &Recorder::OnClock, &recorder);
  lcm.subscribe("IIWA_STATUS", &Recorder::OnStatus, &recorder);
  lcm.subscribe("PLAN_CHECK_REPLY", &Recorder::OnReply, &recorder);
  auto drain = [&] {
    while (lcm.handleTimeout(0) > 0) {
    }
  };
  // Each answer is handled (OnAck, then Advance) as it is drained.
  auto answer = [&](int64_t t_us, int32_t round, bool published) {
    orbed::sim_clock_ack_t ack{};
    ack.utime = sim.start_utime() + t_us;
    ack.start_utime = sim.start_utime();
    ack.lockstep_round = round;
    ack.process = "follower";
    ack.published = published;
    lcm.publish("SIM_CLOCK_ACK", &ack);
    drain();
  };
  auto take = [&] {
    std::vector<std::string> out;
    out.swap(got);
    return out;
  };
  using Seen = std::vector<std::string>;

  // Nobody to wait for yet: tick 1's rounds are complete at once (round 1 the clock alone, the
  // state with round 2), all in one call; one tick per call.
  sim.Advance();
  drain();
  EXPECT_EQ(take(), (Seen{"SIM_CLOCK 2 r1", "IIWA_STATUS 2", "SIM_CLOCK 2 r2"}));
  answer(2, 2, false);  // joins, answering the round that is out: quiet, tick 2
  EXPECT_EQ(take(), (Seen{"SIM_CLOCK 4 r1"}));
  EXPECT_EQ(sim.lockstep_followers(), std::vector<std::string>{"follower"});
  sim.Advance();  // waits for the follower
  drain();
  EXPECT_TRUE(take().empty());
  answer(4, 1, false);
  EXPECT_EQ(take(), (Seen{"IIWA_STATUS 4", "SIM_CLOCK 4 r2"}));
  answer(4, 2, true);  // it published: another round
  EXPECT_EQ(take(), (Seen{"SIM_CLOCK 4 r3"}));
  // A plan check during round 3 is answered; the sim published, so round 4 follows.
  orbed::plan_check_request_t request{};
  request.request_id = 7;
  request.num_joints = 7;
  request.joint_position.assign(7, 0.0);
  lcm.publish("PLAN_CHECK_REQUEST", &request);
  drain();
  answer(4, 3, false);
  EXPECT_EQ(take(), (Seen{"PLAN_CHECK_REPLY", "SIM_CLOCK 4 r4"}));
  answer(4, 3, false);  // a repeat of an old round: nothing
  EXPECT_TRUE(take().empty());
  answer(4, 4, false);  // quiet: tick 3
  EXPECT_EQ(take(), (Seen{"SIM_CLOCK 6 r1"}));
  EXPECT_EQ(sim.ticks(), 3);

  // The follower goes silent: the round waits until the timeout, then goes on without it (and
  // through tick 4, with nobody to wait for).
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (got.empty() && std::chrono::steady_clock::now() < give_up) {
    sim.Advance();
    drain();
  }
  EXPECT_EQ(take(),
            (Seen{"IIWA_STATUS 6", "SIM_CLOCK 6 r2", "SIM_CLOCK 8 r1", "IIWA_STATUS 8", "SIM_CLOCK 8 r2"}));
  EXPECT_EQ(sim.process().drop_counts().at("lockstep/follower"), 1);
  EXPECT_TRUE(sim.lockstep_followers().empty());
  // An answer to a round never sent is refused; one to an old round brings the follower back,
  // waited for from the next round on.
  answer(10, 1, false);
  EXPECT_EQ(sim.process().rejections().counts().at("SIM_CLOCK_ACK/unsent"), 1);
  answer(6, 2, false);
  EXPECT_EQ(take(), (Seen{"SIM_CLOCK 10 r1"}));
  EXPECT_EQ(sim.lockstep_followers(), std::vector<std::string>{"follower"});
  sim.Advance();
  drain();
  EXPECT_TRUE(take().empty());
  EXPECT_EQ(sim.process().rejections().total(), 1);
}

// A round whose answer was lost is sent again, the same stamp and round, until the answer comes.
TEST(IiwaSim, InLockstepResendsARoundWhoseAnswerIsMissing) {
  IiwaSimOptions options;
  options.period_s = 1e-6;
  options.realtime_rate = 100;
  options.steps_per_tick = 2;
  options.lockstep = true;
  options.lockstep_timeout_s = 1e6;
  options.lockstep_resend_s = 0.01;
  IiwaSim sim(MemqFlags(0.1), options);
  lcm::LCM& lcm = sim.process().lcm();
  std::vector<std::pair<int64_t, int32_t>> clocks;
  struct Recorder {
    std::vector<std::pair<int64_t, int32_t>>* clocks;
    int64_t start;
    void OnClock(const lcm::ReceiveBuffer*, const std::string&, const orbed::sim_clock_t* m) {
      clocks->emplace_back(m->utime - start, m->lockstep_round);
    }
  } recorder{&clocks, sim.start_utime()};
  lcm.subscribe("SIM_CLOCK", &Recorder::OnClock, &recorder);
  auto drain = [&] {
    while (lcm.handleTimeout(0) > 0) {
    }
  };
  auto answer = [&](int64_t t_us, int32_t round) {
    orbed::sim_clock_ack_t ack{};
    ack.utime = sim.start_utime() + t_us;
    ack.start_utime = sim.start_utime();
    ack.lockstep_round = round;
    ack.process = "follower";
    lcm.publish("SIM_CLOCK_ACK", &ack);
    drain();
  };
  sim.Advance();
  drain();
  answer(2, 2);  // joins, answering tick 1's last round: tick 2 goes out and waits for it
  ASSERT_EQ(clocks.back(), std::make_pair(int64_t{4}, 1));
  const size_t sent = clocks.size();
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (clocks.size() < sent + 2 && std::chrono::steady_clock::now() < give_up) {
    sim.Advance();
    drain();
  }
  ASSERT_EQ(clocks.size(), sent + 2);
  EXPECT_EQ(clocks[sent], std::make_pair(int64_t{4}, 1));
  EXPECT_EQ(clocks[sent + 1], std::make_pair(int64_t{4}, 1));
  EXPECT_EQ(sim.ticks(), 2);
  answer(4, 1);  // the answer at last: the state and round 2
  EXPECT_EQ(clocks.back(), std::make_pair(int64_t{4}, 2));
  EXPECT_EQ(sim.process().dropped(), 0);
}

TEST(IiwaSim, PublishesTrueFramesAndClearances) {
  IiwaSim sim(MemqFlags(0.1), IiwaSimOptions{});
  Collector got;
  got.Attach(sim.process().lcm());
  sim.Run();
  ASSERT_FALSE(got.state.empty());
  const orbed::robot_state_t& s = got.state.front();
  EXPECT_EQ(s.robot_name, "iiwa7");
  EXPECT_NEAR(s.X_WR.position_m[0], 0.25, 1e-12);
  EXPECT_NEAR(s.X_WR.position_m[1], -0.55, 1e-12);
  EXPECT_NEAR(s.X_WR.position_m[2], 0.75, 1e-12);
  EXPECT_NEAR(s.X_WR.quaternion_wxyz[0], std::cos(M_PI / 4), 1e-12);
  EXPECT_NEAR(s.X_WR.quaternion_wxyz[3], std::sin(M_PI / 4), 1e-12);
  EXPECT_NEAR(s.X_RF.position_m[2], 1.266, 1e-9);
  EXPECT_NEAR(s.X_RT.position_m[2], 1.516, 1e-9);
  EXPECT_EQ(s.num_links, static_cast<int32_t>(s.link_names.size()));
  EXPECT_EQ(s.link_names.front(), "iiwa_link_0");
  EXPECT_EQ(s.motion_state, +orbed::robot_state_t::MOTION_IDLE);
  ASSERT_FALSE(got.collision.empty());
  const orbed::collision_status_t& c = got.collision.front();
  EXPECT_FALSE(c.in_collision);
  EXPECT_GT(c.min_distance_m, 0.0);
  EXPECT_GE(c.num_links, 8);
  EXPECT_EQ(c.num_links, static_cast<int32_t>(c.link_clearance_m.size()));
  double smallest = INFINITY;
  for (double d : c.link_clearance_m) smallest = std::min(smallest, d);
  EXPECT_DOUBLE_EQ(smallest, c.min_distance_m);
  for (const auto& contact : c.contacts) EXPECT_LT(contact.distance_m, 0.05);
}

// Several arms: orbed-iiwa-sim --arm a0 in scenes/four_arms_or.yaml stands at a0's base
// and uses a0's channels; arm a1 (0.7 m along the table, upright at q = 0) is known from the
// ROBOT_STATE_A1 the test publishes, as a1's own sim would. Swinging a0 horizontal toward a1 stops
// before it (its tool before a1's), naming a1's link; once a1 is elsewhere a0 goes on; a ROBOT_STATE_A1 of
// another model's size is refused; an unknown arm is an error naming the scene's arms.
TEST(IiwaSim, OneOfSeveralArmsStopsBeforeAnother) {
  IiwaSimOptions options;
  options.scene_path = SourceTreePath("sim/models/scenes/four_arms_or.yaml");
  options.arm = "a0";
  IiwaSim sim(MemqFlags(0), options);
  EXPECT_EQ(sim.options().iiwa_status_channel, "IIWA_STATUS_A0");
  EXPECT_EQ(sim.options().iiwa_command_channel, "IIWA_COMMAND_A0");
  EXPECT_EQ(sim.options().robot_state_channel, "ROBOT_STATE_A0");
  EXPECT_EQ(sim.options().sim_clock_channel, "SIM_CLOCK_A0");
  EXPECT_EQ(sim.options().robot_name, "a0");
  EXPECT_TRUE(sim.scene().X_WR.isApprox(sim.scene().FindArm("a0")->X_WR));
  lcm::LCM& lcm = sim.process().lcm();
  auto dispatch = [&] {
    while (lcm.handleTimeout(0) > 0) {
    }
  };
  std::vector<orbed::robot_state_t> states;
  lcm.subscribeFunction(
      "ROBOT_STATE_A0",
      +[](const lcm::ReceiveBuffer*, const std::string&, const orbed::robot_state_t* m,
          std::vector<orbed::robot_state_t>* out) { out->push_back(*m); },
      &states);

  // a1 upright at its base, as its sim would say.
  const RobotModel& model = sim.arm().model();
  orbed::robot_state_t a1{};
  a1.utime = NowMicros();
  a1.robot_name = "a1";
  a1.X_WR = ToPose(sim.scene().FindArm("a1")->X_WR);
  a1.X_RF = a1.X_RT = ToPose(Eigen::Isometry3d::Identity());
  a1.num_joints = 7;
  a1.joint_position.assign(7, 0.0);
  a1.joint_limit_hit.assign(7, 0);
  for (const Eigen::Isometry3d& X : model.CalcLinkPoses(Eigen::VectorXd::Zero(7))) {
    a1.X_RL.push_back(ToPose(X));
    a1.link_names.push_back("x");
  }
  a1.num_links = static_cast<int32_t>(a1.X_RL.size());
  orbed::robot_state_t wrong = a1;
  wrong.num_links = 3;
  wrong.X_RL.resize(3);
  wrong.link_names.resize(3);
  lcm.publish("ROBOT_STATE_A1", &wrong);
  lcm.publish("ROBOT_STATE_A1", &a1);
  dispatch();
  EXPECT_EQ(sim.process().rejections().counts().at("ROBOT_STATE_A1/field"), 1);

  // Joint 1 to 90 deg (upright, turning in place), then joint 2 to 90 deg: horizontal, toward a1.
  for (const std::vector<double>& q_deg :
       {std::vector<double>{90, 0, 0, 0, 0, 0, 0}, std::vector<double>{90, 90, 0, 0, 0, 0, 0}}) {
    const orbed::iiwa_command_t cmd = Command(q_deg);
    lcm.publish("IIWA_COMMAND_A0", &cmd);
    dispatch();
    for (int k = 0; k < 400 && (k < 2 || states.back().motion_state == orbed::robot_state_t::MOTION_MOVING);
         ++k) {
      sim.Tick();
      dispatch();
    }
  }
  ASSERT_FALSE(states.empty());
  const orbed::robot_state_t& last = states.back();
  EXPECT_EQ(last.motion_state, +orbed::robot_state_t::MOTION_STOPPED_BEFORE_COLLISION) << last.stop_reason;
  EXPECT_NE(last.stop_reason.find(" vs a1/"), std::string::npos) << last.stop_reason;
  EXPECT_LT(last.joint_position[1], 89 * kDegToRad);  // short of its command
  // At rest just outside the stop margin (the last step shortened by bisection).
  EXPECT_GE(sim.arm().collision().closest_other_arm.distance_m, options.stop_margin_m);
  EXPECT_LT(sim.arm().collision().closest_other_arm.distance_m, options.stop_margin_m + 0.01);

  // a1 moves away (folded down the other way): a0's refusal is lifted and it reaches its command.
  a1.X_WR = ToPose(Eigen::Translation3d(-3, 0, 0) * sim.scene().FindArm("a1")->X_WR);
  lcm.publish("ROBOT_STATE_A1", &a1);
  dispatch();
  for (int k = 0; k < 400 && states.back().joint_position[1] < 90 * kDegToRad; ++k) {
    sim.Tick();
    dispatch();
  }
  EXPECT_NEAR(states.back().joint_position[1], 90 * kDegToRad, 1e-12) << states.back().stop_reason;

  options.arm = "a9";
  try {
    IiwaSim unknown(MemqFlags(0), options);
    ADD_FAILURE() << "an unknown arm was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("the arms a0, a1, a2, a3"), std::string::npos) << e.what();
  }
}

TEST(IiwaSim, BadOptionsAndFilesAreNamed) {
  IiwaSimOptions bad_q;
  bad_q.initial_q_deg = {0, 0, 0, 0, 0, 0};
  try {
    IiwaSim sim(MemqFlags(0.1), bad_q);
    FAIL() << "accepted 6 initial angles";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--initial-q-deg"), std::string::npos) << e.what();
  }
  IiwaSimOptions no_file;
  no_file.scene_path = "/nonexistent/scene.yaml";
  try {
    IiwaSim sim(MemqFlags(0.1), no_file);
    FAIL() << "accepted a missing scene";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/scene.yaml"), std::string::npos) << e.what();
  }
  IiwaSimOptions period;
  for (double bad : {0.0, -0.005, 4e-7, std::nan(""), double{INFINITY}}) {  // 4e-7 s rounds to 0 us
    period.period_s = bad;
    EXPECT_THROW(IiwaSim(MemqFlags(0.1), period), std::invalid_argument) << bad;
  }
}

// The command line, in-process.
TEST(IiwaSimCli, HelpGoesToOutAndExitsZero) {
  const test::CommandRun r = test::RunCommand(RunIiwaSim, "orbed-iiwa-sim", {"--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("--period-s"), std::string::npos) << r.out;
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST(IiwaSimCli, RefusesAnUnknownFlagAndBadValues) {
  test::CommandRun r = test::RunCommand(RunIiwaSim, "orbed-iiwa-sim", {"--no-such-flag"});
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("--no-such-flag"), std::string::npos) << r.err;
  r = test::RunCommand(RunIiwaSim, "orbed-iiwa-sim", {"--period-s", "-0.005"});
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("--period-s"), std::string::npos) << r.err;
  // Found when the sim starts, not by the parser: exit 1, the flag named.
  r = test::RunCommand(RunIiwaSim, "orbed-iiwa-sim", {"--lcm-url", "memq://", "--initial-q-deg", "1,2,3"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("orbed-iiwa-sim: --initial-q-deg"), std::string::npos) << r.err;
}

TEST(IiwaSimCli, RunsForTheDurationAndExitsZero) {
  const test::CommandRun r = test::RunCommand(
      RunIiwaSim, "orbed-iiwa-sim",
      {"--lcm-url", "memq://", "--duration-s", "0.1", "--initial-q-deg", "0,30,0,-60,0,45,0"});
  EXPECT_EQ(r.code, 0) << r.err;
}

}  // namespace
}  // namespace orbed::sim
