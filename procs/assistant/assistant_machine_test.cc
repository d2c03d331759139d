// The set-up assistant's state machine (assistant_machine.h) in emulated time, on the shipped iiwa 7
// model: no bus, no clock; the test steps it at times it chooses and plays the arm. Oracles: the
// phases of the file comment counted by hand (two steps per look with an arm that is there at
// once, a re-send every command_resend_s, a timeout after move_timeout_s), and the time model in
// closed form for a person who sees and places perfectly (assistant.h).
#include "procs/assistant/assistant_machine.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <orbed/robot_state_t.hpp>

#include "base/source_paths.h"
#include "base/units.h"
#include "procs/assistant/assistant_test_people.h"

namespace orbed::assistant {
namespace {

// Steps of 1/32 s and re-sends of 1/4 s: sums of them are exact in binary, so "every 8 steps" is.
constexpr double kStep_s = 1.0 / 32;

using test::Model;
using test::Perfect;

orbed::guidance_t Guidance(int8_t mode, const Eigen::VectorXd& q_target) {
  return test::Guidance(mode, std::vector<double>(q_target.data(), q_target.data() + q_target.size()),
                        static_cast<int>(q_target.size()));
}

// Joint angles on the grid a first look searches (kGridStepDeg from each joint's lower limit), near
// `deg`: a perfect person's first look lands on them exactly.
Eigen::VectorXd OnGrid(const sim::RobotModel& model, std::initializer_list<double> deg) {
  Eigen::VectorXd q(static_cast<int>(deg.size()));
  int i = 0;
  const double step = kGridStepDeg * kDegToRad;
  for (double d : deg) {
    const double lower = model.joints()[i].lower_rad;
    q[i] = lower + std::round((d * kDegToRad - lower) / step) * step;
    ++i;
  }
  return q;
}

orbed::setup_task_t Task(int64_t request_id, int8_t mode, const Eigen::VectorXd& q_target) {
  orbed::setup_task_t t{};
  t.request_id = request_id;
  t.task_id = "u1-ar-1";
  t.mode = mode;
  t.num_joints = static_cast<int32_t>(q_target.size());
  for (int i = 0; i < q_target.size(); ++i) t.target_position.push_back(q_target[i]);
  return t;
}

// The arm as the test plays it: where it is, its motion state, and whether it follows commands
// (at once: the next step sees it there, at rest).
struct Arm {
  Eigen::VectorXd q;
  int8_t motion{orbed::robot_state_t::MOTION_IDLE};
  bool follows{true};
};

// What a run of steps produced.
struct Stepped {
  std::vector<StepOutput> outputs;                        // one per step
  std::vector<std::pair<int, Eigen::VectorXd>> commands;  // (step, joint_position)
  int finished_step{-1};
  int failed_step{-1};
};

// Steps `machine` `steps` times from step `first` (t = k · kStep_s, utime = 1000 + k), playing `arm`.
Stepped Steps(AssistantMachine* machine, Arm* arm, int first, int steps) {
  Stepped run;
  for (int k = first; k < first + steps; ++k) {
    StepOutput out = machine->Step(k * kStep_s, 1000 + k);
    if (out.command) {
      EXPECT_EQ(out.command->utime, 1000 + k);
      const Eigen::VectorXd q =
          Eigen::Map<const Eigen::VectorXd>(out.command->joint_position.data(), out.command->num_joints);
      run.commands.emplace_back(k, q);
      if (arm->follows) {
        arm->q = q;
        machine->OnJoints(arm->q);
      }
    }
    if (out.finished) run.finished_step = k;
    if (!out.failure.empty()) run.failed_step = k;
    run.outputs.push_back(std::move(out));
  }
  return run;
}

MachineOptions Options() {
  MachineOptions o;
  o.command_resend_s = 0.25;
  o.move_timeout_s = 30.0;
  return o;
}

class AssistantMachineTest : public ::testing::Test {
 protected:
  AssistantMachineTest() : model_(Model()) {
    q_start_ = OnGrid(model_, {0, 30, 0, -60, 0, 45, 0});
    q_target_ = OnGrid(model_, {30, 30, 0, -60, 0, 45, 0});  // joint 1 turned by 30 deg
    arm_.q = q_start_;
  }
  // Everything a headset set-up needs but the task and GUIDANCE: the arm at rest, the robot at the
  // origin and a perfect registration.
  void FeedTheRoom(AssistantMachine* m) {
    m->OnJoints(arm_.q);
    m->OnRobotState(Eigen::Isometry3d::Identity(), arm_.motion);
    m->OnRegistration(Eigen::Isometry3d::Identity());
  }
  sim::RobotModel model_;
  Eigen::VectorXd q_start_, q_target_;
  Arm arm_;
};

// A whole task, 7 joints x 2 looks, one look per step: a look whose joint must move sends the
// command and the arrival is seen at the next step; a look that leaves the joint where it is has
// arrived at once. Here only joint 1's first look moves (onto the target: step 10, arrival 11), so
// the other 13 looks take steps 12 ... 24 and the set-up finishes at step 24 after one command. The
// time model's total is 7 · joint_overhead_s + 14 · look_s + 30 deg / hand_speed_deg_per_s. A
// repeat of the task's id is answered with the very same SETUP_RESULT.
TEST_F(AssistantMachineTest, ATaskIsSetUpJointByJointInEmulatedTime) {
  const AssistantConfig config = Perfect();
  AssistantMachine m(model_, config, Options());
  EXPECT_EQ(m.phase(), AssistantMachine::Phase::kIdle);
  FeedTheRoom(&m);
  m.OnGuidance(Guidance(orbed::guidance_t::MODE_AR, q_target_));
  EXPECT_TRUE(Steps(&m, &arm_, 0, 3).commands.empty());  // no task yet: idle

  const TaskAnswer answer = m.OnSetupTask(Task(7, orbed::guidance_t::MODE_AR, q_target_));
  EXPECT_EQ(answer.kind, TaskAnswer::kStarted);
  EXPECT_FALSE(answer.reply);
  EXPECT_EQ(m.phase(), AssistantMachine::Phase::kWait);

  const Stepped run = Steps(&m, &arm_, 10, 40);
  ASSERT_EQ(run.commands.size(), 1u);
  EXPECT_EQ(run.commands[0].first, 10);
  EXPECT_NEAR(run.commands[0].second[0], q_target_[0], 1e-12);  // joint 1 onto the target
  for (int i = 1; i < 7; ++i) EXPECT_NEAR(run.commands[0].second[i], q_start_[i], 1e-12);
  // One note per look, in order: joint j look l at step 10 (j, l = 1, 1), then 12 + (2(j−1) + l − 2).
  std::vector<std::string> looks;
  for (int k = 0; k < 40; ++k) {
    for (const MachineNote& note : run.outputs[k].notes) {
      if (note.text.find(" look ") != std::string::npos)
        looks.push_back(std::to_string(10 + k) + ": " + note.text.substr(0, note.text.find(":", 11)));
    }
  }
  ASSERT_EQ(looks.size(), 14u);
  EXPECT_EQ(looks[0], "10: assistant: joint 1 look 1");
  EXPECT_EQ(looks[1], "12: assistant: joint 1 look 2");
  EXPECT_EQ(looks[2], "13: assistant: joint 2 look 1");
  EXPECT_EQ(looks[13], "24: assistant: joint 7 look 2");
  EXPECT_EQ(run.finished_step, 24);
  EXPECT_EQ(m.phase(), AssistantMachine::Phase::kDone);

  ASSERT_TRUE(m.result());
  const SetupResult& r = *m.result();
  EXPECT_EQ(r.mode, int8_t{orbed::guidance_t::MODE_AR});
  EXPECT_EQ(r.seed, config.seed);
  EXPECT_EQ(r.person_scale, 1.0);
  EXPECT_FALSE(r.headset_pose);  // no HMD poses came
  EXPECT_TRUE(r.q_start_rad.isApprox(q_start_));
  EXPECT_LT((r.q_reached_rad - q_target_).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_EQ(r.twisting, (std::vector<int>{1, 0, 1, 0, 1, 0, 1}));
  EXPECT_EQ(r.ranges.size(), 7u);
  const double travel_s = std::abs(q_target_[0] - q_start_[0]) * kRadToDeg / config.hand_speed_deg_per_s;
  EXPECT_NEAR(travel_s, 2.0, 0.25 / config.hand_speed_deg_per_s);  // 30 deg, to the grid
  EXPECT_NEAR(r.execution_s, 7 * config.joint_overhead_s + 14 * config.look_s + travel_s, 1e-9);

  const StepOutput& last = run.outputs[24 - 10];
  ASSERT_TRUE(last.task_reply);
  EXPECT_EQ(last.task_reply->utime, 1000 + 24);
  EXPECT_EQ(last.task_reply->request_id, 7);
  EXPECT_EQ(last.task_reply->task_id, "u1-ar-1");
  EXPECT_EQ(last.task_reply->mode, int8_t{orbed::guidance_t::MODE_AR});
  EXPECT_EQ(last.task_reply->execution_s, r.execution_s);
  EXPECT_EQ(last.task_reply->ranges, r.ranges);
  EXPECT_EQ(last.task_reply->reached_position.size(), 7u);
  EXPECT_FALSE(last.stop);  // serving tasks, not --once

  // Done: further steps do nothing; the repeat gets the same message back.
  EXPECT_TRUE(Steps(&m, &arm_, 50, 20).commands.empty());
  const TaskAnswer repeat = m.OnSetupTask(Task(7, orbed::guidance_t::MODE_AR, q_target_));
  EXPECT_EQ(repeat.kind, TaskAnswer::kRepeat);
  ASSERT_TRUE(repeat.reply);
  EXPECT_EQ(repeat.reply->utime, last.task_reply->utime);
  EXPECT_EQ(repeat.reply->execution_s, last.task_reply->execution_s);

  // A new id starts over from the arm where it is: nothing to move (no command, 14 looks in steps
  // 100 ... 113), the travel time is gone.
  EXPECT_EQ(m.OnSetupTask(Task(8, orbed::guidance_t::MODE_AR, q_target_)).kind, TaskAnswer::kStarted);
  const Stepped again = Steps(&m, &arm_, 100, 40);
  EXPECT_TRUE(again.commands.empty());
  EXPECT_EQ(again.finished_step, 113);
  EXPECT_NEAR(m.result()->execution_s, 7 * config.joint_overhead_s + 14 * config.look_s, 1e-9);
}

// kWait: a GUIDANCE that shows another target (or mode) than the task's, a moving arm, or a
// headset mode without a REGISTRATION hold the set-up; the missing registration is noted once.
TEST_F(AssistantMachineTest, TheSetUpWaitsForItsGuidanceARegistrationAndTheArmAtRest) {
  AssistantMachine m(model_, Perfect(), Options());
  m.OnJoints(arm_.q);
  m.OnRobotState(Eigen::Isometry3d::Identity(), orbed::robot_state_t::MOTION_IDLE);
  ASSERT_EQ(m.OnSetupTask(Task(1, orbed::guidance_t::MODE_AR, q_target_)).kind, TaskAnswer::kStarted);

  m.OnGuidance(Guidance(orbed::guidance_t::MODE_FIXED_DISPLAY, q_target_));  // another mode
  const Stepped other_mode = Steps(&m, &arm_, 0, 5);
  EXPECT_TRUE(other_mode.commands.empty());
  m.OnGuidance(Guidance(orbed::guidance_t::MODE_AR, q_start_));  // an earlier target
  const Stepped other_target = Steps(&m, &arm_, 5, 5);
  EXPECT_TRUE(other_target.commands.empty());
  m.OnGuidance(Guidance(orbed::guidance_t::MODE_AR, q_target_));
  const Stepped no_registration = Steps(&m, &arm_, 10, 5);
  EXPECT_TRUE(no_registration.commands.empty());
  // A headset GUIDANCE without a registration is noted once (at the first such step).
  std::vector<std::string> notes;
  for (const Stepped* part : {&other_mode, &other_target, &no_registration}) {
    for (const StepOutput& out : part->outputs) {
      for (const MachineNote& note : out.notes) notes.push_back(note.text);
    }
  }
  ASSERT_EQ(notes.size(), 1u);
  ASSERT_EQ(other_target.outputs[0].notes.size(), 1u);
  EXPECT_NE(notes[0].find("waiting for a valid REGISTRATION"), std::string::npos);

  m.OnRegistration(Eigen::Isometry3d::Identity());
  m.OnRobotState(Eigen::Isometry3d::Identity(), orbed::robot_state_t::MOTION_MOVING);
  EXPECT_TRUE(Steps(&m, &arm_, 15, 5).commands.empty());
  EXPECT_EQ(m.phase(), AssistantMachine::Phase::kWait);

  m.OnRobotState(Eigen::Isometry3d::Identity(), orbed::robot_state_t::MOTION_IDLE);
  const Stepped run = Steps(&m, &arm_, 20, 1);
  ASSERT_EQ(run.commands.size(), 1u);  // the start, the first look and its command in one step
  EXPECT_EQ(m.phase(), AssistantMachine::Phase::kMove);
  EXPECT_EQ(m.joint(), 0);
  EXPECT_EQ(m.look(), 0);
}

// An arm that never moves: the command is re-sent every 0.25 s (every 8th step) and the move fails
// at the first step more than 30 s after it started (step 961), naming the joint; nothing after.
TEST_F(AssistantMachineTest, AMoveThatNeverArrivesTimesOutInEmulatedSeconds) {
  AssistantMachine m(model_, Perfect(), Options());
  FeedTheRoom(&m);
  m.OnGuidance(Guidance(orbed::guidance_t::MODE_AR, q_target_));
  ASSERT_EQ(m.OnSetupTask(Task(1, orbed::guidance_t::MODE_AR, q_target_)).kind, TaskAnswer::kStarted);
  arm_.follows = false;
  const Stepped run = Steps(&m, &arm_, 0, 1000);
  ASSERT_EQ(run.commands.size(), 121u);  // t = 0, 0.25, ..., 30 s
  for (size_t i = 0; i < run.commands.size(); ++i) EXPECT_EQ(run.commands[i].first, 8 * static_cast<int>(i));
  EXPECT_EQ(run.failed_step, 961);
  EXPECT_NE(run.outputs[961].failure.find("joint 1 did not reach"), std::string::npos);
  EXPECT_FALSE(run.outputs[961].command);
  EXPECT_EQ(m.phase(), AssistantMachine::Phase::kDone);
  EXPECT_FALSE(m.result());
}

// The sim stops the arm short (a limit or a collision): after 2 re-send periods (0.5 s, the first
// step beyond: 17 steps) the joint stays where it stopped, with a warning, and the next look starts.
TEST_F(AssistantMachineTest, AJointTheSimStopsStaysWhereItStopped) {
  AssistantMachine m(model_, Perfect(), Options());
  FeedTheRoom(&m);
  m.OnGuidance(Guidance(orbed::guidance_t::MODE_AR, q_target_));
  ASSERT_EQ(m.OnSetupTask(Task(1, orbed::guidance_t::MODE_AR, q_target_)).kind, TaskAnswer::kStarted);
  arm_.follows = false;
  ASSERT_EQ(Steps(&m, &arm_, 0, 1).commands.size(), 1u);
  arm_.q[0] = 0.5 * (q_start_[0] + q_target_[0]);  // halfway
  m.OnJoints(arm_.q);
  m.OnRobotState(Eigen::Isometry3d::Identity(), orbed::robot_state_t::MOTION_STOPPED_BEFORE_COLLISION);
  const Stepped run = Steps(&m, &arm_, 1, 17);
  EXPECT_EQ(m.phase(), AssistantMachine::Phase::kLook);
  EXPECT_EQ(m.joint(), 0);
  EXPECT_EQ(m.look(), 1);
  const std::vector<MachineNote>& notes = run.outputs.back().notes;
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_TRUE(notes[0].warning);
  EXPECT_NE(notes[0].text.find("joint 1 stopped by the sim"), std::string::npos);
  for (int i = 0; i < 16; ++i) EXPECT_TRUE(run.outputs[i].notes.empty()) << "step " << i + 1;
}

// --once: the set-up starts without a task (any GUIDANCE), tasks are ignored, and the finish asks
// to stop without a SETUP_RESULT.
TEST_F(AssistantMachineTest, OnceNeedsNoTaskAndStopsWhenDone) {
  MachineOptions options = Options();
  options.once = true;
  AssistantMachine m(model_, Perfect(), options);
  EXPECT_EQ(m.phase(), AssistantMachine::Phase::kWait);
  EXPECT_EQ(m.OnSetupTask(Task(1, orbed::guidance_t::MODE_AR, q_target_)).kind, TaskAnswer::kIgnored);
  FeedTheRoom(&m);
  m.OnGuidance(Guidance(orbed::guidance_t::MODE_FIXED_DISPLAY, q_target_));
  const Stepped run = Steps(&m, &arm_, 0, 40);
  EXPECT_EQ(run.finished_step, 14);  // as the task above, from step 0
  EXPECT_TRUE(run.outputs[14].stop);
  EXPECT_FALSE(run.outputs[14].task_reply);
  ASSERT_TRUE(m.result());
  EXPECT_EQ(m.result()->mode, int8_t{orbed::guidance_t::MODE_FIXED_DISPLAY});
}

// On the fixed monitor the person turns the view once, at the start: the configured camera is
// about 80 deg around from the configured eye, beyond turn_view_above_deg, so the view is turned
// until turn_view_leaves_deg is left, and that view is the one seen until the set-up ends. The time
// model's total adds the turn and, per look, the mental rotation over what is left:
// turn + 7 joint_overhead_s + 14 (look_s + leaves / mental_rotation_deg_per_s) + 30 deg / hand speed.
// In ar_reflective the view has the display's capture viewpoint and the registration's hologram.
TEST_F(AssistantMachineTest, TheMonitorsViewIsTurnedOnceAndTheDisplayIsConsulted) {
  MachineOptions options = Options();
  options.once = true;
  const AssistantConfig c = Perfect();
  AssistantMachine m(model_, c, options);
  FeedTheRoom(&m);
  m.OnGuidance(Guidance(orbed::guidance_t::MODE_FIXED_DISPLAY, q_target_));
  const MonitorTurn turn = m.assistant().PlanMonitorView(m.CurrentView(0));
  ASSERT_GT(turn.turned_deg, 0);
  const Stepped run = Steps(&m, &arm_, 0, 40);
  ASSERT_TRUE(m.result());
  ASSERT_TRUE(m.CurrentView(0).p_WD);
  EXPECT_TRUE(m.CurrentView(0).p_WD->isApprox(turn.p_WD));
  EXPECT_NEAR(m.assistant().MonitorDisparityDeg(m.CurrentView(0)), c.turn_view_leaves_deg, 1e-9);
  EXPECT_NEAR(m.result()->execution_s,
              turn.time_s + 7 * c.joint_overhead_s +
                  14 * (c.look_s + c.turn_view_leaves_deg / c.mental_rotation_deg_per_s) +
                  30.0 / c.hand_speed_deg_per_s,
              1e-9);

  AssistantMachine r(model_, c, Options());
  FeedTheRoom(&r);
  r.OnGuidance(Guidance(orbed::guidance_t::MODE_AR_REFLECTIVE, q_target_));
  const Viewing view = r.CurrentView(0);
  ASSERT_TRUE(view.p_WC_display);
  EXPECT_TRUE(view.p_WC_display->isApprox(c.display_capture_m));
  EXPECT_TRUE(view.X_WV_display.isApprox(Eigen::Isometry3d::Identity()));
  r.OnGuidance(Guidance(orbed::guidance_t::MODE_AR, q_target_));
  EXPECT_FALSE(r.CurrentView(0).p_WC_display);
}

// A task the check refuses (request id 0, a target beyond the limits) starts nothing.
TEST_F(AssistantMachineTest, ABadTaskIsRefused) {
  AssistantMachine m(model_, Perfect(), Options());
  const TaskAnswer no_id = m.OnSetupTask(Task(0, orbed::guidance_t::MODE_AR, q_target_));
  EXPECT_EQ(no_id.kind, TaskAnswer::kRefused);
  EXPECT_NE(no_id.problem.find("request_id"), std::string::npos);
  Eigen::VectorXd beyond = q_target_;
  beyond[1] = 3.0;  // joint 2's limit is 120 deg
  EXPECT_EQ(m.OnSetupTask(Task(2, orbed::guidance_t::MODE_AR, beyond)).kind, TaskAnswer::kRefused);
  EXPECT_EQ(m.phase(), AssistantMachine::Phase::kIdle);
}

// What the person sees: the monitor's camera from FIXED_VIEW while fresh (fixed_view_stale_s in the
// clock's seconds) and 0.3-20 m from the base; the hologram moved by the SLAM error A of the latest
// HMD_POSE / HMD_POSE_TRUTH pair of one seq, the eye at the true head.
TEST_F(AssistantMachineTest, TheViewFollowsTheMonitorsCameraAndTheHeadset) {
  AssistantMachine m(model_, Perfect(), Options());
  m.OnGuidance(Guidance(orbed::guidance_t::MODE_FIXED_DISPLAY, q_target_));
  m.OnRobotState(Eigen::Isometry3d::Identity(), orbed::robot_state_t::MOTION_IDLE);
  EXPECT_TRUE(m.OnMonitorCamera(Eigen::Vector3d(2, 0, 1.5), 10.0));
  EXPECT_FALSE(m.OnMonitorCamera(Eigen::Vector3d(2, 0, 1.5), 10.5));
  EXPECT_TRUE(m.OnMonitorCamera(Eigen::Vector3d(2, 1, 1.5), 11.0));
  ASSERT_TRUE(m.CurrentView(13.0).p_WD);
  EXPECT_TRUE(m.CurrentView(13.0).p_WD->isApprox(Eigen::Vector3d(2, 1, 1.5)));
  EXPECT_FALSE(m.CurrentView(13.01).p_WD);                // stale
  m.OnMonitorCamera(Eigen::Vector3d(0.1, 0, 0.1), 20.0);  // on the robot
  EXPECT_FALSE(m.CurrentView(20.0).p_WD);

  EXPECT_TRUE(m.CurrentView(0).p_WE.isApprox(Perfect().eye_position_m));
  Eigen::Isometry3d X_WH_est = Eigen::Isometry3d::Identity();
  X_WH_est.translation() = Eigen::Vector3d(1, -1, 1.7);
  Eigen::Isometry3d X_WH_true = X_WH_est;
  X_WH_true.translation().x() += 0.01;  // the SLAM estimate 1 cm off
  m.OnHeadPose(false, 5, X_WH_est);
  m.OnHeadPose(true, 4, X_WH_true);  // another seq: no pair
  EXPECT_TRUE(m.CurrentView(0).X_WV_seen.isApprox(Eigen::Isometry3d::Identity()));
  m.OnHeadPose(true, 5, X_WH_true);
  const Viewing view = m.CurrentView(0);
  EXPECT_TRUE(view.p_WE.isApprox(X_WH_true.translation()));
  EXPECT_NEAR(view.X_WV_seen.translation().x(), 0.01, 1e-12);  // no registration: the real base, moved
}

}  // namespace
}  // namespace orbed::assistant
