// orbed-hmd in-process on memq:// (the process's own LCM instance delivers what the test publishes
// on it), images made inline (options.threaded = false) so every step is deterministic:
//   - SESSION_CONTROL START + REQUEST_TRIAL with the robot known → one ALIGNMENT_TRIAL per request,
//     with the session, the per-session index, the mode, num_mirrors and the robot's q; the chosen
//     X_WV is closer to the true X_WR than the start offset written in user.yaml;
//   - every bad input is rejected and counted under its own key, and produces no trial;
//   - HMD_POSE and HMD_POSE_TRUTH share seq and utime, seq counts from 0, the first true head pose
//     is the walk's first waypoint (viraal_walk.yaml);
//   - HMD_CAMERA is a 1280×720 JPEG with the HoloLens PV intrinsics stamped with the estimated
//     pose of the sample it was rendered at; REFLECTIVE_VIEW's K_m = diag(1, −1, 1)·K_o and X_WM is
//     the camera turned π about x and moved D along its principal ray (computed here by hand);
//   - the interactive mode's keys move the hologram by the shown steps and Enter submits a trial;
//   - a published trial equals RunHeadsetTrial() (headset_trial.h) of the same inputs.
#include "hmd_emulator/hmd_process.h"

#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <orbed/gaze_ray_t.hpp>
#include <orbed/hmd_pose_t.hpp>
#include <orbed/iiwa_command_t.hpp>
#include <orbed/image_t.hpp>
#include <orbed/reflective_view_t.hpp>
#include <orbed/setup_task_t.hpp>

#include "base/units.h"
#include "hmd_emulator/gaze.h"
#include "hmd_emulator/headset_trial.h"
#include "lcmtypes/contract/conversions.h"
#include "render/renderer.h"
#include "sim/guidance_messages.h"

namespace orbed::hmd {
namespace {

using SC = orbed::session_control_t;
using AT = orbed::alignment_trial_t;

// The shipped scene's X_WR (sim/models/scenes/trocar_or.yaml), read back through the scene loader.
Eigen::Isometry3d SceneX_WR() {
  return sim::LoadSceneFile(HmdSourcePath(sim::kDefaultSceneRelativePath)).X_WR;
}

struct Collector {
  std::vector<orbed::alignment_trial_t> trials;
  std::vector<orbed::hmd_pose_t> est, truth;
  std::vector<orbed::image_t> camera, ar;
  std::vector<orbed::reflective_view_t> reflective;
  std::vector<orbed::gaze_ray_t> gaze;
  std::vector<orbed::session_control_t> control;
  void OnTrial(const lcm::ReceiveBuffer*, const std::string&, const orbed::alignment_trial_t* m) {
    trials.push_back(*m);
  }
  void OnPose(const lcm::ReceiveBuffer*, const std::string&, const orbed::hmd_pose_t* m) {
    est.push_back(*m);
  }
  void OnTruth(const lcm::ReceiveBuffer*, const std::string&, const orbed::hmd_pose_t* m) {
    truth.push_back(*m);
  }
  void OnCamera(const lcm::ReceiveBuffer*, const std::string&, const orbed::image_t* m) {
    camera.push_back(*m);
  }
  void OnAr(const lcm::ReceiveBuffer*, const std::string&, const orbed::image_t* m) { ar.push_back(*m); }
  void OnReflective(const lcm::ReceiveBuffer*, const std::string&, const orbed::reflective_view_t* m) {
    reflective.push_back(*m);
  }
  void OnGaze(const lcm::ReceiveBuffer*, const std::string&, const orbed::gaze_ray_t* m) {
    gaze.push_back(*m);
  }
  void OnControl(const lcm::ReceiveBuffer*, const std::string&, const orbed::session_control_t* m) {
    control.push_back(*m);
  }
  void Attach(lcm::LCM& lcm) {
    lcm.subscribe("ALIGNMENT_TRIAL", &Collector::OnTrial, this);
    lcm.subscribe("HMD_POSE", &Collector::OnPose, this);
    lcm.subscribe("HMD_POSE_TRUTH", &Collector::OnTruth, this);
    lcm.subscribe("HMD_CAMERA", &Collector::OnCamera, this);
    lcm.subscribe("AR_VIEW", &Collector::OnAr, this);
    lcm.subscribe("REFLECTIVE_VIEW", &Collector::OnReflective, this);
    lcm.subscribe("GAZE_RAY", &Collector::OnGaze, this);
    lcm.subscribe("SESSION_CONTROL", &Collector::OnControl, this);
  }
};

// Every `Msg` on `channel` goes into *out (as the handlers run: Drain).
template <typename Msg>
void CollectInto(lcm::LCM& lcm, const std::string& channel, std::vector<Msg>* out) {
  lcm.subscribeFunction(
      channel,
      +[](const lcm::ReceiveBuffer*, const std::string&, const Msg* m, std::vector<Msg>* o) {
        o->push_back(*m);
      },
      out);
}

CommonFlags MemqFlags(double duration_s) {
  CommonFlags flags("orbed-hmd");
  flags.lcm_url = "memq://";
  flags.duration_s = duration_s;
  flags.log_level = "warn";
  return flags;
}

HmdOptions Inline() {
  HmdOptions o;
  o.threaded = false;
  return o;
}

const std::vector<double> kQDeg{0, 30, 0, -60, 0, 45, 0};

orbed::iiwa_status_t Status(const std::vector<double>& q_deg) {
  orbed::iiwa_status_t m{};
  m.utime = NowMicros();
  m.num_joints = static_cast<int32_t>(q_deg.size());
  for (double q : q_deg) m.joint_position_measured.push_back(q * kDegToRad);
  m.joint_velocity_estimated.assign(q_deg.size(), 0.0);
  m.joint_position_commanded = m.joint_position_measured;
  m.joint_position_ipo = m.joint_position_measured;
  m.joint_torque_measured.assign(q_deg.size(), 0.0);
  m.joint_torque_commanded.assign(q_deg.size(), 0.0);
  m.joint_torque_external.assign(q_deg.size(), 0.0);
  return m;
}

orbed::robot_state_t State(const Eigen::Isometry3d& X_WR) {
  orbed::robot_state_t m{};
  m.utime = NowMicros();
  m.robot_name = "iiwa7";
  m.X_WR = ToPose(X_WR);
  m.X_RF = ToPose(Eigen::Isometry3d::Identity());
  m.X_RT = m.X_RF;
  return m;
}

orbed::session_control_t Control(const std::string& id, int8_t command, int8_t mode = +AT::MODE_AR,
                                 int32_t mirrors = 0) {
  orbed::session_control_t m{};
  m.utime = NowMicros();
  m.session_id = id;
  m.command = command;
  m.display_mode = mode;
  m.num_mirrors = mirrors;
  m.method = +orbed::registration_t::METHOD_KARCHER;
  return m;
}

void Drain(lcm::LCM& lcm) {
  while (lcm.handleTimeout(0) > 0) {
  }
}

// Runs the process for its --duration-s, then hands what is still queued to the handlers (the
// process's and the collector's). Run() stops at its deadline whether or not it got through the
// queue: an emulated trial takes a while (longer in a sanitizer build or on a busy machine), and
// the last trials published would otherwise never reach the collector.
int RunAndDrain(HmdProcess* hmd) {
  const int code = hmd->Run();
  Drain(hmd->process().lcm());
  return code;
}

TEST(HmdProcess, AnswersEachRequestTrialWithOneAlignmentTrial) {
  HmdProcess hmd(MemqFlags(0.5), Inline());
  Collector got;
  lcm::LCM& lcm = hmd.process().lcm();
  got.Attach(lcm);
  const Eigen::Isometry3d X_WR = SceneX_WR();
  const orbed::iiwa_status_t status = Status(kQDeg);
  const orbed::robot_state_t state = State(X_WR);
  const auto start = Control("s-refl", +SC::START, +AT::MODE_AR_REFLECTIVE, 1);
  const auto request = Control("s-refl", +SC::REQUEST_TRIAL);
  lcm.publish("IIWA_STATUS", &status);
  lcm.publish("ROBOT_STATE", &state);
  lcm.publish("SESSION_CONTROL", &start);
  lcm.publish("SESSION_CONTROL", &request);
  lcm.publish("SESSION_CONTROL", &request);
  const auto start_ar = Control("s-ar", +SC::START, +AT::MODE_AR, 0);
  const auto request_ar = Control("s-ar", +SC::REQUEST_TRIAL);
  lcm.publish("SESSION_CONTROL", &start_ar);
  lcm.publish("SESSION_CONTROL", &request_ar);
  EXPECT_EQ(RunAndDrain(&hmd), 0);

  ASSERT_EQ(got.trials.size(), 3u);
  // The start offset of user.yaml: (0.10, -0.08, 0.05) m from the real base, i.e. 0.138 m.
  const double start_offset_m = std::sqrt(0.10 * 0.10 + 0.08 * 0.08 + 0.05 * 0.05);
  for (size_t i = 0; i < got.trials.size(); ++i) {
    const auto& t = got.trials[i];
    const bool refl = i < 2;
    EXPECT_EQ(t.session_id, refl ? "s-refl" : "s-ar");
    EXPECT_EQ(t.trial_index, refl ? static_cast<int>(i) : 0);
    EXPECT_EQ(t.display_mode, refl ? +AT::MODE_AR_REFLECTIVE : +AT::MODE_AR);
    EXPECT_EQ(t.num_mirrors, refl ? 1 : 0);
    ASSERT_EQ(t.num_joints, 7);
    for (int j = 0; j < 7; ++j) EXPECT_NEAR(t.joint_position[j], kQDeg[j] * kDegToRad, 1e-12);
    EXPECT_EQ(t.user_id, "emulated-seed-1");
    EXPECT_GT(t.duration_s, 5.0);  // at least a look and a nudge (user.yaml: 2 s + 5.5 s)
    EXPECT_TRUE(CheckPose(t.X_WV, "X_WV").empty());
    const Eigen::Isometry3d X_WV = FromPose(t.X_WV);
    EXPECT_LT((X_WV.translation() - X_WR.translation()).norm(), start_offset_m) << "trial " << i;
  }
  // Different trials of a session are different draws (their own walk on the session's map, their own seed).
  EXPECT_NE(got.trials[0].X_WV.position_m[0], got.trials[1].X_WV.position_m[0]);
  EXPECT_EQ(hmd.process().rejections().total(), 0);
  // After the trials the hologram is drawn where the user put it last.
  EXPECT_TRUE(hmd.CurrentX_WV().isApprox(FromPose(got.trials.back().X_WV)));
}

// Retries and duplicated datagrams: a REQUEST_TRIAL whose request id was answered is answered with
// the very same ALIGNMENT_TRIAL (never a second, different trial), and a repeated START (of the
// active session, or late, of the previous one) changes nothing.
TEST(HmdProcess, ARepeatedRequestIdGetsTheSameTrialAgain) {
  HmdProcess hmd(MemqFlags(0.5), Inline());
  Collector got;
  lcm::LCM& lcm = hmd.process().lcm();
  got.Attach(lcm);
  const orbed::iiwa_status_t status = Status(kQDeg);
  const orbed::robot_state_t state = State(SceneX_WR());
  auto start = Control("s1", +SC::START, +AT::MODE_AR_REFLECTIVE, 1);
  start.request_id = 101;
  auto request = Control("s1", +SC::REQUEST_TRIAL);
  request.request_id = 102;
  auto next = Control("s1", +SC::REQUEST_TRIAL);
  next.request_id = 103;
  auto other = Control("s2", +SC::START, +AT::MODE_AR, 0);
  other.request_id = 104;
  lcm.publish("IIWA_STATUS", &status);
  lcm.publish("ROBOT_STATE", &state);
  lcm.publish("SESSION_CONTROL", &start);
  lcm.publish("SESSION_CONTROL", &request);
  lcm.publish("SESSION_CONTROL", &start);    // a retry's START: no reset
  lcm.publish("SESSION_CONTROL", &request);  // the retried request: the same trial again
  lcm.publish("SESSION_CONTROL", &next);
  lcm.publish("SESSION_CONTROL", &request);  // a late duplicate: still the first trial
  lcm.publish("SESSION_CONTROL", &other);
  lcm.publish("SESSION_CONTROL", &start);  // late, after another session started: ignored
  // Run() may reach its 0.5 s before the queue (its clock starts with the process, and four emulated
  // trials take a while under a sanitizer on a busy machine): what is left is handled after it.
  EXPECT_EQ(RunAndDrain(&hmd), 0);

  ASSERT_EQ(got.trials.size(), 4u);
  auto bytes = [](const orbed::alignment_trial_t& t) {
    std::vector<uint8_t> out(t.getEncodedSize());
    t.encode(out.data(), 0, static_cast<int>(out.size()));
    return out;
  };
  EXPECT_EQ(got.trials[0].request_id, 102);
  EXPECT_EQ(got.trials[0].trial_index, 0);
  EXPECT_EQ(bytes(got.trials[1]), bytes(got.trials[0]));
  EXPECT_EQ(got.trials[2].request_id, 103);
  EXPECT_EQ(got.trials[2].trial_index, 1);
  EXPECT_EQ(bytes(got.trials[3]), bytes(got.trials[0]));
  EXPECT_EQ(hmd.active_session(), "s2");
  EXPECT_EQ(hmd.process().rejections().total(), 0);
}

// A trial with a forced tracking fault (slam.faults) is answered after its fault has played on
// HMD_POSE: LOST for 0.1 s (6 samples at 60 Hz), one RELOCALIZED sample, and in the same tick the
// ALIGNMENT_TRIAL carrying the record. Meanwhile the request's retry is not acted on and another
// request is refused (busy). The pose ticks are driven here, as fast as they go.
TEST(HmdProcess, ATrialWithATrackingFaultIsAnsweredAfterItPlaysOnHmdPose) {
  const std::string config = ::testing::TempDir() + "/hmd_fault.yaml";
  std::ofstream(config) << "slam:\n  faults:\n    - {session: s1, trial: 0, at_s: 0.5, state: lost, "
                           "duration_s: 0.1, jump: {position_m: [0.03, 0, 0]}}\n";
  HmdOptions options = Inline();
  options.config_paths = {config};
  HmdProcess hmd(MemqFlags(0), options);
  Collector got;
  lcm::LCM& lcm = hmd.process().lcm();
  got.Attach(lcm);
  const orbed::iiwa_status_t status = Status(kQDeg);
  const orbed::robot_state_t state = State(SceneX_WR());
  auto start = Control("s1", +SC::START, +AT::MODE_AR_REFLECTIVE, 1);
  auto request = Control("s1", +SC::REQUEST_TRIAL);
  request.request_id = 7;
  auto other = Control("s1", +SC::REQUEST_TRIAL);
  other.request_id = 8;
  lcm.publish("IIWA_STATUS", &status);
  lcm.publish("ROBOT_STATE", &state);
  lcm.publish("SESSION_CONTROL", &start);
  lcm.publish("SESSION_CONTROL", &request);
  lcm.publish("SESSION_CONTROL", &request);  // the conductor's retry: the answer is coming
  lcm.publish("SESSION_CONTROL", &other);    // refused: busy
  Drain(lcm);
  EXPECT_TRUE(got.trials.empty());
  EXPECT_EQ(hmd.process().rejections().total(), 1);

  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  size_t poses_at_answer = 0;
  const double walk_at_request_s = hmd.walk_t_s();  // no pose yet: 0
  double walk_at_answer_s = 0;
  while (got.trials.empty() && std::chrono::steady_clock::now() < deadline) {
    hmd.PublishPose();
    walk_at_answer_s = hmd.walk_t_s();
    Drain(lcm);
    poses_at_answer = got.est.size();
  }
  ASSERT_EQ(got.trials.size(), 1u);
  // The person walked on for the trial's emulated time in all: the part the faults took on the
  // live stream, then the rest at once.
  EXPECT_EQ(walk_at_request_s, 0.0);
  EXPECT_GT(walk_at_answer_s, 0.5);
  EXPECT_NEAR(hmd.walk_offset_s(), got.trials[0].duration_s - (walk_at_answer_s - walk_at_request_s), 1e-9);
  std::vector<int> states;
  for (const auto& p : got.est) states.push_back(p.tracking_state);
  ASSERT_GE(states.size(), 7u);
  EXPECT_EQ(poses_at_answer, states.size());
  EXPECT_EQ(states.back(), +orbed::hmd_pose_t::RELOCALIZED);  // the trial right after it
  for (size_t k = states.size() - 7; k + 1 < states.size(); ++k)
    EXPECT_EQ(states[k], +orbed::hmd_pose_t::LOST) << k;
  if (states.size() > 7) {
    EXPECT_NE(states[states.size() - 8], +orbed::hmd_pose_t::LOST);
  }

  const AT& t = got.trials[0];
  EXPECT_EQ(t.request_id, 7);
  EXPECT_EQ(t.trial_index, 0);
  EXPECT_EQ(t.tracking_losses, 1);
  EXPECT_EQ(t.relocalizations, 1);
  EXPECT_NEAR(t.tracking_wait_s, 0.1, 1e-9);
  EXPECT_EQ(t.alignment_repeats, 1);  // 3 cm at ~2 m is ~50 arcmin: the person re-aligns
  // The emulated trial itself, as the pure function makes it.
  HeadsetTrialInputs in;
  SetRobotAt(sim::LoadRobotForScene(HmdSourcePath(sim::RobotModel::kDefaultUrdfRelativePath),
                                    sim::LoadSceneFile(HmdSourcePath(sim::kDefaultSceneRelativePath))),
             sim::DegToRad(Eigen::Map<const Eigen::VectorXd>(kQDeg.data(), 7)), &in);
  in.X_WR = SceneX_WR();
  in.X_WV_start = EmulatedUser(hmd.config().user).StartPose(SceneX_WR());
  in.process_seed = hmd.process().seed();
  in.session_id = "s1";
  in.num_mirrors = 1;
  const TrialOutcome o = RunHeadsetTrial(hmd.config(), in);
  EXPECT_EQ(t.duration_s, o.alignment.duration_s);
  EXPECT_TRUE(FromPose(t.X_WV).isApprox(o.alignment.X_WV, 1e-12));
  // Answered: the retry now gets the same trial.
  lcm.publish("SESSION_CONTROL", &request);
  Drain(lcm);
  ASSERT_EQ(got.trials.size(), 2u);
  EXPECT_EQ(got.trials[1].tracking_losses, 1);
}

TEST(HmdProcess, SameSeedSameSessionGivesTheSameTrial) {
  std::vector<orbed::alignment_trial_t> runs;
  for (int k = 0; k < 2; ++k) {
    HmdProcess hmd(MemqFlags(0.2), Inline());
    Collector got;
    got.Attach(hmd.process().lcm());
    const auto status = Status(kQDeg);
    const auto state = State(SceneX_WR());
    const auto start = Control("same", +SC::START, +AT::MODE_AR_REFLECTIVE, 1);
    const auto request = Control("same", +SC::REQUEST_TRIAL);
    hmd.process().lcm().publish("IIWA_STATUS", &status);
    hmd.process().lcm().publish("ROBOT_STATE", &state);
    hmd.process().lcm().publish("SESSION_CONTROL", &start);
    hmd.process().lcm().publish("SESSION_CONTROL", &request);
    EXPECT_EQ(RunAndDrain(&hmd), 0);
    ASSERT_EQ(got.trials.size(), 1u);
    runs.push_back(got.trials[0]);
  }
  for (int i = 0; i < 3; ++i) EXPECT_EQ(runs[0].X_WV.position_m[i], runs[1].X_WV.position_m[i]);
  EXPECT_EQ(runs[0].duration_s, runs[1].duration_s);
}

// The published trial is RunHeadsetTrial() of the same inputs (headset_trial.h), bit for bit: what
// another program gets when it calls the function with the process's seed, session and index.
// The inputs orbed-hmd gives RunHeadsetTrial for a REQUEST_TRIAL with the shipped scene and model.
HeadsetTrialInputs ShippedTrialInputs(const HmdProcess& hmd, const orbed::iiwa_status_t& status,
                                      const orbed::robot_state_t& state, std::uint64_t seed,
                                      const std::string& session, int32_t mirrors) {
  const sim::Scene scene = sim::LoadSceneFile(HmdSourcePath(sim::kDefaultSceneRelativePath));
  const sim::RobotModel robot =
      sim::LoadRobotForScene(HmdSourcePath(sim::RobotModel::kDefaultUrdfRelativePath), scene);
  HeadsetTrialInputs in;
  SetRobotAt(robot, ToVectorX(status.joint_position_measured), &in);
  in.X_WR = FromPose(state.X_WR);
  in.X_WV_start = EmulatedUser(hmd.config().user).StartPose(scene.X_WR);
  in.process_seed = seed;
  in.session_id = session;
  in.num_mirrors = mirrors;
  in.p_RL = AnnotationLandmarkPoints(robot, hmd.config().hmd, ToVectorX(status.joint_position_measured));
  return in;
}

TEST(HmdProcess, PublishedTrialIsTheHeadsetTrialFunction) {
  CommonFlags flags = MemqFlags(0.2);
  flags.seed = 7;
  HmdProcess hmd(flags, Inline());
  Collector got;
  got.Attach(hmd.process().lcm());
  const Eigen::Isometry3d X_WR = SceneX_WR() * Eigen::Translation3d(0.004, -0.003, 0.0);
  const auto status = Status(kQDeg);
  const auto state = State(X_WR);
  const auto start = Control("fn", +SC::START, +AT::MODE_AR_REFLECTIVE, 2);
  const auto request = Control("fn", +SC::REQUEST_TRIAL);
  hmd.process().lcm().publish("IIWA_STATUS", &status);
  hmd.process().lcm().publish("ROBOT_STATE", &state);
  hmd.process().lcm().publish("SESSION_CONTROL", &start);
  hmd.process().lcm().publish("SESSION_CONTROL", &request);
  hmd.process().lcm().publish("SESSION_CONTROL", &request);
  EXPECT_EQ(RunAndDrain(&hmd), 0);
  ASSERT_EQ(got.trials.size(), 2u);

  HeadsetTrialInputs in = ShippedTrialInputs(hmd, status, state, 7, "fn", 2);
  for (int32_t index = 0; index < 2; ++index) {
    in.trial_index = index;
    const TrialOutcome outcome = RunHeadsetTrial(hmd.config(), in);
    const orbed::alignment_trial_t& t = got.trials[index];
    EXPECT_EQ(t.trial_index, index);
    const orbed::pose_t X_WV = ToPose(outcome.alignment.X_WV);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(t.X_WV.position_m[i], X_WV.position_m[i]) << index;
    for (int i = 0; i < 4; ++i) EXPECT_EQ(t.X_WV.quaternion_wxyz[i], X_WV.quaternion_wxyz[i]) << index;
    EXPECT_EQ(t.duration_s, outcome.alignment.duration_s);
  }
}

TEST(HmdProcess, RejectsBadInputsPerReasonAndKeepsRunning) {
  HmdProcess hmd(MemqFlags(0.4), Inline());
  Collector got;
  lcm::LCM& lcm = hmd.process().lcm();
  got.Attach(lcm);

  // A trial before the robot is known, and for a session that was never started.
  const auto start = Control("s", +SC::START, +AT::MODE_AR_REFLECTIVE, 1);
  const auto request = Control("s", +SC::REQUEST_TRIAL);
  const auto request_other = Control("other", +SC::REQUEST_TRIAL);
  lcm.publish("SESSION_CONTROL", &start);
  lcm.publish("SESSION_CONTROL", &request);        // no_robot_state
  lcm.publish("SESSION_CONTROL", &request_other);  // unknown_session
  auto bad_command = Control("s", 9);
  auto empty_id = Control("", +SC::START);
  auto bad_mode = Control("t", +SC::START, 7, 0);
  auto ar_with_mirror = Control("t", +SC::START, +AT::MODE_AR, 1);
  auto too_many_mirrors = Control("t", +SC::START, +AT::MODE_AR_REFLECTIVE, 99);
  for (const auto* m : {&bad_command, &empty_id, &bad_mode, &ar_with_mirror, &too_many_mirrors}) {
    lcm.publish("SESSION_CONTROL", m);
  }
  auto six = Status({0, 30, 0, -60, 0, 45});
  auto nan = Status(kQDeg);
  nan.joint_position_measured[3] = std::nan("");
  auto beyond = Status({0, 130, 0, -60, 0, 45, 0});  // joint 2 limit is ±120 deg
  lcm.publish("IIWA_STATUS", &six);
  lcm.publish("IIWA_STATUS", &nan);
  lcm.publish("IIWA_STATUS", &beyond);
  auto bad_pose = State(SceneX_WR());
  bad_pose.X_WR.quaternion_wxyz[0] = 0.5;
  lcm.publish("ROBOT_STATE", &bad_pose);
  orbed::registration_t reg{};
  reg.session_id = "s";
  reg.valid = true;
  reg.X_WV_mean.position_m[0] = std::nan("");
  reg.X_WV_mean.quaternion_wxyz[0] = 1;
  lcm.publish("REGISTRATION", &reg);
  const char garbage[5] = {1, 2, 3, 4, 5};
  lcm.publish("IIWA_STATUS", garbage, sizeof(garbage));
  // Still no valid robot: the request is refused again.
  lcm.publish("SESSION_CONTROL", &request);
  EXPECT_EQ(RunAndDrain(&hmd), 0);

  EXPECT_TRUE(got.trials.empty());
  const std::map<std::string, int64_t> counts = hmd.process().rejections().counts();
  auto count = [&counts](const std::string& key) {
    const auto it = counts.find(key);
    return it == counts.end() ? 0 : it->second;
  };
  EXPECT_EQ(count("SESSION_CONTROL/no_robot_state"), 2);
  EXPECT_EQ(count("SESSION_CONTROL/unknown_session"), 1);
  EXPECT_EQ(count("SESSION_CONTROL/command"), 1);
  EXPECT_EQ(count("SESSION_CONTROL/session_id"), 1);
  EXPECT_EQ(count("SESSION_CONTROL/display_mode"), 1);
  EXPECT_EQ(count("SESSION_CONTROL/num_mirrors"), 2);
  EXPECT_EQ(count("IIWA_STATUS/num_joints"), 1);
  EXPECT_EQ(count("IIWA_STATUS/non_finite"), 1);
  EXPECT_EQ(count("IIWA_STATUS/limits"), 1);
  EXPECT_EQ(count("IIWA_STATUS/decode/truncated"), 1);  // 5 bytes: not even a fingerprint
  EXPECT_EQ(count("ROBOT_STATE/pose"), 1);
  EXPECT_EQ(count("REGISTRATION/pose"), 1);
  EXPECT_EQ(hmd.process().rejections().total(), 14);
  // The heartbeat carries them too, and the process kept publishing poses throughout.
  EXPECT_EQ(hmd.process().MakeStatus().rejected_inputs, 14);
  EXPECT_GT(got.est.size(), 10u);
}

// The pose and gaze timers' callbacks driven directly (no wall-clock run: how many ticks a busy
// machine fits into half a second is not what this test is about).
TEST(HmdProcess, PoseAndTruthShareSeqAndStartAtTheFirstWaypoint) {
  HmdProcess hmd(MemqFlags(0), Inline());
  Collector got;
  got.Attach(hmd.process().lcm());
  for (int i = 0; i < 30; ++i) {
    hmd.PublishPose();
    if (i % 6 == 0) hmd.PublishGaze();
  }
  Drain(hmd.process().lcm());
  ASSERT_EQ(got.est.size(), 30u);
  ASSERT_EQ(got.est.size(), got.truth.size());
  for (size_t i = 0; i < got.est.size(); ++i) {
    EXPECT_EQ(got.est[i].seq, static_cast<int64_t>(i));
    EXPECT_EQ(got.truth[i].seq, got.est[i].seq);
    EXPECT_EQ(got.truth[i].utime, got.est[i].utime);
    EXPECT_EQ(got.est[i].hmd_name, "hololens1");
    EXPECT_TRUE(CheckPose(got.est[i].X_WH, "X_WH").empty());
    EXPECT_GE(got.est[i].tracking_state, +orbed::hmd_pose_t::TRACKING);
    EXPECT_LE(got.est[i].tracking_state, +orbed::hmd_pose_t::RELOCALIZED);
  }
  // viraal_walk.yaml: the wearer starts at foot_end, (1.45, -1.20, 1.70) m, dwelling 2 s.
  const Eigen::Vector3d p_WH = ToVector3(got.truth.front().X_WH.position_m);
  EXPECT_NEAR(p_WH.x(), 1.45, 1e-9);
  EXPECT_NEAR(p_WH.y(), -1.20, 1e-9);
  EXPECT_NEAR(p_WH.z(), 1.70, 1e-9);
  // The map starts on W: the estimate is the truth up to jitter (slam.yaml: 0.5 mm std).
  EXPECT_LT((ToVector3(got.est.front().X_WH.position_m) - p_WH).norm(), 0.005);
  // Gaze rays from the head: unit direction.
  ASSERT_EQ(got.gaze.size(), 5u);
  EXPECT_NEAR(ToVector3(got.gaze.back().direction_W).norm(), 1.0, 1e-9);
}

// Several headsets and arms: --headset suffixes what the headset publishes, --arm what
// it reads of its arm, and the person walks the shipped walk carried to that arm's base.
TEST(HmdProcess, AHeadsetAtAnotherArmUsesItsChannelsAndWalksAroundThatArm) {
  HmdOptions o = Inline();
  o.scene_path = HmdSourcePath("sim/models/scenes/four_arms_or.yaml");
  o.headset = "h1";
  o.arm = "a2";
  HmdProcess hmd(MemqFlags(0), o);
  EXPECT_EQ(hmd.options().hmd_pose_channel, "HMD_POSE_H1");
  EXPECT_EQ(hmd.options().camera_channel, "HMD_CAMERA_H1");
  EXPECT_EQ(hmd.options().trial_channel, "ALIGNMENT_TRIAL_H1");
  EXPECT_EQ(hmd.options().session_control_channel, "SESSION_CONTROL_H1");
  EXPECT_EQ(hmd.options().registration_channel, "REGISTRATION_H1");
  EXPECT_EQ(hmd.options().iiwa_status_channel, "IIWA_STATUS_A2");
  EXPECT_EQ(hmd.options().robot_state_channel, "ROBOT_STATE_A2");
  EXPECT_EQ(hmd.options().guidance_channel, "GUIDANCE_A2");
  Collector plain;  // the single headset's channels
  plain.Attach(hmd.process().lcm());
  std::vector<orbed::hmd_pose_t> truth;
  lcm::LCM& lcm = hmd.process().lcm();
  CollectInto(lcm, "HMD_POSE_TRUTH_H1", &truth);
  hmd.PublishPose();
  hmd.PublishGaze();
  Drain(lcm);
  EXPECT_TRUE(plain.truth.empty() && plain.est.empty() && plain.gaze.empty());
  ASSERT_EQ(truth.size(), 1u);
  // foot_end (1.45, -1.20, 1.70) of viraal_walk.yaml, written for the single arm (a0's base), carried
  // to a2's base.
  const sim::Scene scene = sim::LoadSceneFile(o.scene_path);
  const Eigen::Vector3d expected =
      scene.FindArm("a2")->X_WR * scene.FindArm("a0")->X_WR.inverse() * Eigen::Vector3d(1.45, -1.20, 1.70);
  EXPECT_LT((ToVector3(truth[0].X_WH.position_m) - expected).norm(), 1e-9);
  EXPECT_GT((expected - Eigen::Vector3d(1.45, -1.20, 1.70)).norm(), 0.5);  // a2 stands elsewhere

  HmdOptions bad = o;
  bad.arm = "a7";
  try {
    HmdProcess unknown(MemqFlags(0), bad);
    ADD_FAILURE() << "an arm the scene lacks was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("the arms a0, a1, a2, a3"), std::string::npos) << e.what();
  }
  bad = o;
  bad.headset = "H1";
  EXPECT_THROW(HmdProcess(MemqFlags(0), bad), std::invalid_argument);
}

// A collaborator's headset as the first display (--collaborator h2): REFLECTIVE_VIEW_H1's frame is
// stamped with h2's true camera in this headset's map of the moment (M = X_WH_est X_WH_true^-1 of
// its own sample; no anchor error configured), and a trial is RunHeadsetTrial with that camera.
TEST(HmdProcess, ACollaboratorsCameraIsTheFirstDisplay) {
  HmdOptions o = Inline();
  o.headset = "h1";
  o.collaborator = "h2";
  HmdProcess hmd(MemqFlags(0), o);
  lcm::LCM& lcm = hmd.process().lcm();
  std::vector<orbed::reflective_view_t> views;
  std::vector<orbed::hmd_pose_t> est, truth;
  std::vector<orbed::alignment_trial_t> trials;
  CollectInto(lcm, "REFLECTIVE_VIEW_H1", &views);
  CollectInto(lcm, "HMD_POSE_H1", &est);
  CollectInto(lcm, "HMD_POSE_TRUTH_H1", &truth);
  CollectInto(lcm, "ALIGNMENT_TRIAL_H1", &trials);
  const auto status = Status(kQDeg);
  const auto state = State(SceneX_WR());
  lcm.publish("IIWA_STATUS", &status);
  lcm.publish("ROBOT_STATE", &state);
  // h2 stands 1.2 m along the table from where h1 starts, looking the same way.
  hmd.PublishPose();
  Drain(lcm);
  ASSERT_EQ(truth.size(), 1u);
  orbed::hmd_pose_t h2 = truth[0];
  h2.X_WC.position_m[1] += 1.2;
  const Eigen::Isometry3d X_WC2 = FromPose(h2.X_WC);
  lcm.publish("HMD_POSE_TRUTH_H2", &h2);
  Drain(lcm);
  hmd.PublishPose();
  hmd.RequestCamera();
  hmd.RequestReflective();
  Drain(lcm);
  ASSERT_EQ(views.size(), 1u);
  const Eigen::Isometry3d M = FromPose(est.back().X_WH) * FromPose(truth.back().X_WH).inverse();
  EXPECT_TRUE(FromPose(views[0].image.X_WC).isApprox(M * X_WC2, 1e-9));
  EXPECT_GT((FromPose(views[0].image.X_WC).translation() - FromPose(est.back().X_WC).translation()).norm(),
            1.0);

  const auto start = Control("co", +SC::START, +AT::MODE_AR_REFLECTIVE, 1);
  const auto request = Control("co", +SC::REQUEST_TRIAL);
  lcm.publish("SESSION_CONTROL_H1", &start);
  lcm.publish("SESSION_CONTROL_H1", &request);
  Drain(lcm);
  ASSERT_EQ(trials.size(), 1u);
  HeadsetTrialInputs in = ShippedTrialInputs(hmd, status, state, 1, "co", 1);
  in.collaborator_X_WC_true = X_WC2;
  const TrialOutcome with = RunHeadsetTrial(hmd.config(), in);
  EXPECT_TRUE(FromPose(trials[0].X_WV).isApprox(with.alignment.X_WV, 1e-12));
  in.collaborator_X_WC_true.reset();
  EXPECT_FALSE(FromPose(trials[0].X_WV).isApprox(RunHeadsetTrial(hmd.config(), in).alignment.X_WV, 1e-9));
}

TEST(HmdProcess, CameraReflectiveAndArViewCarryTheirGeometry) {
  HmdOptions options = Inline();
  options.displays = 1;
  HmdProcess hmd(MemqFlags(0), options);
  Collector got;
  lcm::LCM& lcm = hmd.process().lcm();
  got.Attach(lcm);
  const auto status = Status(kQDeg);
  const auto state = State(SceneX_WR());
  lcm.publish("IIWA_STATUS", &status);
  lcm.publish("ROBOT_STATE", &state);
  Drain(lcm);
  hmd.PublishPose();
  hmd.RequestCamera();  // display 0 captures at the first waypoint, i.e. this frame
  hmd.RequestReflective();
  hmd.RequestArView();
  hmd.PublishGaze();
  Drain(lcm);

  ASSERT_EQ(got.est.size(), 1u);
  ASSERT_EQ(got.camera.size(), 1u);
  const orbed::image_t& cam = got.camera[0];
  EXPECT_EQ(cam.pixel_format, +orbed::image_t::FORMAT_JPEG);
  EXPECT_EQ(cam.width, 1280);
  EXPECT_EQ(cam.height, 720);
  EXPECT_DOUBLE_EQ(cam.fx_px, 1545.4);
  EXPECT_DOUBLE_EQ(cam.fy_px, 1551.2);
  EXPECT_DOUBLE_EQ(cam.cx_px, 597.2);
  EXPECT_DOUBLE_EQ(cam.cy_px, 322.1);
  // Stamped with the ESTIMATED camera pose of the sample it was rendered at, and its utime.
  EXPECT_EQ(cam.pose_utime, got.est[0].utime);
  EXPECT_EQ(cam.utime, got.est[0].utime);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(cam.X_WC.position_m[i], got.est[0].X_WC.position_m[i]);
  const cv::Mat frame = render::DecodeJpeg(cam.data);
  ASSERT_EQ(frame.cols, 1280);
  ASSERT_EQ(frame.rows, 720);

  ASSERT_EQ(got.reflective.size(), 1u);
  const orbed::reflective_view_t& rv = got.reflective[0];
  EXPECT_EQ(rv.display_id, 0);
  EXPECT_EQ(rv.source_utime, cam.utime);
  const double K_m[3][3] = {{1545.4, 0, 597.2}, {0, -1551.2, -322.1}, {0, 0, 1}};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(rv.K_m[r][c], K_m[r][c]) << r << "," << c;
  }
  // X_WM: the camera turned π about its x axis and moved D along its principal ray.
  const Eigen::Isometry3d X_WC = FromPose(rv.image.X_WC);
  const Eigen::Isometry3d X_WM = FromPose(rv.X_WM);
  EXPECT_GT(rv.distance_m, 0.5);
  EXPECT_LT(rv.distance_m, 5.0);
  EXPECT_LT((X_WM.translation() - (X_WC.translation() + rv.distance_m * X_WC.linear().col(2))).norm(), 1e-9);
  EXPECT_LT((X_WM.linear().col(0) - X_WC.linear().col(0)).norm(), 1e-9);
  EXPECT_LT((X_WM.linear().col(1) + X_WC.linear().col(1)).norm(), 1e-9);
  EXPECT_LT((X_WM.linear().col(2) + X_WC.linear().col(2)).norm(), 1e-9);
  // D: from the capture camera centre to the gaze hit ON THE ROBOT (paper Sec. II-B), found here by
  // casting the capture-time line of sight against the real robot alone.
  const sim::RobotModel robot =
      sim::RobotModel::LoadFile(HmdSourcePath(sim::RobotModel::kDefaultUrdfRelativePath));
  render::SceneGeometry robot_only;
  Eigen::VectorXd q(kQDeg.size());
  for (std::size_t i = 0; i < kQDeg.size(); ++i) q[i] = kQDeg[i] * kDegToRad;
  robot_only.PoseRobot(robot_only.AddRobot(robot, render::BodyKind::kRealRobot), q, SceneX_WR());
  ASSERT_EQ(got.truth.size(), 1u);
  const Eigen::Isometry3d X_WH_true = FromPose(got.truth[0].X_WH);
  const RayHit on_robot = CastRay(robot_only, X_WH_true.translation(), X_WH_true.linear().col(2));
  ASSERT_TRUE(on_robot.hit);
  EXPECT_NEAR(rv.distance_m, (on_robot.p_WQ - FromPose(got.truth[0].X_WC).translation()).norm(), 1e-6);
  const cv::Mat mirror = render::DecodeJpeg(rv.image.data);
  ASSERT_EQ(mirror.cols, 1280);
  ASSERT_EQ(mirror.rows, 720);

  // The AR view is the camera frame with the hologram drawn over it: same size, not the same picture.
  ASSERT_EQ(got.ar.size(), 1u);
  const cv::Mat ar = render::DecodeJpeg(got.ar[0].data);
  ASSERT_EQ(ar.cols, 1280);
  cv::Mat diff;
  cv::absdiff(ar, frame, diff);
  EXPECT_GT(cv::countNonZero(diff.reshape(1) > 40), 2000);

  // The gaze from the foot end looks at the robot's middle: it hits the real world ~2 m away.
  ASSERT_EQ(got.gaze.size(), 1u);
  EXPECT_TRUE(got.gaze[0].valid);
  EXPECT_GT(got.gaze[0].hit_distance_m, 0.5);
  EXPECT_LT(got.gaze[0].hit_distance_m, 4.0);

  // A second frame with nothing changed reuses the same JPEG bytes.
  hmd.PublishPose();
  hmd.RequestCamera();
  Drain(lcm);
  ASSERT_EQ(got.camera.size(), 2u);
  EXPECT_EQ(got.camera[1].data, got.camera[0].data);
  EXPECT_EQ(got.camera[1].pose_utime, got.est[1].utime);
}

// The shell on the worker thread: every request that is waited for (Flush) is published; what the
// frames hold is compared with the inline path in image_pipeline_test.
TEST(HmdProcess, ThreadedPipelinePublishesEveryFlushedRequest) {
  HmdProcess hmd(MemqFlags(0), HmdOptions{});
  Collector got;
  got.Attach(hmd.process().lcm());
  for (int i = 0; i < 5; ++i) {
    hmd.PublishPose();
    hmd.RequestCamera();
    hmd.RequestReflective();
    hmd.RequestArView();
    hmd.Flush();
  }
  Drain(hmd.process().lcm());
  EXPECT_EQ(got.camera.size(), 5u);
  EXPECT_EQ(got.reflective.size(), 5u);  // one display (the default)
  EXPECT_GE(got.ar.size(), 1u);
  EXPECT_EQ(hmd.skipped_frames(), 0);
  for (size_t i = 0; i < got.camera.size(); ++i) EXPECT_EQ(got.camera[i].pose_utime, got.est[i].utime);
}

TEST(HmdProcess, InteractiveKeysMoveTheHologramAndEnterSubmits) {
  HmdOptions options = Inline();
  options.interactive = true;  // no window unless Run() is called
  HmdProcess hmd(MemqFlags(0), options);
  Collector got;
  lcm::LCM& lcm = hmd.process().lcm();
  got.Attach(lcm);
  const Eigen::Isometry3d X_WV0 = hmd.CurrentX_WV();
  hmd.HandleKey('d');  // +x by the default 5 mm
  EXPECT_NEAR((hmd.CurrentX_WV().translation() - X_WV0.translation()).x(), 0.005, 1e-12);
  hmd.HandleKey(']');  // 10 mm steps
  hmd.HandleKey('w');
  EXPECT_NEAR((hmd.CurrentX_WV().translation() - X_WV0.translation()).y(), 0.010, 1e-12);
  hmd.HandleKey('l');  // yaw +0.5 deg about z_W
  const Eigen::Matrix3d R = X_WV0.linear().transpose() * hmd.CurrentX_WV().linear();
  EXPECT_NEAR(Eigen::AngleAxisd(R).angle(), 0.5 * kDegToRad, 1e-12);
  const Eigen::Matrix3d dR = hmd.CurrentX_WV().linear() * X_WV0.linear().transpose();
  EXPECT_NEAR(Eigen::AngleAxisd(dR).axis().z(), 1.0, 1e-9);

  hmd.HandleKey(13);  // no robot yet: nothing is submitted
  Drain(lcm);
  EXPECT_TRUE(got.trials.empty());
  const auto status = Status(kQDeg);
  const auto state = State(SceneX_WR());
  lcm.publish("IIWA_STATUS", &status);
  lcm.publish("ROBOT_STATE", &state);
  Drain(lcm);
  hmd.HandleKey(13);
  Drain(lcm);
  ASSERT_EQ(got.trials.size(), 1u);
  ASSERT_EQ(got.control.size(), 1u);  // the local session's START
  EXPECT_EQ(got.control[0].command, +SC::START);
  EXPECT_EQ(got.trials[0].session_id, got.control[0].session_id);
  EXPECT_EQ(got.trials[0].trial_index, 0);
  EXPECT_EQ(got.trials[0].display_mode, +AT::MODE_AR_REFLECTIVE);
  EXPECT_EQ(got.trials[0].user_id, "interactive");
  EXPECT_TRUE(FromPose(got.trials[0].X_WV).isApprox(hmd.CurrentX_WV(), 1e-12));
  hmd.HandleKey(13);  // the echoed START did not reset the index
  Drain(lcm);
  ASSERT_EQ(got.trials.size(), 2u);
  EXPECT_EQ(got.trials[1].trial_index, 1);

  // The window: two 800×450 panels over a status bar; the help overlay changes the picture.
  const cv::Mat without_help = hmd.CurrentWindowImage();
  EXPECT_EQ(without_help.cols, 1600);
  EXPECT_GT(without_help.rows, 450);
  hmd.HandleKey('h');
  const cv::Mat with_help = hmd.CurrentWindowImage();
  cv::Mat diff;
  cv::absdiff(with_help, without_help, diff);
  EXPECT_GT(cv::countNonZero(diff.reshape(1)), 1000);
}

TEST(HmdConfig, ErrorsNameTheFileAndTheKey) {
  const std::string dir = ::testing::TempDir();
  const std::string bad_waypoint = dir + "/hmd_bad_waypoint.yaml";
  std::ofstream(bad_waypoint) << "hmd:\n  displays:\n    - {capture_waypoint: nowhere}\n";
  std::vector<std::string> paths;
  for (const auto& rel : DefaultHmdConfigRelativePaths()) paths.push_back(HmdSourcePath(rel));
  paths.push_back(bad_waypoint);
  try {
    LoadHmdConfigs(paths);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("hmd_bad_waypoint.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("nowhere"), std::string::npos) << e.what();
  }
  const std::string unknown = dir + "/hmd_unknown_key.yaml";
  std::ofstream(unknown) << "hmd:\n  gaze_hz: 10\nslamm: {}\n";
  paths.back() = unknown;
  try {
    LoadHmdConfigs(paths);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("slamm"), std::string::npos) << e.what();
  }
  // The shipped files: two displays placed, alignment at head_end.
  paths.pop_back();
  const HmdConfigSet set = LoadHmdConfigs(paths);
  ASSERT_EQ(set.hmd.displays.size(), 2u);
  EXPECT_EQ(set.hmd.displays[0].capture_waypoint, "foot_end");
  EXPECT_EQ(set.hmd.align_waypoint, "head_end");
}

// A --config overlay changes only the keys it has: everything else stays as the files before it
// set it (not the compiled-in defaults).
TEST(HmdConfig, OverlaysMergeKeyByKey) {
  std::vector<std::string> paths;
  for (const auto& rel : DefaultHmdConfigRelativePaths()) paths.push_back(HmdSourcePath(rel));
  const HmdConfigSet shipped = LoadHmdConfigs(paths);
  const std::string first = ::testing::TempDir() + "/hmd_overlay_seed.yaml";
  std::ofstream(first) << "user: {seed: 7}\nslam: {seed: 9, jitter: {translation_std_m: 0.004}}\n"
                          "hmd: {gaze_hz: 20}\n";
  const std::string second = ::testing::TempDir() + "/hmd_overlay_offset.yaml";
  std::ofstream(second) << "user:\n  start_offset: {rpy_deg: [0, 0, 10]}\n  nudging: {gain: 0.5}\n";
  paths.push_back(first);
  paths.push_back(second);
  const HmdConfigSet set = LoadHmdConfigs(paths);
  // What the overlays set.
  EXPECT_EQ(set.user.seed, 7u);
  EXPECT_EQ(set.slam.seed, 9u);
  EXPECT_DOUBLE_EQ(set.slam.jitter_translation_std_m, 0.004);
  EXPECT_DOUBLE_EQ(set.hmd.gaze_hz, 20);
  EXPECT_DOUBLE_EQ(set.user.gain, 0.5);
  EXPECT_NEAR(Eigen::AngleAxisd(set.user.X_RV_start.linear()).angle(), 10 * kDegToRad, 1e-12);
  // What they leave: the start offset's position (shipped: 0.10, -0.08, 0.05), the rest of the
  // user, the SLAM model and the process as the shipped files set them.
  EXPECT_TRUE(set.user.X_RV_start.translation().isApprox(shipped.user.X_RV_start.translation(), 0));
  EXPECT_NEAR(set.user.X_RV_start.translation().x(), 0.10, 1e-12);
  EXPECT_DOUBLE_EQ(set.user.depth_bias_fraction_std, shipped.user.depth_bias_fraction_std);
  EXPECT_DOUBLE_EQ(set.user.fov_v_deg, shipped.user.fov_v_deg);
  EXPECT_EQ(set.user.max_nudges, shipped.user.max_nudges);
  EXPECT_TRUE(set.slam.X_HC.isApprox(shipped.slam.X_HC, 0));
  EXPECT_NE(set.slam.X_HC.translation().norm(), 0.0);
  EXPECT_DOUBLE_EQ(set.slam.jitter_rotation_std_deg, shipped.slam.jitter_rotation_std_deg);
  EXPECT_DOUBLE_EQ(set.slam.drift_fraction_of_distance, shipped.slam.drift_fraction_of_distance);
  EXPECT_EQ(set.hmd.name, shipped.hmd.name);
  ASSERT_EQ(set.hmd.displays.size(), 2u);
  EXPECT_EQ(set.hmd.displays[1].capture_waypoint, "head_end");
  EXPECT_EQ(set.hmd.align_waypoint, "head_end");
  // A list is replaced as a whole.
  const std::string third = ::testing::TempDir() + "/hmd_overlay_displays.yaml";
  std::ofstream(third) << "hmd: {displays: [{capture_waypoint: head_end}]}\n";
  paths.push_back(third);
  const HmdConfigSet one = LoadHmdConfigs(paths);
  ASSERT_EQ(one.hmd.displays.size(), 1u);
  EXPECT_EQ(one.hmd.displays[0].capture_waypoint, "head_end");
  EXPECT_DOUBLE_EQ(one.hmd.gaze_hz, 20);
}

}  // namespace
}  // namespace orbed::hmd

namespace orbed::hmd {
namespace {

orbed::guidance_t Guidance(int8_t mode, const std::vector<double>& target_deg) {
  orbed::guidance_t g{};
  g.utime = NowMicros();
  g.mode = mode;
  g.num_joints = static_cast<int32_t>(target_deg.size());
  for (double q : target_deg) {
    g.target_position.push_back(q * kDegToRad);
    g.current_position.push_back(0);
    g.error_deg.push_back(-q);
    g.joint_kind.push_back(0);
  }
  g.next_joint = 0;
  return g;
}

// During a set-up the hologram shows GUIDANCE's target (ar, ar_reflective) or nothing (fixed), in
// the reflective displays only in ar_reflective; during an alignment session the real arm's joints;
// a bad GUIDANCE is refused, counted and changes nothing.
TEST(HmdProcess, TheHologramShowsTheGuidancesTarget) {
  HmdProcess hmd(MemqFlags(0.05), Inline());
  lcm::LCM& lcm = hmd.process().lcm();
  EXPECT_EQ(hmd.Hologram().q_rad.size(), 0);
  EXPECT_FALSE(hmd.Hologram().hidden);
  const std::vector<double> target = {20, 35, 0, -50, 0, 40, 10};
  const auto ar = Guidance(+orbed::guidance_t::MODE_AR, target);
  lcm.publish("GUIDANCE", &ar);
  Drain(lcm);
  ASSERT_EQ(hmd.Hologram().q_rad.size(), 7);
  EXPECT_NEAR(hmd.Hologram().q_rad[1], 35 * kDegToRad, 1e-12);
  EXPECT_TRUE(hmd.Hologram().reflective_hidden);  // the ar mode has no reflective display
  const auto reflective = Guidance(+orbed::guidance_t::MODE_AR_REFLECTIVE, target);
  lcm.publish("GUIDANCE", &reflective);
  Drain(lcm);
  EXPECT_FALSE(hmd.Hologram().reflective_hidden);
  ASSERT_EQ(hmd.Hologram().reflective_q_rad.size(), 7);
  EXPECT_NEAR(hmd.Hologram().reflective_q_rad[3], -50 * kDegToRad, 1e-12);
  lcm.publish("GUIDANCE", &ar);
  Drain(lcm);
  auto bad = Guidance(+orbed::guidance_t::MODE_AR, {1, 2, 3});
  lcm.publish("GUIDANCE", &bad);
  Drain(lcm);
  EXPECT_EQ(hmd.process().rejections().counts()["GUIDANCE/field"], 1);
  EXPECT_NEAR(hmd.Hologram().q_rad[6], 10 * kDegToRad, 1e-12);
  const auto fixed = Guidance(+orbed::guidance_t::MODE_FIXED_DISPLAY, target);
  lcm.publish("GUIDANCE", &fixed);
  Drain(lcm);
  EXPECT_TRUE(hmd.Hologram().hidden);
  EXPECT_TRUE(hmd.Hologram().reflective_hidden);
  // An alignment session: the hologram is aligned at the real joints whatever the guidance says.
  const auto start = Control("align", +SC::START);
  lcm.publish("SESSION_CONTROL", &start);
  lcm.publish("GUIDANCE", &ar);
  Drain(lcm);
  EXPECT_FALSE(hmd.Hologram().hidden);
  EXPECT_EQ(hmd.Hologram().q_rad.size(), 0);
  EXPECT_FALSE(hmd.Hologram().reflective_hidden);
  EXPECT_EQ(hmd.Hologram().reflective_q_rad.size(), 0);
}

// The person as the set-up assistant: a digit selects a joint, , and . turn it by the rotation step
// through IIWA_COMMAND (each press from the measured joints; the model's limits hold); the guidance
// shows as one status line; t plans a target instead.
TEST(HmdProcess, InteractiveKeysTurnAJointOfTheRealArm) {
  HmdOptions options = Inline();
  options.interactive = true;
  HmdProcess hmd(MemqFlags(0), options);
  lcm::LCM& lcm = hmd.process().lcm();
  struct Commands {
    std::vector<orbed::iiwa_command_t> seen;
    void On(const lcm::ReceiveBuffer*, const std::string&, const orbed::iiwa_command_t* m) {
      seen.push_back(*m);
    }
  } commands;
  lcm.subscribe("IIWA_COMMAND", &Commands::On, &commands);
  hmd.HandleKey('.');  // no IIWA_STATUS yet: nothing is sent
  Drain(lcm);
  EXPECT_TRUE(commands.seen.empty());
  const auto status = Status(kQDeg);
  lcm.publish("IIWA_STATUS", &status);
  Drain(lcm);
  hmd.HandleKey('3');
  hmd.HandleKey('.');
  hmd.HandleKey('.');
  hmd.HandleKey(',');
  Drain(lcm);
  ASSERT_EQ(commands.seen.size(), 3u);
  const std::vector<double> turned = {0.5, 0.5, -0.5};  // the default step from the measured q
  for (size_t k = 0; k < 3; ++k) {
    ASSERT_EQ(commands.seen[k].num_joints, 7);
    for (int i = 0; i < 7; ++i) {
      const double expected = (kQDeg[i] + (i == 2 ? turned[k] : 0.0)) * kDegToRad;
      EXPECT_NEAR(commands.seen[k].joint_position[i], expected, 1e-12) << k << " " << i;
    }
  }
  for (int i = 0; i < 5; ++i) hmd.HandleKey('=');  // 10 deg steps (the cap)
  std::vector<double> near_limit = kQDeg;
  near_limit[1] = 115;
  const auto moved = Status(near_limit);
  lcm.publish("IIWA_STATUS", &moved);
  Drain(lcm);
  hmd.HandleKey('2');
  hmd.HandleKey('.');  // 115 + 10 deg: held at joint 2's 120 deg limit
  Drain(lcm);
  EXPECT_NEAR(commands.seen.back().joint_position[1], 120 * kDegToRad, 1e-12);
  EXPECT_NEAR(commands.seen.back().joint_position[2], 0.0, 1e-12);  // the others as measured
  const size_t sent = commands.seen.size();
  hmd.HandleKey('8');  // the iiwa has 7 joints: nothing
  hmd.HandleKey('.');
  Drain(lcm);
  EXPECT_EQ(commands.seen.size(), sent + 1);
  EXPECT_NEAR(commands.seen.back().joint_position[1], 120 * kDegToRad, 1e-12);  // still joint 2

  // Planning (t): the target starts at the fresh GUIDANCE's (else the arm's), , and . turn its
  // joints and the hologram shows it; Enter sends it as a SETUP_TASK in the guidance's mode.
  struct Tasks {
    std::vector<orbed::setup_task_t> seen;
    void On(const lcm::ReceiveBuffer*, const std::string&, const orbed::setup_task_t* m) {
      seen.push_back(*m);
    }
  } tasks;
  lcm.subscribe("SETUP_TASK", &Tasks::On, &tasks);
  const std::vector<double> target_deg = {20, 35, 0, -50, 0, 40, 10};
  const auto guidance = Guidance(+orbed::guidance_t::MODE_AR_REFLECTIVE, target_deg);
  lcm.publish("GUIDANCE", &guidance);
  Drain(lcm);
  hmd.HandleKey('t');
  hmd.HandleKey('4');
  hmd.HandleKey(',');  // 10 deg steps still
  ASSERT_EQ(hmd.Hologram().q_rad.size(), 7);
  EXPECT_NEAR(hmd.Hologram().q_rad[3], -60 * kDegToRad, 1e-12);
  EXPECT_NEAR(hmd.Hologram().reflective_q_rad[3], -60 * kDegToRad, 1e-12);
  hmd.HandleKey(13);
  Drain(lcm);
  ASSERT_EQ(tasks.seen.size(), 1u);
  EXPECT_EQ(tasks.seen[0].task_id, "interactive-1");
  EXPECT_EQ(tasks.seen[0].mode, +orbed::guidance_t::MODE_AR_REFLECTIVE);
  const sim::RobotModel model =
      sim::RobotModel::LoadFile(HmdSourcePath(sim::RobotModel::kDefaultUrdfRelativePath));
  EXPECT_EQ(guidance::CheckSetupTask(tasks.seen[0], model, 0.0), "");
  for (int i = 0; i < 7; ++i) {
    EXPECT_NEAR(tasks.seen[0].target_position[i], (i == 3 ? -60.0 : target_deg[i]) * kDegToRad, 1e-12);
  }
  EXPECT_EQ(commands.seen.size(), sent + 1);  // planning moved no arm
  hmd.HandleKey('t');                         // back to the arm
  hmd.HandleKey('.');
  Drain(lcm);
  EXPECT_EQ(commands.seen.size(), sent + 2);

  EXPECT_EQ(GuidanceLine("ar", {1.0, -12.46}, 1, false),
            "guidance (ar): next joint 2 | error [deg] +1.0 -12.5");
  EXPECT_EQ(GuidanceLine("fixed", {0.0}, -1, true), "guidance (fixed): done | error [deg] +0.0");
}

}  // namespace
}  // namespace orbed::hmd
