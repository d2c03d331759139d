// orbed-hmd's core (Headset, hmd.h) driven with numbers, no bus and no clock: the options resolved,
// the person's keys (a joint of the real arm, a planned target, a submitted trial with its local
// START), the session decisions (what is saved, refused, published, answered again), the hologram
// during a set-up, and the walk's time moved on by an emulated trial.
#include "hmd_emulator/hmd.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/units.h"
#include "lcmtypes/contract/conversions.h"
#include "sim/scene.h"

namespace orbed::hmd {
namespace {

using SC = orbed::session_control_t;
using AT = orbed::alignment_trial_t;
using GT = orbed::guidance_t;
constexpr int kEnter = 13;

HmdOptions Options(bool interactive) {
  HmdOptions options;
  options.interactive = interactive;
  options.threaded = false;
  return ResolveHmdOptions(options);
}

HeadsetClock At(double clock_s, int64_t wall_utime = 0, double monotonic_s = 0, int64_t clock_utime = 0) {
  return HeadsetClock{clock_s, clock_utime, monotonic_s, wall_utime};
}

SC Control(const std::string& id, int8_t command, int64_t request_id = 0) {
  SC m{};
  m.utime = 1000;
  m.session_id = id;
  m.command = command;
  m.display_mode = +AT::MODE_AR;
  m.num_mirrors = 0;
  m.method = +orbed::registration_t::METHOD_KARCHER;
  m.request_id = request_id;
  return m;
}

GT Guidance(int8_t mode, double target_deg) {
  GT g{};
  g.mode = mode;
  g.num_joints = 7;
  g.target_position.assign(7, target_deg * kDegToRad);
  return g;
}

bool Nothing(const HeadsetActions& a) {
  return !a.refusal && !a.start && !a.save && !a.trial && !a.command && !a.task && !a.recapture && !a.stop;
}

TEST(Headset, ResolvesTheChannelsOfItsHeadsetAndArmAndChecksTheFlags) {
  HmdOptions options;
  options.headset = "h1";
  options.arm = "a2";
  options = ResolveHmdOptions(options);
  EXPECT_EQ(options.hmd_pose_channel, "HMD_POSE_H1");
  EXPECT_EQ(options.trial_channel, "ALIGNMENT_TRIAL_H1");
  EXPECT_EQ(options.session_control_channel, "SESSION_CONTROL_H1");
  EXPECT_EQ(options.iiwa_status_channel, "IIWA_STATUS_A2");
  EXPECT_EQ(options.setup_task_channel, "SETUP_TASK_A2");
  EXPECT_FALSE(options.urdf_path.empty());
  EXPECT_FALSE(options.scene_path.empty());

  const auto error_of = [](HmdOptions o) {
    try {
      ResolveHmdOptions(o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  HmdOptions bad;
  bad.headset = "H1";
  EXPECT_EQ(error_of(bad), "--headset H1: expected 1..32 characters of a-z, 0-9 and _");
  bad = {};
  bad.headset = bad.collaborator = "h1";
  EXPECT_EQ(error_of(bad), "--collaborator h1: that is this headset");
  bad = {};
  bad.camera_hz = 0;
  EXPECT_EQ(error_of(bad), "--camera-hz must be in (0, 1000] Hz");
  bad = {};
  bad.jpeg_quality = 101;
  EXPECT_EQ(error_of(bad), "--jpeg-quality must be in [1, 100]");
  bad = {};
  bad.screenshot_path = "x.png";
  EXPECT_EQ(error_of(bad), "--screenshot needs --interactive (it saves the window's image)");
}

TEST(Headset, CommaAndDotTurnTheSelectedJointOfTheMeasuredArmWithinItsLimits) {
  Headset headset(Options(true), 1, 0);
  // No IIWA_STATUS yet: the person is told, nothing is sent.
  EXPECT_TRUE(Nothing(headset.HandleKey('.', At(0))));
  EXPECT_EQ(headset.interactive().last_event(), "cannot turn a joint yet: no IIWA_STATUS");

  headset.OnJoints(Eigen::VectorXd::Zero(7));
  EXPECT_TRUE(Nothing(headset.HandleKey('2', At(0))));  // joint 2 selected
  const HeadsetActions plus = headset.HandleKey('.', At(0, 5'000'000));
  ASSERT_TRUE(plus.command);
  EXPECT_EQ(plus.command->utime, 5'000'000);
  ASSERT_EQ(plus.command->num_joints, 7);
  // The rotation step starts at 0.5 deg; the other joints stay as measured.
  EXPECT_DOUBLE_EQ(plus.command->joint_position[1], 0.5 * kDegToRad);
  for (int j : {0, 2, 3, 4, 5, 6}) EXPECT_EQ(plus.command->joint_position[j], 0.0);
  EXPECT_EQ(headset.interactive().last_event(), "joint 2 to +0.5 deg");
  // Every press starts from the measured q (still zero): ',' gives −0.5 deg, not 0.
  const HeadsetActions minus = headset.HandleKey(',', At(0));
  ASSERT_TRUE(minus.command);
  EXPECT_DOUBLE_EQ(minus.command->joint_position[1], -0.5 * kDegToRad);

  // At the upper limit a press beyond it is held at the limit.
  Eigen::VectorXd q = Eigen::VectorXd::Zero(7);
  const double upper = headset.robot_model().upper_limits_rad()[1];
  q[1] = upper;
  headset.OnJoints(q);
  const HeadsetActions held = headset.HandleKey('.', At(0));
  ASSERT_TRUE(held.command);
  EXPECT_EQ(held.command->joint_position[1], upper);
}

TEST(Headset, TPlansATargetFromTheFreshGuidanceAndEnterSendsIt) {
  Headset headset(Options(true), 1, 0);
  // Neither a joint vector nor a guidance: nothing to plan from.
  EXPECT_TRUE(Nothing(headset.HandleKey('t', At(0))));
  EXPECT_EQ(headset.interactive().last_event(), "cannot plan yet: no IIWA_STATUS and no GUIDANCE");
  EXPECT_TRUE(Nothing(headset.HandleKey('t', At(0))));  // back to the arm

  headset.OnJoints(Eigen::VectorXd::Zero(7));
  headset.OnGuidance(Guidance(+GT::MODE_AR_REFLECTIVE, 10.0), 100.0);
  EXPECT_TRUE(Nothing(headset.HandleKey('t', At(100.5))));  // planning from the guidance's target
  HologramShown shown = headset.Hologram(100.5);
  ASSERT_EQ(shown.q_rad.size(), 7);
  EXPECT_DOUBLE_EQ(shown.q_rad[3], 10.0 * kDegToRad);
  EXPECT_EQ(shown.reflective_q_rad, shown.q_rad);
  // '.' turns joint 1 of the target (the real arm gets no command).
  EXPECT_TRUE(Nothing(headset.HandleKey('.', At(100.6))));
  EXPECT_EQ(headset.interactive().last_event(), "planned target: joint 1 at +10.5 deg");

  const HeadsetActions sent = headset.HandleKey(kEnter, At(100.8, 7'000'000));
  ASSERT_TRUE(sent.task);
  EXPECT_FALSE(sent.trial);
  EXPECT_EQ(sent.task->task_id, "interactive-1");
  EXPECT_EQ(sent.task->utime, 7'000'000);
  EXPECT_EQ(sent.task->request_id, 7'000'000);
  EXPECT_EQ(sent.task->mode, +GT::MODE_AR_REFLECTIVE);
  ASSERT_EQ(sent.task->num_joints, 7);
  EXPECT_NEAR(sent.task->target_position[0], 10.5 * kDegToRad, 1e-12);
  EXPECT_DOUBLE_EQ(sent.task->target_position[1], 10.0 * kDegToRad);
  EXPECT_EQ(headset.interactive().last_event(), "sent interactive-1 on SETUP_TASK");
  // 1.2 s after the guidance it is stale: the next task is in the ar mode.
  const HeadsetActions again = headset.HandleKey(kEnter, At(101.2, 8'000'000));
  ASSERT_TRUE(again.task);
  EXPECT_EQ(again.task->task_id, "interactive-2");
  EXPECT_EQ(again.task->mode, +GT::MODE_AR);
}

TEST(Headset, TheHologramFollowsAFreshGuidanceOutsideASession) {
  Headset headset(Options(false), 1, 0);
  headset.OnGuidance(Guidance(+GT::MODE_FIXED_DISPLAY, 20.0), 10.0);
  HologramShown shown = headset.Hologram(11.0);  // 1 s old: still fresh
  EXPECT_TRUE(shown.hidden);
  EXPECT_TRUE(shown.reflective_hidden);
  shown = headset.Hologram(11.01);  // stale: the real arm
  EXPECT_FALSE(shown.hidden);
  EXPECT_FALSE(shown.reflective_hidden);
  EXPECT_EQ(shown.q_rad.size(), 0);

  headset.OnGuidance(Guidance(+GT::MODE_AR, 20.0), 20.0);
  shown = headset.Hologram(20.0);
  EXPECT_FALSE(shown.hidden);
  ASSERT_EQ(shown.q_rad.size(), 7);
  EXPECT_DOUBLE_EQ(shown.q_rad[6], 20.0 * kDegToRad);
  EXPECT_TRUE(shown.reflective_hidden);  // the ar mode has no display
  EXPECT_EQ(shown.reflective_q_rad.size(), 0);

  // An alignment session aligns the hologram at the real arm.
  EXPECT_TRUE(headset.OnSessionControl(Control("s", +SC::START), At(20.0)).save);
  shown = headset.Hologram(20.0);
  EXPECT_FALSE(shown.hidden);
  EXPECT_FALSE(shown.reflective_hidden);
  EXPECT_EQ(shown.q_rad.size(), 0);
}

TEST(Headset, SessionControlSavesRefusesRunsAndAnswersAgain) {
  const HmdOptions options = Options(false);
  Headset headset(options, 7, 0);
  const Eigen::Isometry3d X_WV_start = headset.CurrentX_WV();

  // A REGISTRATION outside a session moves the hologram; a START forgets it.
  orbed::registration_t registration{};
  registration.valid = false;
  EXPECT_FALSE(headset.WantsRegistration(registration));
  registration.valid = true;
  EXPECT_TRUE(headset.WantsRegistration(registration));
  Eigen::Isometry3d X_WV_registered = X_WV_start;
  X_WV_registered.translation().x() += 0.25;
  headset.OnRegistration(X_WV_registered);
  EXPECT_TRUE(headset.CurrentX_WV().isApprox(X_WV_registered));

  const HeadsetActions started = headset.OnSessionControl(Control("s", +SC::START), At(0));
  EXPECT_TRUE(started.save);
  EXPECT_FALSE(started.refusal);
  ASSERT_TRUE(headset.saved().start);
  EXPECT_EQ(headset.saved().start->session_id, "s");
  EXPECT_FALSE(headset.saved().last_trial);
  EXPECT_TRUE(headset.CurrentX_WV().isApprox(X_WV_start));
  registration.session_id = "other";
  EXPECT_FALSE(headset.WantsRegistration(registration));  // another session's
  registration.session_id = "s";
  EXPECT_TRUE(headset.WantsRegistration(registration));

  // No robot yet: refused with the session's key, nothing saved or run.
  const HeadsetActions early = headset.OnSessionControl(Control("s", +SC::REQUEST_TRIAL, 41), At(0));
  ASSERT_TRUE(early.refusal);
  EXPECT_EQ(early.refusal->key, "no_robot_state");
  EXPECT_FALSE(early.save);
  EXPECT_FALSE(headset.trial_ready());

  headset.OnJoints(Eigen::VectorXd::Zero(7));
  headset.OnRobotBase(sim::LoadSceneFile(options.scene_path).X_WR);
  EXPECT_TRUE(Nothing(headset.OnSessionControl(Control("s", +SC::REQUEST_TRIAL, 42), At(0))));
  ASSERT_TRUE(headset.trial_ready());
  const HeadsetActions answered = headset.PublishReadyTrial(777);
  EXPECT_FALSE(headset.trial_ready());
  EXPECT_TRUE(answered.save);
  ASSERT_TRUE(answered.trial);
  const AT& trial = *answered.trial;
  EXPECT_EQ(trial.utime, 777);
  EXPECT_EQ(trial.session_id, "s");
  EXPECT_EQ(trial.trial_index, 0);
  EXPECT_EQ(trial.request_id, 42);
  EXPECT_EQ(trial.user_id, "emulated-seed-" + std::to_string(headset.config().user.seed));
  EXPECT_EQ(trial.num_joints, 7);
  EXPECT_GT(trial.duration_s, 0);
  EXPECT_EQ(trial.tracking_losses, 0);
  // Saved as published; the hologram is where the person aligned it; the walk moved on by the
  // alignment's time.
  ASSERT_TRUE(headset.saved().last_trial);
  EXPECT_EQ(headset.saved().last_trial->utime, 777);
  EXPECT_EQ(headset.saved().last_trial->trial_index, 0);
  EXPECT_TRUE(headset.CurrentX_WV().isApprox(FromPose(trial.X_WV)));
  EXPECT_DOUBLE_EQ(headset.walk_offset_s(), trial.duration_s);

  // The same request id again: that very trial, not saved again, no new run.
  const HeadsetActions repeated = headset.OnSessionControl(Control("s", +SC::REQUEST_TRIAL, 42), At(5));
  ASSERT_TRUE(repeated.trial);
  EXPECT_FALSE(repeated.save);
  EXPECT_FALSE(headset.trial_ready());
  EXPECT_EQ(repeated.trial->utime, 777);
  EXPECT_EQ(repeated.trial->trial_index, 0);
  EXPECT_EQ(repeated.trial->X_WV.position_m[0], trial.X_WV.position_m[0]);

  // Another session's RESET is refused; the session's own drops the saved trial; STOP saves none.
  const HeadsetActions wrong = headset.OnSessionControl(Control("x", +SC::RESET), At(6));
  ASSERT_TRUE(wrong.refusal);
  EXPECT_EQ(wrong.refusal->key, "unknown_session");
  const HeadsetActions reset = headset.OnSessionControl(Control("s", +SC::RESET), At(6));
  EXPECT_TRUE(reset.save);
  ASSERT_TRUE(headset.saved().start);
  EXPECT_FALSE(headset.saved().last_trial);
  const HeadsetActions stopped = headset.OnSessionControl(Control("s", +SC::STOP), At(7));
  EXPECT_TRUE(stopped.save);
  EXPECT_FALSE(headset.saved().start);
  EXPECT_FALSE(headset.session().state().active());
}

TEST(Headset, EnterWithoutASessionStartsALocalOneAndSubmitsTheTrial) {
  Headset headset(Options(true), 1, /*monotonic_s=*/1.0);
  EXPECT_TRUE(Nothing(headset.HandleKey(kEnter, At(0))));
  EXPECT_EQ(headset.interactive().last_event(), "cannot submit yet: no IIWA_STATUS / ROBOT_STATE");

  headset.OnJoints(Eigen::VectorXd::Zero(7));
  headset.OnRobotBase(Eigen::Isometry3d::Identity());
  const HeadsetActions a = headset.HandleKey(kEnter, At(2.0, 1'700'000'000'500'000, 3.5, 123));
  ASSERT_TRUE(a.start);
  EXPECT_EQ(a.start->command, +SC::START);
  EXPECT_EQ(a.start->session_id, "interactive-1700000000");
  EXPECT_EQ(a.start->utime, 1'700'000'000'500'000);
  EXPECT_EQ(a.start->display_mode, +AT::MODE_AR_REFLECTIVE);  // one live display
  EXPECT_EQ(a.start->num_mirrors, 1);
  EXPECT_EQ(a.start->method, +orbed::registration_t::METHOD_KARCHER);
  EXPECT_TRUE(a.save);
  ASSERT_TRUE(a.trial);
  EXPECT_EQ(a.trial->session_id, "interactive-1700000000");
  EXPECT_EQ(a.trial->trial_index, 0);
  EXPECT_EQ(a.trial->utime, 123);
  EXPECT_EQ(a.trial->user_id, "interactive");
  EXPECT_DOUBLE_EQ(a.trial->duration_s, 2.5);  // the timer started at 1.0 s
  EXPECT_TRUE(FromPose(a.trial->X_WV).isApprox(headset.interactive().X_WV_start()));
  ASSERT_TRUE(headset.saved().start);
  EXPECT_EQ(headset.saved().start->session_id, "interactive-1700000000");
  ASSERT_TRUE(headset.saved().last_trial);

  // The next Enter is trial 1 of the same session, no second START.
  const HeadsetActions b = headset.HandleKey(kEnter, At(3.0, 1'700'000'001'000'000, 4.0, 124));
  EXPECT_FALSE(b.start);
  ASSERT_TRUE(b.trial);
  EXPECT_EQ(b.trial->trial_index, 1);
  EXPECT_DOUBLE_EQ(b.trial->duration_s, 0.5);

  // A conductor's REQUEST_TRIAL only asks the person: no trial is run.
  EXPECT_TRUE(Nothing(
      headset.OnSessionControl(Control("interactive-1700000000", +SC::REQUEST_TRIAL, 9), At(4.0, 0, 5.0))));
  EXPECT_FALSE(headset.trial_ready());
  EXPECT_TRUE(headset.interactive().trial_requested());
  // Re-capture and quit are the shell's.
  EXPECT_EQ(headset.HandleKey('c', At(4.0)).recapture, 0);
  EXPECT_TRUE(headset.HandleKey('q', At(4.0)).stop);
}

TEST(Headset, TheWalksTimeStartsAtTheFirstPoseAndMovesOnByAnEmulatedTrial) {
  const HmdOptions options = Options(false);
  Headset headset(options, 3, 0);
  headset.StepPose(At(50.0));
  EXPECT_EQ(headset.walk_t_s(), 0.0);
  const Headset::PoseStep step = headset.StepPose(At(50.5, 0, 0, 50'500'000));
  EXPECT_DOUBLE_EQ(headset.walk_t_s(), 0.5);
  EXPECT_EQ(step.poses.estimate.utime, 50'500'000);
  EXPECT_EQ(step.poses.truth.seq, step.poses.estimate.seq);
  EXPECT_TRUE(Nothing(step.actions));

  headset.OnJoints(Eigen::VectorXd::Zero(7));
  headset.OnRobotBase(sim::LoadSceneFile(options.scene_path).X_WR);
  headset.OnSessionControl(Control("s", +SC::START), At(50.5));
  headset.OnSessionControl(Control("s", +SC::REQUEST_TRIAL, 1), At(50.5));
  const double duration_s = headset.PublishReadyTrial(1).trial->duration_s;
  headset.StepPose(At(51.0));
  EXPECT_DOUBLE_EQ(headset.walk_t_s(), 1.0 + duration_s);
}

}  // namespace
}  // namespace orbed::hmd
