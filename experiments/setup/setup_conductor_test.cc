// SetupConductor driven by hand in emulated time: a fake arm (ROBOT_STATE at the commanded joints)
// and a fake assistant (SETUP_RESULT). Fixed-display tasks only: the headset modes' alignment is the
// ViRAAl conductor's, tested in experiments/viraal and end to end in setup_integration_test.
#include "experiments/setup/setup_conductor.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <orbed/guidance_t.hpp>

#include "base/json_fields.h"
#include "base/source_paths.h"
#include "base/units.h"

namespace orbed::setup {
namespace {

constexpr int8_t kFixed = orbed::guidance_t::MODE_FIXED_DISPLAY;

sim::RobotModel Model() {
  return sim::RobotModel::LoadFile(SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath));
}

SetupOptions FixedOnly() {
  SetupOptions o;
  o.user = "u3";
  o.modes = {kFixed};
  o.targets_deg = {{10, 20, 0, -60, 0, 40, 0}, {-10, 30, 5, -70, 0, 30, 20}};
  o.start_deg = {0, 20, 0, -60, 0, 40, 0};
  return o;
}

orbed::robot_state_t State(const std::vector<double>& q_deg, int8_t motion) {
  orbed::robot_state_t s{};
  s.X_WR.quaternion_wxyz[0] = 1;
  s.num_joints = static_cast<int32_t>(q_deg.size());
  for (double q : q_deg) {
    s.joint_position.push_back(q * kDegToRad);
    s.joint_limit_hit.push_back(0);
  }
  s.motion_state = motion;
  return s;
}

ConductorTime At(double t_s) { return ConductorTime{t_s, 1'000'000'000 + static_cast<int64_t>(t_s * 1e6)}; }

const orbed::setup_task_t* FindTask(const SetupConductor::Actions& a) {
  for (const SetupPublication& p : a.publish) {
    if (const auto* task = std::get_if<orbed::setup_task_t>(&p.message)) return task;
  }
  return nullptr;
}

// The assistant's answer to `task`: all joints at 0, one range each.
orbed::setup_result_t Answer(const orbed::setup_task_t& task, double execution_s, double person_scale) {
  orbed::setup_result_t r{};
  r.request_id = task.request_id;
  r.task_id = task.task_id;
  r.mode = task.mode;
  r.num_joints = 7;
  r.reached_position.assign(7, 0.0);
  r.ranges.assign(7, 1);
  r.execution_s = execution_s;
  r.person_scale = person_scale;
  return r;
}

TEST(SetupConductor, ParksThenAsksForEachTargetAndRecordsTheSimsJoints) {
  SetupConductor c(FixedOnly(), Model());
  c.Start(At(0));
  // The arm somewhere else: the conductor parks it (IIWA_COMMAND to the start), no task yet.
  SetupConductor::Actions a = c.OnRobotState(State({5, 5, 5, -50, 5, 5, 5}, 0), At(0.1));
  ASSERT_EQ(a.publish.size(), 1u);
  const auto* command = std::get_if<orbed::iiwa_command_t>(&a.publish[0].message);
  ASSERT_NE(command, nullptr);
  EXPECT_NEAR(command->joint_position[3], -60 * kDegToRad, 1e-12);
  EXPECT_EQ(FindTask(a), nullptr);
  // At the start and at rest: the first task.
  a = c.OnRobotState(State({0, 20, 0, -60, 0, 40, 0}, 0), At(0.5));
  const orbed::setup_task_t* task = FindTask(a);
  ASSERT_NE(task, nullptr);
  EXPECT_EQ(task->task_id, "u3-fixed-1");
  EXPECT_EQ(task->mode, kFixed);
  EXPECT_NEAR(task->target_position[0], 10 * kDegToRad, 1e-12);
  const orbed::setup_task_t first = *task;
  // Unanswered, it is re-sent unchanged after task_resend_s.
  EXPECT_EQ(FindTask(c.Tick(At(0.9))), nullptr);
  a = c.Tick(At(1.6));
  ASSERT_NE(FindTask(a), nullptr);
  EXPECT_EQ(FindTask(a)->request_id, first.request_id);

  // The assistant's answer; the sim says the arm is at (12, 20, ...): the record takes the sim's,
  // from the first state at rest handled after the answer (not the one before it, nor a moving one).
  c.OnRobotState(State({11, 20, 0, -60, 0, 40, 0}, 0), At(2.0));
  orbed::setup_result_t r = Answer(first, 95, 1.1);
  orbed::setup_result_t other = r;
  other.request_id = first.request_id + 100;  // someone else's: ignored
  EXPECT_TRUE(c.OnSetupResult(other, At(2.1)).publish.empty());
  EXPECT_TRUE(c.run().setups.empty());
  orbed::setup_result_t bad = r;
  bad.execution_s = -1;
  EXPECT_EQ(c.OnSetupResult(bad, At(2.15)).refusals.size(), 1u);
  c.OnSetupResult(r, At(2.2));
  EXPECT_TRUE(c.run().setups.empty());
  c.OnSetupResult(r, At(2.21));  // a repeat while waiting changes nothing
  EXPECT_TRUE(
      c.OnRobotState(State({11.5, 20, 0, -60, 0, 40, 0}, orbed::robot_state_t::MOTION_MOVING), At(2.22))
          .publish.empty());
  EXPECT_TRUE(c.run().setups.empty());
  EXPECT_EQ(FindTask(c.Tick(At(3.5))), nullptr);  // answered: no more re-sends while waiting
  c.OnRobotState(State({12, 20, 0, -60, 0, 40, 0}, 0), At(3.6));
  ASSERT_EQ(c.run().setups.size(), 1u);
  const SetupRecord& rec = c.run().setups[0];
  EXPECT_EQ(rec.target, 1);
  EXPECT_EQ(rec.order, 1);
  EXPECT_NEAR(rec.reached_deg[0], 12.0, 1e-9);
  EXPECT_NEAR(rec.assistant_reached_deg[0], 0.0, 1e-9);
  EXPECT_EQ(rec.execution_s, 95);
  EXPECT_FALSE(rec.alignment_s.has_value());
  EXPECT_EQ(rec.twisting, (std::vector<int>{1, 0, 1, 0, 1, 0, 1}));
  // A repeat of the answer changes nothing; the second target is next (after parking again).
  c.OnSetupResult(r, At(3.7));
  EXPECT_EQ(c.run().setups.size(), 1u);
  a = c.OnRobotState(State({0, 20, 0, -60, 0, 40, 0}, 0), At(3.8));
  ASSERT_NE(FindTask(a), nullptr);
  EXPECT_EQ(FindTask(a)->task_id, "u3-fixed-2");
  r.request_id = FindTask(a)->request_id;
  c.OnSetupResult(r, At(4.0));
  EXPECT_FALSE(c.done());
  c.OnRobotState(State({10, 20, 0, -60, 0, 40, 0}, 0), At(4.1));
  EXPECT_TRUE(c.done());
  EXPECT_TRUE(c.run().ok);
  const std::string json = SetupRunJson(c.run(), false);
  EXPECT_NE(json.find("\"status\": \"ok\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"alignment_s\": null"), std::string::npos) << json;
}

orbed::collision_status_t Clearance(double min_distance_m, bool in_collision) {
  orbed::collision_status_t m{};
  m.min_distance_m = min_distance_m;
  m.in_collision = in_collision;
  return m;
}

// A run of FixedOnly() stopped after its first set-up, as the file it left says.
SetupRun StoppedAfterOne(std::string* json) {
  SetupConductor c(FixedOnly(), Model());
  c.Start(At(0));
  const orbed::setup_task_t first = *FindTask(c.OnRobotState(State({0, 20, 0, -60, 0, 40, 0}, 0), At(0.1)));
  c.OnCollisionStatus(Clearance(0.03, false), At(0.2));
  c.OnSetupResult(Answer(first, 80, 0.9), At(0.5));
  c.OnRobotState(State({11, 21, 0, -60, 0, 40, 0}, 0), At(0.6));
  *json = SetupRunJson(c.run(), true);
  return c.run();
}

std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

// setup_results.json read back gives the same document, byte for byte, alignment included.
TEST(SetupResume, TheResultsFileReadsBackToTheSameDocument) {
  std::string json;
  SetupRun run = StoppedAfterOne(&json);
  SetupRecord aligned = run.setups[0];
  aligned.task_id = "u3-ar-1";
  aligned.mode = orbed::guidance_t::MODE_AR;
  aligned.alignment_s = 141.5;
  viraal::SessionResult session;
  session.session_id = "setup-u3-ar-1-ar";
  session.trials.resize(3);
  session.mean.emplace();
  session.mean->errors.translation_error_mm = 12.25;
  session.mean->errors.rotation_error_deg = 0.125;
  session.mean->errors.misalignment_mm = 9.5;
  aligned.alignment = session;
  aligned.min_clearance_m.reset();
  run.setups.push_back(aligned);
  const std::string text = SetupRunJson(run, true);
  std::string status;
  const SetupRun back = ReadSetupRunFile(WriteTemp("setup_results.json", text), &status);
  EXPECT_EQ(status, "partial");
  EXPECT_EQ(SetupRunJson(back, true), text);
  // A folder names its setup_results.json.
  EXPECT_EQ(SetupRunJson(ReadSetupRunFile(::testing::TempDir(), &status), true), text);
}

TEST(SetupResume, DamagedFilesAreRefusedNamingTheKey) {
  std::string json;
  StoppedAfterOne(&json);
  std::string status;
  auto refusal = [&](const std::string& from, const std::string& to) {
    std::string text = json;
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    try {
      ReadSetupRunFile(WriteTemp("damaged.json", text), &status);
    } catch (const JsonReadError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(refusal("\"status\": \"partial\"", "\"status\": \"maybe\"").find("status"), std::string::npos);
  EXPECT_NE(refusal("\"mode\": \"fixed\"", "\"mode\": \"hologram\"").find("setups[0].mode"),
            std::string::npos);
  EXPECT_NE(refusal("\"execution_s\": 80", "\"execution_s\": -80").find("execution_s"), std::string::npos);
  EXPECT_NE(refusal("\"contact\": false", "\"contact\": 0").find("contact"), std::string::npos);
  EXPECT_NE(refusal("\"order\": 1", "\"order\": 9").find("order"), std::string::npos);
  EXPECT_NE(refusal("\"user\": \"u3\",", "").find("user"), std::string::npos);
}

// A resumed run keeps the finished set-ups and starts with the next one; the final file holds both.
TEST(SetupResume, ARunResumesWithTheNextSetUp) {
  std::string json;
  const SetupRun earlier = StoppedAfterOne(&json);
  SetupOptions o = FixedOnly();
  o.kept = KeptSetups(earlier, "partial", o);
  ASSERT_EQ(o.kept.size(), 1u);
  SetupConductor c(o, Model());
  const SetupConductor::Actions started = c.Start(At(0));
  ASSERT_FALSE(started.progress.empty());
  EXPECT_NE(started.progress[0].find("resumed with the 1 set-up(s) kept, next u3-fixed-2"), std::string::npos)
      << started.progress[0];
  const SetupConductor::Actions parked = c.OnRobotState(State({0, 20, 0, -60, 0, 40, 0}, 0), At(0.1));
  const orbed::setup_task_t* task = FindTask(parked);
  ASSERT_NE(task, nullptr);
  EXPECT_EQ(task->task_id, "u3-fixed-2");
  EXPECT_NEAR(task->target_position[0], -10 * kDegToRad, 1e-12);
  c.OnSetupResult(Answer(*task, 70, 0.9), At(0.5));
  c.OnRobotState(State({-9, 20, 0, -60, 0, 40, 0}, 0), At(0.6));
  ASSERT_TRUE(c.done());
  ASSERT_EQ(c.run().setups.size(), 2u);
  EXPECT_EQ(c.run().setups[0].task_id, "u3-fixed-1");
  EXPECT_NEAR(c.run().setups[0].reached_deg[0], 11.0, 1e-9);
  EXPECT_EQ(c.run().setups[1].task_id, "u3-fixed-2");
  EXPECT_TRUE(c.run().ok);
}

TEST(SetupResume, WhatDoesNotBelongToThisRunIsRefused) {
  std::string json;
  const SetupRun earlier = StoppedAfterOne(&json);
  auto why = [&](SetupRun run, const std::string& status, SetupOptions o) {
    try {
      KeptSetups(run, status, o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const SetupOptions o = FixedOnly();
  EXPECT_NE(why(earlier, "ok", o).find("nothing is left"), std::string::npos);
  SetupOptions other = o;
  other.user = "u4";
  EXPECT_NE(why(earlier, "partial", other).find("user"), std::string::npos);
  other = o;
  other.run_id = "another";
  EXPECT_NE(why(earlier, "partial", other).find("run id"), std::string::npos);
  other = o;
  other.targets_deg[0][2] = 1;
  EXPECT_NE(why(earlier, "partial", other).find("target"), std::string::npos);
  other = o;
  other.targets_deg.resize(1);  // the one set-up is all this run has
  EXPECT_NE(why(earlier, "partial", other).find("nothing is left"), std::string::npos);
  SetupRun shuffled = earlier;
  shuffled.setups[0].task_id = "u3-fixed-2";
  EXPECT_NE(why(shuffled, "failed", o).find("set-up 1 is u3-fixed-2"), std::string::npos);
}

// Clearance and collision stops are what happened while the assistant had the arm: what came
// before the task (parking) does not count, a stop that lasts several messages counts once, a
// bad COLLISION_STATUS is refused and changes nothing.
TEST(SetupConductor, RecordsClearanceAndStopsDuringTheSetUpOnly) {
  SetupConductor c(FixedOnly(), Model());
  c.Start(At(0));
  c.OnCollisionStatus(Clearance(-0.01, true), At(0.05));  // before the task: not the assistant's
  SetupConductor::Actions a = c.OnRobotState(State({0, 20, 0, -60, 0, 40, 0}, 0), At(0.1));
  const orbed::setup_task_t* task = FindTask(a);
  ASSERT_NE(task, nullptr);
  const orbed::setup_task_t first = *task;
  constexpr int8_t kStopped = orbed::robot_state_t::MOTION_STOPPED_BEFORE_COLLISION;
  constexpr int8_t kMoving = orbed::robot_state_t::MOTION_MOVING;
  c.OnCollisionStatus(Clearance(0.20, false), At(0.2));
  c.OnRobotState(State({2, 20, 0, -60, 0, 40, 0}, kMoving), At(0.3));
  c.OnCollisionStatus(Clearance(0.004, false), At(0.4));
  c.OnRobotState(State({3, 20, 0, -60, 0, 40, 0}, kStopped), At(0.5));
  c.OnRobotState(State({3, 20, 0, -60, 0, 40, 0}, kStopped), At(0.6));
  c.OnRobotState(State({3, 20, 0, -60, 0, 40, 0}, kMoving), At(0.7));
  c.OnRobotState(State({4, 20, 0, -60, 0, 40, 0}, kStopped), At(0.8));
  EXPECT_EQ(c.OnCollisionStatus(Clearance(std::nan(""), true), At(0.85)).refusals.size(), 1u);
  c.OnCollisionStatus(Clearance(0.05, false), At(0.9));
  c.OnSetupResult(Answer(first, 60, 1), At(1.0));
  c.OnRobotState(State({10, 20, 0, -60, 0, 40, 0}, 0), At(1.1));
  ASSERT_EQ(c.run().setups.size(), 1u);
  const SetupRecord& rec = c.run().setups[0];
  ASSERT_TRUE(rec.min_clearance_m.has_value());
  EXPECT_EQ(*rec.min_clearance_m, 0.004);
  EXPECT_FALSE(rec.contact);
  EXPECT_EQ(rec.collision_stops, 2);
  // Reached the target exactly: no docking error.
  EXPECT_NEAR(rec.docking_tip_mm, 0, 1e-9);
  EXPECT_NEAR(rec.docking_axis_deg, 0, 1e-6);
  const std::string json = SetupRunJson(c.run(), true);
  EXPECT_NE(json.find("\"collision_stops\": 2"), std::string::npos) << json;
  EXPECT_NE(json.find("\"contact\": false"), std::string::npos) << json;
}

// The docking error against closed forms. The iiwa 7's joint 7 turns the flange about the tool
// axis: no error at all. Joint 6 swings the tool about an axis through the wrist point, which lies
// on the tool axis 0.126 m behind the flange (KUKA data sheet, DH d7): the axis turns by the joint
// error θ and the tip moves on a circle of radius 0.126 m + the tool length, a chord 2 r sin(θ/2).
// Joint 1 turns everything about the base's vertical z: the tip moves on a circle of its horizontal
// distance ρ from z, and a tool axis at α from z turns by acos(cos²α + sin²α cos θ).
TEST(DockingError, ClosedForms) {
  const sim::RobotModel model = Model();
  const std::vector<double> target = {10, 40, -20, -70, 30, 50, 15};
  std::vector<double> reached = target;
  reached[6] += 37;
  Docking d = DockingError(model, target, reached);
  EXPECT_NEAR(d.tip_mm, 0, 1e-9);
  EXPECT_NEAR(d.axis_deg, 0, 1e-9);

  const double theta_deg = 12;
  reached = target;
  reached[5] += theta_deg;
  d = DockingError(model, target, reached);
  EXPECT_NEAR(d.axis_deg, theta_deg, 1e-9);
  const double r_m = 0.126 + model.tool_length_m();
  EXPECT_NEAR(d.tip_mm, 2 * r_m * std::sin(theta_deg * kDegToRad / 2) * 1e3, 1e-6);

  reached = target;
  reached[0] += theta_deg;
  d = DockingError(model, target, reached);
  Eigen::VectorXd q(7);
  for (int i = 0; i < 7; ++i) q[i] = target[i] * kDegToRad;
  const Eigen::Isometry3d X_RT = model.CalcToolTipPose(q);
  const double rho_m = X_RT.translation().head<2>().norm();
  const double cos_alpha = X_RT.linear()(2, 2);
  const double c = std::cos(theta_deg * kDegToRad);
  EXPECT_NEAR(d.tip_mm, 2 * rho_m * std::sin(theta_deg * kDegToRad / 2) * 1e3, 1e-6);
  EXPECT_NEAR(d.axis_deg, std::acos(cos_alpha * cos_alpha + (1 - cos_alpha * cos_alpha) * c) * kRadToDeg,
              1e-6);
  EXPECT_THROW(DockingError(model, target, {1, 2}), std::invalid_argument);
}

// The registration's share: a headset mode with perfect_registration aligns nobody; every
// SETUP_TASK goes with a REGISTRATION whose mean is the true base pose of the latest ROBOT_STATE.
TEST(SetupConductor, PerfectRegistrationPublishesTheTrueBasePose) {
  SetupOptions o = FixedOnly();
  o.modes = {orbed::guidance_t::MODE_AR};
  o.targets_deg.resize(1);
  o.perfect_registration = true;
  SetupConductor c(o, Model());
  c.Start(At(0));
  orbed::robot_state_t state = State({0, 20, 0, -60, 0, 40, 0}, 0);
  state.X_WR.position_m[0] = 1.5;
  state.X_WR.position_m[1] = -0.25;
  state.X_WR.quaternion_wxyz[0] = std::sqrt(0.5);
  state.X_WR.quaternion_wxyz[3] = std::sqrt(0.5);
  SetupConductor::Actions a = c.OnRobotState(state, At(0.1));
  EXPECT_TRUE(a.viraal.empty());  // no alignment session
  ASSERT_EQ(a.publish.size(), 2u);
  const auto* truth = std::get_if<orbed::registration_t>(&a.publish[0].message);
  ASSERT_NE(truth, nullptr);
  EXPECT_EQ(a.publish[0].channel, "REGISTRATION");
  EXPECT_TRUE(truth->valid);
  EXPECT_EQ(truth->num_trials, 0);
  EXPECT_EQ(truth->session_id, "setup-u3-ar-1-truth");
  for (int i = 0; i < 3; ++i) EXPECT_EQ(truth->X_WV_mean.position_m[i], state.X_WR.position_m[i]);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(truth->X_WV_mean.quaternion_wxyz[i], state.X_WR.quaternion_wxyz[i]);
  ASSERT_NE(FindTask(a), nullptr);
  const orbed::setup_task_t task = *FindTask(a);
  // Re-sent with the task.
  a = c.Tick(At(1.2));
  ASSERT_EQ(a.publish.size(), 2u);
  EXPECT_NE(std::get_if<orbed::registration_t>(&a.publish[0].message), nullptr);
  c.OnSetupResult(Answer(task, 60, 1), At(1.5));
  c.OnRobotState(state, At(1.6));
  ASSERT_TRUE(c.done());
  ASSERT_EQ(c.run().setups.size(), 1u);
  EXPECT_TRUE(c.run().setups[0].perfect_registration);
  EXPECT_FALSE(c.run().setups[0].alignment_s.has_value());
  EXPECT_NE(SetupRunJson(c.run(), false).find("\"registration\": \"truth\""), std::string::npos);
}

// The design: per-target starts and ids, the same (start, target) pairs in every mode in the same
// order, and the retract after each set-up (without a scene: joints 4, 2, 6, 1 zeroed one after
// the other, then the zero configuration) before the next park. A fake arm goes wherever it is commanded; the
// fake assistant leaves it 1 deg past every joint of the target.
TEST(SetupConductor, TheDesignsPairsAreTheSameInEveryModeWithARetractBetween) {
  SetupOptions o = FixedOnly();
  o.modes = {kFixed, orbed::guidance_t::MODE_AR};
  o.perfect_registration = true;  // no alignment: the pairs alone
  o.retract = true;
  o.starts_deg = {{0, -20, 0, 60, 0, -40, 0}, {-90, 20, 0, -60, 0, 40, 0}};
  o.start_ids = {"ready_away", "aside"};
  o.target_ids = {"medium/umbilicus/1", "medium/umbilicus/2"};
  SetupConductor c(o, Model());
  c.Start(At(0));
  std::vector<double> arm = {0, 0, 0, 0, 0, 0, 0};
  std::vector<std::vector<double>> commands;  // every distinct IIWA_COMMAND, in order
  double t = 0.1;
  SetupConductor::Actions a = c.OnRobotState(State(arm, 0), At(t));
  for (int step = 0; step < 200 && !c.done(); ++step) {
    t += 0.5;
    if (const orbed::setup_task_t* task = FindTask(a)) {
      std::vector<double> reached;
      for (double q : task->target_position) reached.push_back(q * kRadToDeg + 1.0);
      c.OnSetupResult(Answer(*task, 50, 1), At(t));
      arm = reached;
      a = c.OnRobotState(State(arm, 0), At(t + 0.1));
      continue;
    }
    for (const SetupPublication& p : a.publish) {
      if (const auto* command = std::get_if<orbed::iiwa_command_t>(&p.message)) {
        arm.clear();
        for (double q : command->joint_position) arm.push_back(q * kRadToDeg);
        if (commands.empty() || commands.back() != arm) commands.push_back(arm);
      }
    }
    a = c.OnRobotState(State(arm, 0), At(t));
  }
  ASSERT_TRUE(c.done());
  ASSERT_TRUE(c.run().ok) << c.run().error;
  ASSERT_EQ(c.run().setups.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    const SetupRecord& r = c.run().setups[i];
    const size_t k = i % 2;  // the same pair at the same place in both modes
    EXPECT_EQ(r.target, static_cast<int>(k) + 1);
    EXPECT_EQ(r.start_id, o.start_ids[k]);
    EXPECT_EQ(r.target_id, o.target_ids[k]);
    EXPECT_EQ(r.start_deg, o.starts_deg[k]);
    EXPECT_EQ(r.target_deg, o.targets_deg[k]);
  }
  // Start 1; then after each set-up: straightened, candle, the next start.
  auto zeroed = [](std::vector<double> q, std::vector<int> joints) {
    for (int j : joints) q[j] = 0;
    return q;
  };
  auto past = [](std::vector<double> q) {
    for (double& v : q) v += 1.0;
    return q;
  };
  const std::vector<double> zero(7, 0.0);
  std::vector<std::vector<double>> expected = {o.starts_deg[0]};
  for (size_t k : {0, 1, 0}) {
    const std::vector<double> reached = past(o.targets_deg[k]);
    for (const std::vector<double>& q : {zeroed(reached, {3}), zeroed(reached, {3, 1}),
                                         zeroed(reached, {3, 1, 5}), zeroed(reached, {3, 1, 5, 0}), zero})
      expected.push_back(q);
    expected.push_back(o.starts_deg[1 - k]);
  }
  ASSERT_EQ(commands.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    for (size_t j = 0; j < 7; ++j) EXPECT_NEAR(commands[i][j], expected[i][j], 1e-9) << i << " " << j;
  }
  // The ids and the start come back from the file; a run with another start is refused.
  const std::string json = SetupRunJson(c.run(), true);
  EXPECT_NE(json.find("\"target_id\": \"medium/umbilicus/2\""), std::string::npos) << json;
  std::string status;
  SetupRun back = ParseSetupRunJson(json, "setup_results.json", &status);
  EXPECT_EQ(SetupRunJson(back, true), json);
  back.setups.resize(3);
  EXPECT_EQ(KeptSetups(back, "partial", o).size(), 3u);
  SetupOptions other = o;
  other.starts_deg[1] = {0, 20, 0, -60, 0, 40, 0};
  EXPECT_THROW(KeptSetups(back, "partial", other), std::invalid_argument);
  other = o;
  other.target_ids[0] = "small/umbilicus/1";
  EXPECT_THROW(KeptSetups(back, "partial", other), std::invalid_argument);
  // A file from before the design (no ids, no start) still reads.
  nlohmann::json doc = nlohmann::json::parse(json);
  for (auto& r : doc["setups"]) {
    for (const char* key : {"start_id", "target_id", "start_deg"}) r.erase(key);
  }
  const SetupRun read = ParseSetupRunJson(doc.dump(), "old.json", &status);
  ASSERT_EQ(read.setups.size(), 4u);
  EXPECT_TRUE(read.setups[0].start_id.empty());
  EXPECT_TRUE(read.setups[0].start_deg.empty());
  EXPECT_EQ(read.setups[3].target_deg, o.targets_deg[1]);
}

TEST(SetupConductor, TimeoutsNameWhoDidNotAnswer) {
  {
    SetupConductor c(FixedOnly(), Model());
    c.Start(At(0));
    c.Tick(At(11));
    EXPECT_TRUE(c.done());
    EXPECT_NE(c.run().error.find("orbed-iiwa-sim"), std::string::npos) << c.run().error;
  }
  {
    SetupOptions o = FixedOnly();
    o.task_timeout_s = 5;
    SetupConductor c(o, Model());
    c.Start(At(0));
    c.OnRobotState(State({0, 20, 0, -60, 0, 40, 0}, 0), At(0.1));
    c.Tick(At(6));
    EXPECT_TRUE(c.done());
    EXPECT_FALSE(c.run().ok);
    EXPECT_NE(c.run().error.find("orbed-assistant"), std::string::npos) << c.run().error;
  }
  {
    SetupOptions o = FixedOnly();
    o.task_timeout_s = 5;
    SetupConductor c(o, Model());
    c.Start(At(0));
    const orbed::setup_task_t task = *FindTask(c.OnRobotState(State({0, 20, 0, -60, 0, 40, 0}, 0), At(0.1)));
    c.OnSetupResult(Answer(task, 60, 1), At(1.0));
    c.Tick(At(6));
    EXPECT_TRUE(c.done());
    EXPECT_FALSE(c.run().ok);
    EXPECT_NE(c.run().error.find("no ROBOT_STATE with the arm at rest"), std::string::npos) << c.run().error;
  }
}

TEST(SetupConductor, RefusesBadOptions) {
  SetupOptions o = FixedOnly();
  o.modes = {kFixed, kFixed};
  EXPECT_THROW(SetupConductor(o, Model()), std::invalid_argument);
  o = FixedOnly();
  o.targets_deg[0][1] = 130;  // joint 2's limit is 120
  EXPECT_THROW(SetupConductor(o, Model()), std::invalid_argument);
  o = FixedOnly();
  o.start_deg.pop_back();
  EXPECT_THROW(SetupConductor(o, Model()), std::invalid_argument);
}

}  // namespace
}  // namespace orbed::setup
