// orbed-assistant's shell (assistant_process.h) in-process on memq:// (the process's own LCM
// instance delivers what the test publishes on it). The test plays the arm on the same instance: an
// IIWA_COMMAND is answered at once with an IIWA_STATUS at the commanded q. Checked: what the shell
// refuses and counts, that the looks' commands reach the bus (joint by joint, each moving one joint:
// the arm follows), the result file, and SETUP_TASK answered with SETUP_RESULT, a repeat with the same
// message.
#include "procs/assistant/assistant_process.h"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>
#include <orbed/iiwa_command_t.hpp>
#include <orbed/iiwa_status_t.hpp>
#include <orbed/registration_t.hpp>
#include <orbed/robot_state_t.hpp>

#include "base/units.h"
#include "lcmtypes/contract/conversions.h"
#include "procs/assistant/assistant_test_people.h"

namespace orbed::assistant {
namespace {

constexpr int kJoints = 7;

CommonFlags MemqFlags(double duration_s) {
  CommonFlags flags("orbed-assistant-test");
  flags.lcm_url = "memq://";
  flags.duration_s = duration_s;  // a guard: the runs below stop themselves in about a second
  return flags;
}

std::vector<double> Deg(std::initializer_list<double> q) {
  std::vector<double> out;
  for (double x : q) out.push_back(x * kDegToRad);
  return out;
}

orbed::iiwa_status_t Status(const std::vector<double>& q) {
  orbed::iiwa_status_t s{};
  s.num_joints = static_cast<int32_t>(q.size());
  s.joint_position_measured = q;
  for (auto* v : {&s.joint_velocity_estimated, &s.joint_position_commanded, &s.joint_position_ipo,
                  &s.joint_torque_measured, &s.joint_torque_commanded, &s.joint_torque_external}) {
    v->assign(q.size(), 0.0);
  }
  return s;
}

orbed::robot_state_t RobotState() {
  orbed::robot_state_t s{};
  s.X_WR = ToPose(Eigen::Isometry3d::Identity());
  s.X_RF = ToPose(Eigen::Isometry3d::Identity());
  s.X_RT = ToPose(Eigen::Isometry3d::Identity());
  s.num_joints = kJoints;
  s.joint_position.assign(kJoints, 0.0);
  s.joint_limit_hit.assign(kJoints, 0);
  s.num_links = 0;
  s.motion_state = orbed::robot_state_t::MOTION_IDLE;
  return s;
}

orbed::registration_t Registration() {
  orbed::registration_t r{};
  r.valid = true;
  r.X_WV_mean = ToPose(Eigen::Isometry3d::Identity());
  return r;
}

orbed::guidance_t Guidance(const std::vector<double>& q_target, int num_joints = kJoints) {
  return test::Guidance(orbed::guidance_t::MODE_AR, q_target, num_joints);
}

// The arm: every IIWA_COMMAND is where the arm is at once (an IIWA_STATUS back on the same bus).
struct Arm {
  lcm::LCM* lcm{nullptr};
  std::vector<orbed::iiwa_command_t> commands;
  void On(const lcm::ReceiveBuffer*, const std::string&, const orbed::iiwa_command_t* msg) {
    commands.push_back(*msg);
    orbed::iiwa_status_t status = Status(msg->joint_position);
    lcm->publish("IIWA_STATUS", &status);
  }
};

const std::vector<double> kStart = Deg({0, 30, 0, -60, 0, 45, 0});
const std::vector<double> kTarget = Deg({20, 40, 0, -50, 0, 45, 10});

void PublishTheRoom(lcm::LCM& lcm) {
  orbed::iiwa_status_t status = Status(kStart);
  lcm.publish("IIWA_STATUS", &status);
  orbed::robot_state_t state = RobotState();
  lcm.publish("ROBOT_STATE", &state);
  orbed::registration_t registration = Registration();
  lcm.publish("REGISTRATION", &registration);
}

// Each command differs from the one before (the start, first) in one joint, the joints in order,
// at most two commands per joint; every joint is commanded (the person's hand is never exact).
void ExpectJointByJoint(const std::vector<orbed::iiwa_command_t>& commands) {
  ASSERT_GE(commands.size(), static_cast<size_t>(kJoints));
  ASSERT_LE(commands.size(), 2u * kJoints);
  std::vector<double> before = kStart;
  int last_joint = 0;
  std::vector<int> per_joint(kJoints, 0);
  for (const orbed::iiwa_command_t& c : commands) {
    ASSERT_EQ(c.num_joints, kJoints);
    int moved = -1;
    for (int i = 0; i < kJoints; ++i) {
      if (c.joint_position[i] != before[i]) {
        EXPECT_EQ(moved, -1) << "a command moves one joint";
        moved = i;
      }
    }
    ASSERT_GE(moved, last_joint);
    ++per_joint[moved];
    last_joint = moved;
    before = c.joint_position;
  }
  for (int n : per_joint) EXPECT_GE(n, 1);
}

// --once: a bad GUIDANCE (6 joints) is refused and counted, the good one is carried out joint by
// joint (a look that moves its joint commands it; 2 looks per joint in the shipped config), the arm ends
// where the last command put it, and the result file says so.
TEST(AssistantProcess, OnceCarriesOutTheGuidanceAndWritesTheResult) {
  const std::string result_path = ::testing::TempDir() + "assistant_process_test_result.json";
  std::remove(result_path.c_str());
  AssistantOptions options;
  options.once = true;
  options.result_path = result_path;
  AssistantProcess assistant(MemqFlags(30), options);
  lcm::LCM& lcm = assistant.process().lcm();
  Arm arm{&lcm};
  lcm.subscribe("IIWA_COMMAND", &Arm::On, &arm);
  PublishTheRoom(lcm);
  orbed::guidance_t short_guidance = Guidance(kTarget, kJoints - 1);
  lcm.publish("GUIDANCE", &short_guidance);
  orbed::guidance_t guidance = Guidance(kTarget);
  lcm.publish("GUIDANCE", &guidance);

  EXPECT_EQ(assistant.Run(), 0);  // stopped by itself: --once
  EXPECT_EQ(assistant.process().rejections().counts().at("GUIDANCE/field"), 1);
  ExpectJointByJoint(arm.commands);
  ASSERT_TRUE(assistant.result());
  const SetupResult& r = *assistant.result();
  EXPECT_EQ(r.mode, int8_t{orbed::guidance_t::MODE_AR});
  ASSERT_EQ(r.q_reached_rad.size(), kJoints);
  for (int i = 0; i < kJoints; ++i) {
    EXPECT_NEAR(r.q_reached_rad[i], arm.commands.back().joint_position[i], 1e-12);
    EXPECT_NEAR(r.q_start_rad[i], kStart[i], 1e-12);
    EXPECT_NEAR(r.q_target_rad[i], kTarget[i], 1e-12);
  }
  EXPECT_GT(r.execution_s, 0);
  std::ifstream file(result_path);
  ASSERT_TRUE(file.good());
  std::stringstream text;
  text << file.rdbuf();
  EXPECT_EQ(text.str(), SetupResultJson(r));
}

// Tasks: SETUP_TASK starts the set-up, SETUP_RESULT answers it (its id and task id, the arm's
// final q); the same task again is answered with the same message; a task without an id is refused.
TEST(AssistantProcess, ATaskIsAnsweredAndItsRepeatGetsTheSameAnswer) {
  AssistantProcess assistant(MemqFlags(30), AssistantOptions{});
  lcm::LCM& lcm = assistant.process().lcm();
  Arm arm{&lcm};
  lcm.subscribe("IIWA_COMMAND", &Arm::On, &arm);
  orbed::setup_task_t task{};
  task.request_id = 42;
  task.task_id = "u1-ar-1";
  task.mode = orbed::guidance_t::MODE_AR;
  task.num_joints = kJoints;
  task.target_position = kTarget;
  struct Answers {
    AssistantProcess* assistant;
    lcm::LCM* lcm;
    orbed::setup_task_t task;
    std::vector<orbed::setup_result_t> seen;
    void On(const lcm::ReceiveBuffer*, const std::string&, const orbed::setup_result_t* msg) {
      seen.push_back(*msg);
      if (seen.size() == 1) lcm->publish("SETUP_TASK", &task);  // the conductor retries
      if (seen.size() == 2) assistant->process().RequestStop();
    }
  } answers{&assistant, &lcm, task, {}};
  lcm.subscribe("SETUP_RESULT", &Answers::On, &answers);

  PublishTheRoom(lcm);
  orbed::setup_task_t no_id = task;
  no_id.request_id = 0;
  lcm.publish("SETUP_TASK", &no_id);
  lcm.publish("SETUP_TASK", &task);
  orbed::guidance_t guidance = Guidance(kTarget);
  lcm.publish("GUIDANCE", &guidance);

  EXPECT_EQ(assistant.Run(), 0);
  EXPECT_EQ(assistant.process().rejections().counts().at("SETUP_TASK/field"), 1);
  ASSERT_EQ(answers.seen.size(), 2u);
  const orbed::setup_result_t& first = answers.seen[0];
  EXPECT_EQ(first.request_id, 42);
  EXPECT_EQ(first.task_id, "u1-ar-1");
  EXPECT_EQ(first.mode, int8_t{orbed::guidance_t::MODE_AR});
  ASSERT_EQ(first.num_joints, kJoints);
  for (int i = 0; i < kJoints; ++i) {
    EXPECT_NEAR(first.reached_position[i], arm.commands.back().joint_position[i], 1e-12);
  }
  ExpectJointByJoint(arm.commands);
  const orbed::setup_result_t& repeat = answers.seen[1];
  EXPECT_EQ(repeat.utime, first.utime);
  EXPECT_EQ(repeat.execution_s, first.execution_s);
  EXPECT_EQ(repeat.reached_position, first.reached_position);
}

}  // namespace
}  // namespace orbed::assistant
