// ViraalConductor in emulated time: no bus, no clock, no sleeps. A fake clock stamps every input;
// the tests answer the conductor's publications by hand (timeouts, the retry schedule) or through
// a small event-driven emulation of the sim, the user and the registration server (a whole run,
// also over a network that loses, duplicates and delays messages).
#include "experiments/viraal/viraal_conductor.h"

#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/source_paths.h"
#include "base/units.h"
#include "experiments/viraal/resume.h"
#include "lcmtypes/contract/conversions.h"

namespace orbed::scenario {
namespace {

using Phase = ViraalConductor::Phase;
using Status = ViraalConductor::Status;

// The emulated clocks: t_s from 100 s, utime = 1.7e15 µs + t_s.
class FakeClock {
 public:
  ConductorTime Now() const { return {t_s_, 1'700'000'000'000'000 + std::llround(t_s_ * 1e6)}; }
  double t_s() const { return t_s_; }
  void Set(double t_s) { t_s_ = t_s; }
  void Advance(double dt_s) { t_s_ += dt_s; }

 private:
  double t_s_{100.0};
};

// The trocar_or scene's base: (0.25, -0.55, 0.75), yaw 90 deg.
Eigen::Isometry3d SceneBase() {
  Eigen::Isometry3d X_WR = Eigen::Isometry3d::Identity();
  X_WR.linear() = Eigen::AngleAxisd(90 * kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X_WR.translation() = Eigen::Vector3d(0.25, -0.55, 0.75);
  return X_WR;
}

orbed::robot_state_t RobotState(const std::vector<double>& q_rad,
                                int8_t motion = orbed::robot_state_t::MOTION_IDLE,
                                const std::string& stop_reason = "") {
  orbed::robot_state_t s{};
  s.robot_name = "iiwa7";
  s.X_WR = ToPose(SceneBase());
  s.X_RF = ToPose(Eigen::Isometry3d::Identity());
  s.X_RT = s.X_RF;
  s.num_joints = static_cast<int32_t>(q_rad.size());
  s.joint_position = q_rad;
  s.joint_limit_hit.assign(q_rad.size(), 0);
  s.num_links = 0;
  s.motion_state = motion;
  s.stop_reason = stop_reason;
  return s;
}

std::vector<double> Rad(const std::vector<double>& q_deg) {
  std::vector<double> q;
  for (double v : q_deg) q.push_back(v * kDegToRad);
  return q;
}

orbed::plan_check_reply_t PlanReply(int64_t request_id) {
  orbed::plan_check_reply_t reply{};
  reply.request_id = request_id;
  reply.request_valid = reply.within_limits = reply.feasible = true;
  reply.min_distance_m = 0.1;
  return reply;
}

// A label per publication: the channel, and the command for SESSION_CONTROL.
std::string Label(const Publication& p) {
  if (const auto* control = std::get_if<orbed::session_control_t>(&p.message)) {
    const char* names[] = {"START", "RESET", "COMPUTE", "STOP", "REQUEST_TRIAL"};
    return p.channel + " " + names[control->command];
  }
  return p.channel;
}

// A conductor on the shipped scenario (2 modes x 3 trials, 3 configurations, 3 landmarks) with
// the default timeouts, the fake clock and a record of everything it did.
class Bench {
 public:
  explicit Bench(ConductorOptions options = Options())
      : conductor_(options, orbed::sim::RobotModel::LoadFile(
                                orbed::SourceTreePath(orbed::sim::RobotModel::kDefaultUrdfRelativePath))) {}

  static ConductorOptions Options() {
    ConductorOptions options;
    options.config = viraal::LoadScenarioFile(orbed::SourceTreePath(viraal::kDefaultScenarioRelativePath));
    options.run_id = "emu";
    return options;
  }

  // Each input at the clock's time; its actions are recorded.
  void Start() { Record(conductor_.Start(clock_.Now())); }
  void Tick() { Record(conductor_.Tick(clock_.Now())); }
  void TickAt(double t_s) {
    clock_.Set(t_s);
    Tick();
  }
  void Send(const orbed::robot_state_t& m) { Record(conductor_.OnRobotState(m, clock_.Now())); }
  void Send(const orbed::plan_check_reply_t& m) { Record(conductor_.OnPlanCheckReply(m, clock_.Now())); }
  void Send(const orbed::alignment_trial_t& m) { Record(conductor_.OnTrial(m, clock_.Now())); }
  void Send(const orbed::registration_t& m) { Record(conductor_.OnRegistration(m, clock_.Now())); }
  void Send(const orbed::misalignment_t& m) { Record(conductor_.OnMisalignment(m, clock_.Now())); }
  void Send(const orbed::landmark_t& m) { Record(conductor_.OnLandmark(m, clock_.Now())); }

  // Started, the robot seen and every plan check answered: the first IIWA_COMMAND is out.
  void StartAndCheckPlans() {
    Start();
    clock_.Advance(0.1);
    Send(RobotState(std::vector<double>(7, 0.0)));
    clock_.Advance(0.01);
    for (const Publication& p : Sent("PLAN_CHECK_REQUEST")) {
      Send(PlanReply(std::get<orbed::plan_check_request_t>(p.message).request_id));
    }
    ASSERT_EQ(conductor_.phase(), Phase::kMove);
  }

  std::vector<Publication> Sent(const std::string& channel) const {
    std::vector<Publication> out;
    for (const Publication& p : sent_)
      if (p.channel == channel) out.push_back(p);
    return out;
  }
  std::vector<std::string> Labels() const {
    std::vector<std::string> out;
    for (const Publication& p : sent_) out.push_back(Label(p));
    return out;
  }

  ViraalConductor& conductor() { return conductor_; }
  FakeClock& clock() { return clock_; }
  const std::vector<Publication>& sent() const { return sent_; }
  const std::vector<std::string>& lines() const { return lines_; }
  const std::vector<Refusal>& refusals() const { return refusals_; }
  // The publications of the last input only.
  const std::vector<Publication>& last() const { return last_; }

  void Record(const ConductorActions& actions) {
    last_.clear();
    for (const ConductorAction& action : actions) {
      if (const auto* p = std::get_if<Publication>(&action)) {
        sent_.push_back(*p);
        last_.push_back(*p);
      } else if (const auto* line = std::get_if<ProgressLine>(&action)) {
        lines_.push_back(line->text);
      } else if (const auto* refusal = std::get_if<Refusal>(&action)) {
        refusals_.push_back(*refusal);
      }
    }
  }

 private:
  ViraalConductor conductor_;
  FakeClock clock_;
  std::vector<Publication> sent_, last_;
  std::vector<std::string> lines_;
  std::vector<Refusal> refusals_;
};

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The scenario chooses where the reflective display captures (contract change 6): its START says
// so; without a choice (the shipped file) the START names none and the headset uses its own.
TEST(ViraalConductor, TheReflectiveStartCarriesTheScenariosCaptureWaypoints) {
  for (const bool chosen : {false, true}) {
    ConductorOptions options = Bench::Options();
    if (chosen) options.config.capture_waypoints = {"head_end"};
    Bench bench(options);
    bench.StartAndCheckPlans();
    const std::vector<Publication> controls = bench.Sent("SESSION_CONTROL");
    ASSERT_FALSE(controls.empty());
    const auto start = std::get<orbed::session_control_t>(controls[0].message);
    ASSERT_EQ(start.command, +orbed::session_control_t::START);
    ASSERT_GT(start.num_mirrors, 0);
    EXPECT_EQ(start.num_capture_waypoints, chosen ? 1 : 0);
    EXPECT_EQ(start.capture_waypoint,
              chosen ? std::vector<std::string>{"head_end"} : std::vector<std::string>{});
  }
  ConductorOptions two = Bench::Options();
  two.config.capture_waypoints = {"foot_end", "head_end"};  // two for the one display
  EXPECT_THROW(ViraalConductor(two, orbed::sim::RobotModel::LoadFile(orbed::SourceTreePath(
                                        orbed::sim::RobotModel::kDefaultUrdfRelativePath))),
               std::invalid_argument);
}

TEST(ViraalConductor, InputsBeforeStartAreALogicError) {
  Bench bench;
  EXPECT_THROW(bench.Tick(), std::logic_error);
  bench.Start();
  EXPECT_THROW(bench.Start(), std::logic_error);
}

TEST(ViraalConductor, BadOptionsAreRefusedAtConstruction) {
  ConductorOptions options = Bench::Options();
  options.request_deadline_s = 0;
  EXPECT_THROW(Bench{options}, std::invalid_argument);
  options = Bench::Options();
  options.run_id = "";
  EXPECT_THROW(Bench{options}, std::invalid_argument);
  options = Bench::Options();
  options.config.landmarks = {"iiwa_link_9"};
  EXPECT_THROW(Bench{options}, std::invalid_argument);
}

TEST(ViraalConductor, NoRobotStateWithinTheStartupTimeoutNamesTheSim) {
  Bench bench;
  bench.Start();
  ASSERT_EQ(bench.lines().size(), 1u);
  EXPECT_EQ(bench.lines()[0], "ViRAAl run emu: waiting for the robot (ROBOT_STATE)");
  // A ROBOT_STATE with a non-unit quaternion is refused, counted and later quoted.
  orbed::robot_state_t bad = RobotState(std::vector<double>(7, 0.0));
  bad.X_WR.quaternion_wxyz[0] = 0.5;
  bench.Send(bad);
  ASSERT_EQ(bench.refusals().size(), 1u);
  EXPECT_EQ(bench.refusals()[0].key, "ROBOT_STATE/field");
  bench.TickAt(100.0 + 9.99);
  EXPECT_EQ(bench.conductor().status(), Status::kRunning);
  bench.TickAt(100.0 + 10.01);
  EXPECT_EQ(bench.conductor().status(), Status::kFailed);
  const viraal::RunResults& r = bench.conductor().results();
  EXPECT_FALSE(r.ok);
  EXPECT_TRUE(
      Contains(r.error, "no valid ROBOT_STATE on ROBOT_STATE within 10.0 s: is orbed-iiwa-sim running?"))
      << r.error;
  EXPECT_TRUE(Contains(r.error, "(last refused input: " + bench.refusals()[0].reason + ")")) << r.error;
  EXPECT_NEAR(r.duration_s, 10.01, 1e-9);
  EXPECT_EQ(r.started_utime, 1'700'000'100'000'000);
  EXPECT_EQ(r.rejected_inputs, 1);
  EXPECT_TRUE(bench.sent().empty());
  // Done is final: later time and input change nothing.
  bench.TickAt(200);
  bench.Send(RobotState(std::vector<double>(7, 0.0)));
  EXPECT_TRUE(bench.sent().empty());
  EXPECT_EQ(bench.conductor().results().error, r.error);
}

// The bytes of a publication, to compare a retry with the original.
std::vector<uint8_t> Bytes(const Publication& p) {
  return std::visit(
      [](const auto& msg) {
        std::vector<uint8_t> bytes(msg.getEncodedSize());
        msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
        return bytes;
      },
      p.message);
}

TEST(ViraalConductor, MissingPlanCheckRepliesFailAfterTheRequestDeadline) {
  Bench bench;
  bench.Start();
  const int64_t start_utime = bench.clock().Now().utime;
  bench.clock().Advance(0.5);
  bench.Send(RobotState(std::vector<double>(7, 0.0)));
  const std::vector<Publication> requests = bench.Sent("PLAN_CHECK_REQUEST");
  ASSERT_EQ(requests.size(), 3u);
  const double sent_s = bench.clock().t_s();
  const auto& config = bench.conductor().options().config;
  for (size_t k = 0; k < 3; ++k) {
    const auto& request = std::get<orbed::plan_check_request_t>(requests[k].message);
    EXPECT_EQ(request.request_id, start_utime + 1 + static_cast<int64_t>(k));  // ids of the run
    EXPECT_EQ(request.utime, bench.clock().Now().utime);
    ASSERT_EQ(request.num_joints, 7);
    for (int j = 0; j < 7; ++j)
      EXPECT_NEAR(request.joint_position[j], config.configurations_deg[k][j] * kDegToRad, 1e-15);
  }
  // Two answered (one of them twice), one reply for someone else's request.
  const int64_t base = std::get<orbed::plan_check_request_t>(requests[0].message).request_id;
  bench.Send(PlanReply(base));
  bench.Send(PlanReply(base));
  bench.Send(PlanReply(base + 2));
  bench.Send(PlanReply(base + 7));
  EXPECT_TRUE(bench.refusals().empty());
  bench.TickAt(sent_s + 59.99);  // one retry, of the unanswered request only
  EXPECT_EQ(bench.conductor().phase(), Phase::kCheckPlans);
  ASSERT_EQ(bench.last().size(), 1u);
  EXPECT_EQ(Bytes(bench.last()[0]), Bytes(requests[1]));
  bench.TickAt(sent_s + 60.01);
  EXPECT_EQ(bench.conductor().status(), Status::kFailed);
  EXPECT_EQ(bench.conductor().results().error,
            "orbed-iiwa-sim answered 2 of 3 PLAN_CHECK_REQUESTs within 60.0 s, sent 2 times");
  EXPECT_EQ(bench.Labels(), std::vector<std::string>(4, "PLAN_CHECK_REQUEST"));  // nothing moved
}

// Unanswered requests go out again 0.2 s after the first send, then after intervals doubling up to
// 0.5 s (0.2, 0.4, 0.5, 0.5, ...), byte for byte, only those still unanswered, until the deadline
// (here 5 s).
TEST(ViraalConductor, UnansweredRequestsAreRetriedWithBackOffUntilTheDeadline) {
  ConductorOptions options = Bench::Options();
  options.request_deadline_s = 5.0;
  Bench bench(options);
  bench.Start();
  bench.Send(RobotState(std::vector<double>(7, 0.0)));
  const std::vector<Publication> requests = bench.Sent("PLAN_CHECK_REQUEST");
  ASSERT_EQ(requests.size(), 3u);
  const double sent_s = bench.clock().t_s();
  std::vector<double> retry_s;
  for (int k = 1; sent_s + k * 0.01 <= sent_s + 5.005; ++k) {
    bench.TickAt(sent_s + k * 0.01);
    if (k == 30) {  // one configuration answered between the 1st and the 2nd retry
      bench.Send(PlanReply(std::get<orbed::plan_check_request_t>(requests[0].message).request_id));
    }
    if (bench.last().empty()) continue;
    retry_s.push_back(bench.clock().t_s() - sent_s);
    const size_t expected = retry_s.size() == 1 ? 3u : 2u;
    ASSERT_EQ(bench.last().size(), expected) << "retry " << retry_s.size();
    for (size_t i = 0; i < expected; ++i) {
      EXPECT_EQ(Bytes(bench.last()[i]), Bytes(requests[i + 3 - expected])) << "retry " << retry_s.size();
    }
  }
  // Each retry at the first 10 ms tick at or after its due time.
  const std::vector<double> due_s{0.2, 0.6, 1.1, 1.6, 2.1, 2.6, 3.1, 3.6, 4.1, 4.6};
  ASSERT_EQ(retry_s.size(), due_s.size());
  for (size_t i = 0; i < due_s.size(); ++i) {
    EXPECT_GE(retry_s[i], due_s[i] - 1e-9) << i;
    EXPECT_LE(retry_s[i], due_s[i] + 0.0101 * (i + 1)) << i;
  }
  EXPECT_EQ(bench.conductor().retries(), 3 + 2 * 9);
  bench.TickAt(sent_s + 5.01);
  EXPECT_EQ(bench.conductor().results().error,
            "orbed-iiwa-sim answered 1 of 3 PLAN_CHECK_REQUESTs within 5.0 s, sent 11 times");
}

TEST(ViraalConductor, RetryOptionsAreChecked) {
  ConductorOptions options = Bench::Options();
  options.retry_initial_s = 0;
  EXPECT_THROW(Bench{options}, std::invalid_argument);
  options = Bench::Options();
  options.retry_max_s = 0.1;  // below the initial 0.2 s
  try {
    Bench bench(options);
    FAIL() << "expected a throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "--retry-max-s must be >= --retry-initial-s");
  }
}

TEST(ViraalConductor, AnInfeasibleConfigurationFailsAtOnce) {
  Bench bench;
  bench.Start();
  bench.Send(RobotState(std::vector<double>(7, 0.0)));
  orbed::plan_check_reply_t reply =
      PlanReply(std::get<orbed::plan_check_request_t>(bench.sent()[1].message).request_id);
  reply.feasible = false;
  reply.reason = "in collision: iiwa_link_7 vs patient_torso";
  bench.Send(reply);
  EXPECT_EQ(bench.conductor().status(), Status::kFailed);
  EXPECT_TRUE(
      Contains(bench.conductor().results().error,
               "configuration 1 (40.0, 20.0, -30.0, -80.0, 20.0, 50.0, 30.0) deg is infeasible in the "
               "sim's scene: in collision: iiwa_link_7 vs patient_torso"))
      << bench.conductor().results().error;
}

TEST(ViraalConductor, TheCommandIsResentUntilTheMoveTimeout) {
  Bench bench;
  bench.StartAndCheckPlans();
  const double command_s = bench.clock().t_s();
  EXPECT_EQ(bench.Labels().back(), "IIWA_COMMAND");
  EXPECT_EQ(bench.Labels()[3], "SESSION_CONTROL START");
  // The arm moves but never arrives: every tick past command_resend_s re-sends the command.
  bench.clock().Advance(0.1);
  bench.Send(RobotState(Rad({0, 10, 0, -20, 0, 15, 0}), orbed::robot_state_t::MOTION_MOVING));
  bench.TickAt(command_s + 0.24);
  EXPECT_TRUE(bench.last().empty());
  bench.TickAt(command_s + 0.26);
  ASSERT_EQ(bench.last().size(), 1u);
  EXPECT_EQ(Label(bench.last()[0]), "IIWA_COMMAND");
  EXPECT_EQ(std::get<orbed::iiwa_command_t>(bench.last()[0].message).utime, bench.clock().Now().utime);
  bench.TickAt(command_s + 0.50);
  EXPECT_TRUE(bench.last().empty());
  bench.TickAt(command_s + 0.52);
  EXPECT_EQ(bench.last().size(), 1u);
  bench.TickAt(command_s + 29.99);
  EXPECT_EQ(bench.conductor().phase(), Phase::kMove);
  bench.TickAt(command_s + 30.01);
  EXPECT_TRUE(bench.last().empty());  // failing, not re-sending
  EXPECT_EQ(bench.conductor().status(), Status::kFailed);
  EXPECT_EQ(
      bench.conductor().results().error,
      "the arm did not reach configuration (0.0, 30.0, 0.0, -60.0, 0.0, 45.0, 0.0) deg within 30.0 s (it is "
      "at (0.00, 10.00, 0.00, -20.00, 0.00, 15.00, 0.00) deg, 40.000 deg off, motion state 1): is "
      "orbed-iiwa-sim receiving IIWA_COMMAND?");
  EXPECT_EQ(bench.Sent("IIWA_COMMAND").size(), 4u);
}

// The grace runs from the first fresh stopped state (received more than 50 ms after the last
// IIWA_COMMAND). A re-send makes the states before it stale again, so the grace can only elapse
// when command_resend_s exceeds it; here 2 s.
TEST(ViraalConductor, AnArmThatStopsShortFailsAfterTheStoppedGrace) {
  ConductorOptions options = Bench::Options();
  options.command_resend_s = 2.0;
  Bench bench(options);
  bench.StartAndCheckPlans();
  const double command_s = bench.clock().t_s();
  const std::vector<double> short_q = Rad({0, 30, 0, -58, 0, 45, 0});
  const auto stopped = orbed::robot_state_t::MOTION_STOPPED_BEFORE_COLLISION;
  // A stopped state 10 ms after the command predates it: not a stop yet.
  bench.clock().Set(command_s + 0.01);
  bench.Send(RobotState(short_q, stopped, "iiwa_link_7 within 5 mm of patient_torso"));
  bench.TickAt(command_s + 1.0);
  EXPECT_EQ(bench.conductor().status(), Status::kRunning);
  // A fresh one starts the grace.
  bench.clock().Set(command_s + 1.1);
  bench.Send(RobotState(short_q, stopped, "iiwa_link_7 within 5 mm of patient_torso"));
  bench.TickAt(command_s + 1.59);
  EXPECT_EQ(bench.conductor().status(), Status::kRunning);
  bench.TickAt(command_s + 1.61);
  EXPECT_EQ(bench.conductor().status(), Status::kFailed);
  EXPECT_EQ(bench.conductor().results().error,
            "the arm stopped 2.00 deg short of configuration (0.0, 30.0, 0.0, -60.0, 0.0, 45.0, 0.0) deg: "
            "iiwa_link_7 within 5 mm of patient_torso");
}

// With the default re-send period (0.25 s) under the default grace (0.5 s), a streaming stopped
// arm is caught by the move timeout instead: each re-send makes the next 50 ms of states stale,
// which restarts the grace.
TEST(ViraalConductor, WithTheDefaultResendPeriodAStoppedArmMeetsTheMoveTimeout) {
  Bench bench;
  bench.StartAndCheckPlans();
  const double command_s = bench.clock().t_s();
  const std::vector<double> short_q = Rad({0, 30, 0, -58, 0, 45, 0});
  // ROBOT_STATE at 200 Hz and ticks at 100 Hz for 31 s, on an integer grid of 5 ms.
  for (int k = 1; k <= 6200 && bench.conductor().status() == Status::kRunning; ++k) {
    bench.clock().Set(command_s + k * 0.005);
    bench.Send(RobotState(short_q, orbed::robot_state_t::MOTION_STOPPED_AT_LIMIT, "joint 4 at its limit"));
    if (k % 2 == 0) bench.Tick();
  }
  EXPECT_EQ(bench.conductor().status(), Status::kFailed);
  EXPECT_TRUE(Contains(bench.conductor().results().error, "did not reach configuration"))
      << bench.conductor().results().error;
}

TEST(ViraalConductor, NoAlignmentTrialWithinTheTrialTimeoutNamesOrbedHmd) {
  Bench bench;
  bench.StartAndCheckPlans();
  bench.clock().Advance(0.2);
  bench.Send(RobotState(Rad(bench.conductor().options().config.configurations_deg[0])));
  EXPECT_EQ(bench.Labels().back(), "SESSION_CONTROL REQUEST_TRIAL");
  const double request_s = bench.clock().t_s();
  // Another run's trial is ignored; a trial of ours for the wrong index is refused.
  orbed::alignment_trial_t trial{};
  trial.session_id = "other-ar_reflective";
  bench.Send(trial);
  EXPECT_TRUE(bench.refusals().empty());
  trial.session_id = "emu-ar_reflective";
  trial.trial_index = 2;
  bench.Send(trial);
  ASSERT_EQ(bench.refusals().size(), 1u);
  EXPECT_EQ(bench.refusals()[0].key, "ALIGNMENT_TRIAL/unexpected");
  bench.TickAt(request_s + 59.99);
  EXPECT_EQ(bench.conductor().phase(), Phase::kAwaitTrial);
  bench.TickAt(request_s + 60.01);
  EXPECT_EQ(bench.conductor().status(), Status::kFailed);
  EXPECT_EQ(
      bench.conductor().results().error,
      "no ALIGNMENT_TRIAL for session 'emu-ar_reflective' trial 0 within 60.0 s of SESSION_CONTROL "
      "REQUEST_TRIAL, sent 2 times: is orbed-hmd running (its emulated user answers REQUEST_TRIAL on "
      "ALIGNMENT_TRIAL)? (last refused input: ALIGNMENT_TRIAL for session 'emu-ar_reflective' trial 2 was "
      "not requested now)");
  EXPECT_EQ(bench.conductor().results().sessions.size(), 1u);
}

// An ALIGNMENT_TRIAL as orbed-hmd would send it for the requested trial of `session`.
orbed::alignment_trial_t Trial(const std::string& session, int index, const std::vector<double>& q_rad,
                               const Eigen::Isometry3d& X_WV, int64_t utime, int8_t mode, int32_t mirrors) {
  orbed::alignment_trial_t t{};
  t.utime = utime;
  t.session_id = session;
  t.trial_index = index;
  t.display_mode = mode;
  t.num_mirrors = mirrors;
  t.num_joints = static_cast<int32_t>(q_rad.size());
  t.joint_position = q_rad;
  t.X_WV = ToPose(X_WV);
  t.duration_s = 12.5;
  t.user_id = "emulated";
  return t;
}

// The server's REGISTRATION (reason TRIAL) for `trial`, the first of its session.
orbed::registration_t FirstTrialRegistration(const orbed::alignment_trial_t& trial) {
  orbed::registration_t registration{};
  registration.utime = trial.utime;
  registration.session_id = trial.session_id;
  registration.reason = orbed::registration_t::REASON_TRIAL;
  registration.valid = true;
  registration.X_WV_mean = trial.X_WV;
  registration.num_trials = 1;
  registration.request_id = trial.request_id;
  return registration;
}

// The request id of the last SESSION_CONTROL `command` the bench saw.
int64_t LastControlId(const Bench& bench, int8_t command) {
  int64_t id = 0;
  for (const Publication& p : bench.Sent("SESSION_CONTROL")) {
    const auto& control = std::get<orbed::session_control_t>(p.message);
    if (control.command == command) id = control.request_id;
  }
  return id;
}

TEST(ViraalConductor, NoRegistrationOfTheTrialFailsAfterTheRequestDeadline) {
  Bench bench;
  bench.StartAndCheckPlans();
  const auto& q0 = bench.conductor().options().config.configurations_deg[0];
  bench.Send(RobotState(Rad(q0)));
  bench.clock().Advance(1.0);
  orbed::alignment_trial_t trial =
      Trial("emu-ar_reflective", 0, Rad(q0), SceneBase(), bench.clock().Now().utime,
            orbed::alignment_trial_t::MODE_AR_REFLECTIVE, 1);
  trial.request_id = LastControlId(bench, orbed::session_control_t::REQUEST_TRIAL);
  bench.Send(trial);
  ASSERT_EQ(bench.Labels().back(), "MISALIGNMENT_REQUEST");
  const double trial_s = bench.clock().t_s();
  bench.TickAt(trial_s + 59.99);
  EXPECT_EQ(bench.conductor().phase(), Phase::kAwaitTrialResults);
  bench.TickAt(trial_s + 60.01);
  EXPECT_EQ(bench.conductor().status(), Status::kFailed);
  EXPECT_EQ(bench.conductor().results().error,
            "no REGISTRATION (reason TRIAL) from orbed-registration for session 'emu-ar_reflective' trial 0 "
            "within 60.0 s, sent 2 times (is it running? did it refuse the trial? see its PROCESS_STATUS "
            "rejections)");
}

// Waiting for the trial's results, a retry re-sends the session's START and the REQUEST_TRIAL
// (so that a server or headset that missed either catches up) and the MISALIGNMENT_REQUEST, each
// only while its answer is missing; repeats of answers and answers to older requests are ignored.
TEST(ViraalConductor, ATrialIsRetriedUntilItIsReceivedAndRegistered) {
  Bench bench;
  bench.StartAndCheckPlans();
  const Publication start = bench.Sent("SESSION_CONTROL").back();
  const auto& q0 = bench.conductor().options().config.configurations_deg[0];
  bench.Send(RobotState(Rad(q0)));
  const Publication request = bench.sent().back();
  ASSERT_EQ(Label(request), "SESSION_CONTROL REQUEST_TRIAL");
  const double request_s = bench.clock().t_s();
  bench.TickAt(request_s + 0.21);
  ASSERT_EQ(bench.last().size(), 2u);
  EXPECT_EQ(Bytes(bench.last()[0]), Bytes(start));
  EXPECT_EQ(Bytes(bench.last()[1]), Bytes(request));

  orbed::alignment_trial_t trial = Trial("emu-ar_reflective", 0, Rad(q0), SceneBase(), 1234,
                                         orbed::alignment_trial_t::MODE_AR_REFLECTIVE, 1);
  trial.request_id = std::get<orbed::session_control_t>(request.message).request_id;
  bench.Send(trial);
  const Publication misalignment = bench.sent().back();
  ASSERT_EQ(Label(misalignment), "MISALIGNMENT_REQUEST");
  bench.Send(trial);  // the answer to the retry: a repeat, ignored
  EXPECT_TRUE(bench.last().empty());
  EXPECT_TRUE(bench.refusals().empty());
  const double trial_s = bench.clock().t_s();
  bench.TickAt(trial_s + 0.21);  // neither answer yet: all three again
  ASSERT_EQ(bench.last().size(), 3u);
  EXPECT_EQ(Bytes(bench.last()[2]), Bytes(misalignment));

  const auto& misalignment_request = std::get<orbed::misalignment_request_t>(misalignment.message);
  orbed::misalignment_t answer{};
  answer.utime = misalignment_request.utime;
  answer.request_id = misalignment_request.request_id;
  answer.session_id = misalignment_request.session_id;
  answer.valid = true;
  answer.num_pairs = misalignment_request.num_pairs;
  answer.error_norm_m.assign(answer.num_pairs, 0.0);
  answer.error_W_m.assign(answer.num_pairs, {0, 0, 0});
  bench.Send(answer);
  bench.TickAt(trial_s + 0.62);  // the trial's registration is still missing: START + REQUEST_TRIAL
  ASSERT_EQ(bench.last().size(), 2u);
  EXPECT_EQ(Label(bench.last()[1]), "SESSION_CONTROL REQUEST_TRIAL");

  orbed::registration_t registration = FirstTrialRegistration(trial);
  registration.request_id = trial.request_id - 1;  // another request's: ignored
  bench.Send(registration);
  EXPECT_EQ(bench.conductor().phase(), Phase::kAwaitTrialResults);
  registration.request_id = trial.request_id;
  bench.Send(registration);
  EXPECT_EQ(bench.conductor().phase(), Phase::kMove);  // trial 1 is on its way
  EXPECT_EQ(bench.conductor().results().sessions[0].trials.size(), 1u);
  bench.Send(registration);  // a late repeat changes nothing
  bench.Send(trial);
  bench.Send(answer);
  EXPECT_EQ(bench.conductor().phase(), Phase::kMove);
  EXPECT_TRUE(bench.refusals().empty());
  EXPECT_EQ(bench.conductor().results().sessions[0].trials.size(), 1u);
}

// The user's annotation of `landmarks` landmarks as the headset sends it: per landmark and side
// two rays, from (0.1 l, 0.01 side, 1.5 + k) along x (the tests answer the LANDMARK_REQUESTs).
void Annotate(orbed::alignment_trial_t* trial, int landmarks) {
  using AT = orbed::alignment_trial_t;
  for (int l = 0; l < landmarks; ++l) {
    for (int8_t side : {AT::ANNOTATION_REAL, AT::ANNOTATION_VIRTUAL}) {
      for (int k = 0; k < 2; ++k) {
        trial->annotation_landmark.push_back(l);
        trial->annotation_side.push_back(side);
        trial->annotation_origin_W_m.push_back({0.1 * l, 0.01 * side, 1.5 + k});
        trial->annotation_direction_W.push_back({1.0, 0.0, 0.0});
      }
    }
  }
  trial->num_annotation_rays = static_cast<int32_t>(trial->annotation_landmark.size());
}

// An annotated trial (the user's gaze rays, contract change 5) is scored from the landmarks that
// orbed-registration triangulates: a LANDMARK_REQUEST per landmark and side with exactly the
// trial's rays, retried while unanswered, and once all are in, the MISALIGNMENT_REQUEST of the
// answered points (real, virtual) in landmark order; the truth's misalignment stays beside it.
TEST(ViraalConductor, AnAnnotatedTrialIsScoredFromTheTriangulatedLandmarks) {
  using AT = orbed::alignment_trial_t;
  Bench bench;
  bench.StartAndCheckPlans();
  const auto& q0 = bench.conductor().options().config.configurations_deg[0];
  bench.Send(RobotState(Rad(q0)));
  const Publication request = bench.sent().back();
  AT trial = Trial("emu-ar_reflective", 0, Rad(q0), SceneBase(), 1234, AT::MODE_AR_REFLECTIVE, 1);
  trial.request_id = std::get<orbed::session_control_t>(request.message).request_id;
  Annotate(&trial, 3);
  bench.Send(trial);
  ASSERT_TRUE(bench.refusals().empty()) << bench.refusals()[0].reason;
  const std::vector<Publication> requests = bench.Sent("LANDMARK_REQUEST");
  ASSERT_EQ(requests.size(), 6u);
  EXPECT_TRUE(bench.Sent("MISALIGNMENT_REQUEST").empty());
  std::vector<orbed::landmark_request_t> sent;
  for (size_t k = 0; k < 6; ++k) {
    sent.push_back(std::get<orbed::landmark_request_t>(requests[k].message));
    const int l = static_cast<int>(k / 2);
    const bool virt = k % 2 == 1;
    EXPECT_EQ(sent[k].name,
              "emu-ar_reflective/0/" + std::string(virt ? "virtual/" : "real/") + std::to_string(l));
    ASSERT_EQ(sent[k].num_rays, 2);
    ASSERT_EQ(sent[k].origin_W_m.size(), 2u);
    ASSERT_EQ(sent[k].origin_W_m[1].size(), 3u);
    EXPECT_EQ(sent[k].origin_W_m[1][0], 0.1 * l);
    EXPECT_EQ(sent[k].origin_W_m[1][1], virt ? 0.01 : 0.0);
    EXPECT_EQ(sent[k].origin_W_m[1][2], 2.5);
  }
  // Answers: landmark l real at (l, 0, 1), virtual 3 mm further along x and 4 mm along y.
  auto answer = [&](size_t k) {
    orbed::landmark_t a{};
    a.utime = sent[k].utime;
    a.request_id = sent[k].request_id;
    a.name = sent[k].name;
    a.valid = true;
    a.p_W_m[0] = static_cast<double>(k / 2) + (k % 2 ? 0.003 : 0.0);
    a.p_W_m[1] = k % 2 ? 0.004 : 0.0;
    a.p_W_m[2] = 1.0;
    return a;
  };
  for (size_t k : {0, 2, 3, 5}) bench.Send(answer(k));
  bench.Send(answer(0));  // a repeat: ignored
  EXPECT_TRUE(bench.Sent("MISALIGNMENT_REQUEST").empty());
  const double t_s = bench.clock().t_s();
  bench.TickAt(t_s + 0.21);  // START, REQUEST_TRIAL (not registered) and the two unanswered
  std::vector<int64_t> retried;
  for (const Publication& p : bench.last()) {
    if (p.channel == "LANDMARK_REQUEST")
      retried.push_back(std::get<orbed::landmark_request_t>(p.message).request_id);
  }
  EXPECT_EQ(retried, (std::vector<int64_t>{sent[1].request_id, sent[4].request_id}));
  bench.Send(answer(1));
  bench.Send(answer(4));
  ASSERT_EQ(bench.Sent("MISALIGNMENT_REQUEST").size(), 1u);
  const auto m = std::get<orbed::misalignment_request_t>(bench.Sent("MISALIGNMENT_REQUEST")[0].message);
  ASSERT_EQ(m.num_pairs, 3);
  for (int l = 0; l < 3; ++l) {
    EXPECT_EQ(m.p_W_real_m[l], (std::vector<double>{static_cast<double>(l), 0.0, 1.0}));
    EXPECT_EQ(m.p_W_virtual_m[l], (std::vector<double>{l + 0.003, 0.004, 1.0}));
  }
  // The server's answer for those pairs: every pair 5 mm apart, (3, 4, 0) mm per axis.
  orbed::misalignment_t reply{};
  reply.utime = m.utime;
  reply.request_id = m.request_id;
  reply.session_id = m.session_id;
  reply.valid = true;
  reply.num_pairs = 3;
  reply.error_norm_m.assign(3, 0.005);
  reply.error_W_m.assign(3, {0.003, 0.004, 0});
  reply.mean_error_W_m[0] = 0.003;
  reply.mean_error_W_m[1] = 0.004;
  reply.mean_error_norm_m = 0.005;
  reply.mean_pair_distance_m = 0.005;
  bench.Send(reply);
  bench.Send(FirstTrialRegistration(trial));
  ASSERT_EQ(bench.conductor().results().sessions[0].trials.size(), 1u);
  const viraal::ErrorMeasures& e = bench.conductor().results().sessions[0].trials[0].errors;
  EXPECT_EQ(e.landmarks, "gaze");
  EXPECT_NEAR(e.misalignment_mm, 5.0, 1e-12);
  // X_WV = X_WR (SceneBase): the truth's pairs coincide.
  EXPECT_NEAR(e.truth_misalignment_mm, 0.0, 1e-9);
}

// A landmark orbed-registration cannot triangulate fails the run, naming it and the reason.
TEST(ViraalConductor, ALandmarkThatCannotBeTriangulatedFailsTheRun) {
  using AT = orbed::alignment_trial_t;
  Bench bench;
  bench.StartAndCheckPlans();
  const auto& q0 = bench.conductor().options().config.configurations_deg[0];
  bench.Send(RobotState(Rad(q0)));
  AT trial = Trial("emu-ar_reflective", 0, Rad(q0), SceneBase(), 1234, AT::MODE_AR_REFLECTIVE, 1);
  trial.request_id = LastControlId(bench, orbed::session_control_t::REQUEST_TRIAL);
  Annotate(&trial, 1);
  bench.Send(trial);
  const auto first = std::get<orbed::landmark_request_t>(bench.Sent("LANDMARK_REQUEST").at(0).message);
  orbed::landmark_t a{};
  a.request_id = first.request_id;
  a.name = first.name;
  a.valid = false;
  a.reason = "rays are near-parallel";
  bench.Send(a);
  EXPECT_EQ(bench.conductor().status(), Status::kFailed);
  EXPECT_EQ(
      bench.conductor().results().error,
      "orbed-registration could not triangulate landmark emu-ar_reflective/0/real/0: rays are near-parallel");
}

TEST(ViraalConductor, AbortEndsARunningRunOnly) {
  Bench bench;
  bench.StartAndCheckPlans();
  bench.clock().Advance(3.0);
  bench.Record(bench.conductor().Abort("interrupted before the run completed", bench.clock().Now()));
  EXPECT_EQ(bench.conductor().status(), Status::kFailed);
  EXPECT_EQ(bench.conductor().results().error, "interrupted before the run completed");
  bench.conductor().Abort("again", bench.clock().Now());
  EXPECT_EQ(bench.conductor().results().error, "interrupted before the run completed");
}

// ----------------------------------------------------------------------------------------------
// A whole run against an event-driven emulation of orbed-iiwa-sim (teleports in 0.2 s),
// orbed-hmd's user (answers REQUEST_TRIAL after 0.1 s, X_WV 10 mm along W x from the truth) and
// orbed-registration (trial registrations, the mean, the misalignment of the pairs). Like the real
// ones, the user and the server act only in a session START opened, answer a repeated request id
// with their first answer, and the server registers a repeated trial once. Ticks every 10 ms, as
// the shell does.
//
// Lossy: between the conductor and the others the first copy of every request and of every answer
// is lost (so every exchange needs the conductor's retries), every other IIWA_COMMAND is lost, and
// every answer that gets through arrives twice, the copy 5 ms later.

class Emulation {
 public:
  explicit Emulation(Bench* bench, bool lossy = false) : bench_(bench), lossy_(lossy) {}

  // Runs until the conductor is done or `until_s`.
  void Run(double until_s) {
    bench_->Start();
    const double start_s = bench_->clock().t_s();
    At(start_s + 0.05, [this] { bench_->Send(RobotState(q_)); });
    for (int k = 1; start_s + k * 0.01 <= until_s; ++k) At(start_s + k * 0.01, [this] { bench_->Tick(); });
    while (!events_.empty() && !bench_->conductor().done() && events_.begin()->first <= until_s) {
      const auto next = events_.begin();
      bench_->clock().Set(next->first);
      const std::function<void()> event = next->second;
      events_.erase(next);
      event();
      for (const Publication& p : bench_->last()) Transmit(p);
    }
  }

 private:
  void At(double t_s, std::function<void()> event) { events_.emplace(t_s, std::move(event)); }
  double Now() const { return bench_->clock().t_s(); }

  // On a lossy network the first copy of whatever `key` names is lost.
  bool Lost(const std::string& key) { return lossy_ && lost_.insert(key).second; }

  // An answer (`send`) reaches the conductor `delay_s` from now, unless lost; twice when lossy.
  void Answer(const std::string& key, double delay_s, const std::function<void()>& send) {
    if (Lost("answer " + key)) return;
    At(Now() + delay_s, send);
    if (lossy_) At(Now() + delay_s + 0.005, send);
  }

  // A publication of the conductor reaches the sim, the user and the server, unless lost.
  void Transmit(const Publication& p) {
    if (const auto* request = std::get_if<orbed::plan_check_request_t>(&p.message)) {
      const int64_t id = request->request_id;
      if (Lost("plan " + std::to_string(id))) return;
      Answer("plan " + std::to_string(id), 0.002, [this, id] { bench_->Send(PlanReply(id)); });
    } else if (const auto* command = std::get_if<orbed::iiwa_command_t>(&p.message)) {
      if (lossy_ && commands_++ % 2 == 0) return;
      const std::vector<double> target = command->joint_position;
      At(Now() + 0.005, [this] { bench_->Send(RobotState(q_, orbed::robot_state_t::MOTION_MOVING)); });
      At(Now() + 0.2, [this, target] {
        q_ = target;
        bench_->Send(RobotState(q_));
      });
    } else if (const auto* control = std::get_if<orbed::session_control_t>(&p.message)) {
      if (Lost("control " + std::to_string(control->request_id))) return;
      OnSessionControl(*control);
    } else if (const auto* request = std::get_if<orbed::misalignment_request_t>(&p.message)) {
      if (Lost("misalignment " + std::to_string(request->request_id))) return;
      Answer("misalignment " + std::to_string(request->request_id), 0.002,
             [this, m = Misalignment(*request)] { bench_->Send(m); });
    } else if (const auto* trial = std::get_if<orbed::alignment_trial_t>(&p.message)) {
      // A kept trial re-sent by a resumed conductor: the server registers it (the user's next index
      // moves past it), and the conductor hears its own message back, as on LCM.
      Register(*trial);
      At(Now() + 0.001, [this, t = *trial] { bench_->Send(t); });
    }
  }

  void OnSessionControl(const orbed::session_control_t& msg) {
    using SC = orbed::session_control_t;
    if (msg.command == SC::START) {
      if (msg.session_id != session_) {  // a repeated START changes nothing
        session_ = msg.session_id;
        registered_.clear();
      }
      return;
    }
    if (msg.session_id != session_) return;  // refused: a session neither knows
    const std::string key = std::to_string(msg.request_id);
    if (msg.command == SC::REQUEST_TRIAL) {
      if (const auto it = trials_.find(msg.request_id); it != trials_.end()) return Aligned(it->second);
      if (!aligning_.insert(msg.request_id).second) return;  // the user is at it already
      At(Now() + 0.1, [this, msg] {
        Eigen::Isometry3d X_WV = SceneBase();
        X_WV.translation() += Eigen::Vector3d(0.010, 0, 0);
        orbed::alignment_trial_t trial =
            Trial(msg.session_id, static_cast<int>(registered_.size()), q_, X_WV, bench_->clock().Now().utime,
                  msg.display_mode, msg.num_mirrors);
        trial.request_id = msg.request_id;
        trials_[msg.request_id] = trial;
        Aligned(trial);
      });
    } else if (msg.command == SC::COMPUTE) {
      Eigen::Isometry3d X_WV = SceneBase();
      X_WV.translation() += Eigen::Vector3d(0.010, 0, 0);
      orbed::registration_t mean = Registration(msg.session_id, msg.utime, ToPose(X_WV), msg.request_id);
      mean.reason = orbed::registration_t::REASON_COMPUTE;
      Answer("compute " + key, 0.003, [this, mean] { bench_->Send(mean); });
    }
  }

  // The user publishes `trial`: the conductor gets it, and the server registers it (a repeat once)
  // and answers with its registration.
  void Aligned(const orbed::alignment_trial_t& trial) {
    const std::string key = std::to_string(trial.request_id);
    Answer("trial " + key, 0.0, [this, trial] { bench_->Send(trial); });
    Answer("registration " + key, 0.003, [this, r = Register(trial)] { bench_->Send(r); });
  }

  // The server registers a trial of its session once, by index; a repeat gets the first answer.
  orbed::registration_t Register(const orbed::alignment_trial_t& trial) {
    auto it = registered_.find(trial.trial_index);
    if (it == registered_.end()) {
      it = registered_.emplace(trial.trial_index, orbed::registration_t{}).first;
      it->second = Registration(trial.session_id, trial.utime, trial.X_WV, trial.request_id);
    }
    return it->second;
  }

  orbed::registration_t Registration(const std::string& session, int64_t utime, const orbed::pose_t& X_WV,
                                     int64_t request_id) {
    orbed::registration_t r{};
    r.utime = utime;
    r.session_id = session;
    r.reason = orbed::registration_t::REASON_TRIAL;
    r.method = orbed::registration_t::METHOD_KARCHER;
    r.valid = true;
    r.X_WV_mean = X_WV;
    r.num_trials = r.num_used = static_cast<int32_t>(registered_.size());
    r.converged = r.unique = true;
    r.iterations = 4;
    r.request_id = request_id;
    return r;
  }

  // The server's Table 1 evaluation: mean |virtual − real| per W axis and its norm.
  static orbed::misalignment_t Misalignment(const orbed::misalignment_request_t& request) {
    orbed::misalignment_t m{};
    m.utime = request.utime;
    m.request_id = request.request_id;
    m.session_id = request.session_id;
    m.valid = true;
    m.num_pairs = request.num_pairs;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    double distance = 0;
    for (int k = 0; k < request.num_pairs; ++k) {
      Eigen::Vector3d d;
      for (int i = 0; i < 3; ++i) d[i] = request.p_W_virtual_m[k][i] - request.p_W_real_m[k][i];
      m.error_W_m.push_back({std::abs(d.x()), std::abs(d.y()), std::abs(d.z())});
      m.error_norm_m.push_back(d.norm());
      mean += d.cwiseAbs() / request.num_pairs;
      distance += d.norm() / request.num_pairs;
    }
    FromVector3(mean, m.mean_error_W_m);
    m.mean_error_norm_m = mean.norm();
    m.mean_pair_distance_m = distance;
    return m;
  }

  Bench* bench_;
  bool lossy_;
  std::multimap<double, std::function<void()>> events_;
  std::vector<double> q_ = std::vector<double>(7, 0.0);
  std::set<std::string> lost_;
  int commands_ = 0;
  std::string session_;                                 // opened by START (user and server)
  std::map<int64_t, orbed::alignment_trial_t> trials_;  // the user's, by request id
  std::set<int64_t> aligning_;                          // requests the user has started on
  std::map<int, orbed::registration_t> registered_;     // the server's, by trial index
};

TEST(ViraalConductor, AWholeRunInEmulatedTime) {
  Bench bench;
  Emulation(&bench).Run(200.0);
  ASSERT_EQ(bench.conductor().status(), Status::kSucceeded) << bench.conductor().results().error;

  // The actions, in order.
  std::vector<std::string> expected(3, "PLAN_CHECK_REQUEST");
  for (int mode = 0; mode < 2; ++mode) {
    expected.push_back("SESSION_CONTROL START");
    for (int i = 0; i < 3; ++i) {
      for (const char* label : {"IIWA_COMMAND", "SESSION_CONTROL REQUEST_TRIAL", "MISALIGNMENT_REQUEST"})
        expected.push_back(label);
    }
    for (const char* label : {"SESSION_CONTROL COMPUTE", "MISALIGNMENT_REQUEST", "SESSION_CONTROL STOP"})
      expected.push_back(label);
  }
  EXPECT_EQ(bench.Labels(), expected);
  EXPECT_TRUE(bench.refusals().empty());

  // What the messages carry.
  const viraal::ScenarioConfig& config = bench.conductor().options().config;
  const std::vector<Publication> commands = bench.Sent("IIWA_COMMAND");
  ASSERT_EQ(commands.size(), 6u);
  for (size_t i = 0; i < commands.size(); ++i) {
    const auto& command = std::get<orbed::iiwa_command_t>(commands[i].message);
    for (int j = 0; j < 7; ++j)
      EXPECT_NEAR(command.joint_position[j], config.configurations_deg[i % 3][j] * kDegToRad, 1e-15);
  }
  std::vector<int> pairs;
  for (const Publication& p : bench.Sent("MISALIGNMENT_REQUEST"))
    pairs.push_back(std::get<orbed::misalignment_request_t>(p.message).num_pairs);
  EXPECT_EQ(pairs, (std::vector<int>{3, 3, 3, 9, 3, 3, 3, 9}));
  for (const Publication& p : bench.Sent("SESSION_CONTROL")) {
    const auto& control = std::get<orbed::session_control_t>(p.message);
    EXPECT_TRUE(control.session_id == "emu-ar_reflective" || control.session_id == "emu-ar")
        << control.session_id;
    EXPECT_EQ(control.method, +orbed::registration_t::METHOD_KARCHER);
  }

  // The results: a pure 10 mm shift along W x is 10 mm everywhere, t̄ = (10, 0, 0) mm.
  const viraal::RunResults& r = bench.conductor().results();
  EXPECT_TRUE(r.ok);
  EXPECT_EQ(r.run_id, "emu");
  EXPECT_EQ(r.error, "");
  EXPECT_EQ(r.rejected_inputs, 0);
  EXPECT_EQ(r.started_utime, 1'700'000'100'000'000);
  // Per trial: 0.2 s to arrive, 0.1 s of user, 3 ms to register; then 5 ms for the mean; per
  // session a first 0.05 s for the robot and 2 ms for the plan checks. Every answer came before
  // its retry was due: nothing was re-sent.
  EXPECT_NEAR(r.duration_s, 0.05 + 0.002 + 2 * (3 * (0.2 + 0.1 + 0.003) + 0.003 + 0.002), 1e-6);
  EXPECT_EQ(bench.conductor().retries(), 0);
  ASSERT_EQ(r.sessions.size(), 2u);
  EXPECT_EQ(r.sessions[0].session_id, "emu-ar_reflective");
  EXPECT_EQ(r.sessions[1].session_id, "emu-ar");
  EXPECT_EQ(r.sessions[1].num_mirrors, 0);
  for (const viraal::SessionResult& s : r.sessions) {
    ASSERT_EQ(s.trials.size(), 3u);
    ASSERT_TRUE(s.mean.has_value());
    EXPECT_EQ(s.mean->num_used, 3);
    EXPECT_EQ(s.mean->iterations, 4);
    for (const viraal::ErrorMeasures& e :
         {s.trials[0].errors, s.trials[1].errors, s.trials[2].errors, s.mean->errors}) {
      EXPECT_NEAR(e.translation_error_mm, 10.0, 1e-9);
      EXPECT_NEAR(e.flange_translation_error_mm, 10.0, 1e-9);
      EXPECT_NEAR(e.rotation_error_deg, 0.0, 1e-6);
      EXPECT_NEAR(e.misalignment_mm, 10.0, 1e-9);
      EXPECT_NEAR((e.misalignment_axes_mm - Eigen::Vector3d(10, 0, 0)).norm(), 0.0, 1e-9);
    }
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(s.trials[i].index, i);
      EXPECT_EQ(s.trials[i].user_duration_s, 12.5);
      EXPECT_EQ(s.trials[i].user_id, "emulated");
      for (int j = 0; j < 7; ++j) EXPECT_NEAR(s.trials[i].q_deg[j], config.configurations_deg[i][j], 1e-9);
    }
  }
  EXPECT_TRUE(Contains(viraal::ResultsJson(r), "\"status\": \"ok\""));

  // The operator's lines.
  const std::vector<std::string>& lines = bench.lines();
  ASSERT_EQ(lines.size(), 1u + 1u + 2 * (1 + 3 + 1));
  EXPECT_EQ(lines[1],
            "[plan] 3 configurations checked with orbed-iiwa-sim: within limits and collision-free");
  EXPECT_EQ(lines[2], "[ar_reflective] session emu-ar_reflective started: 3 trials, 1 reflective display(s)");
  EXPECT_EQ(
      lines[3],
      "[1/6] ar_reflective trial 0: robot at q=(0.0, 30.0, 0.0, -60.0, 0.0, 45.0, 0.0) deg (reached in 0.2 "
      "s); aligned in 12.5 s of user time: 10.0 mm, 0.00 deg, misalignment 10.0 mm");
  EXPECT_EQ(lines[6],
            "[ar_reflective] mean of 3 trials (SE(3), converged): 10.0 mm, 0.00 deg, misalignment 10.0 mm");
}

// Resuming: a run stopped after some trials, resumed from its results with the sessions it kept
// (resume.h), ends with the results of the run that was never stopped, having re-sent the kept
// trials and run only the rest.
TEST(ViraalConductor, AResumedRunRunsOnlyWhatWasLeftAndEndsWithTheSameResults) {
  Bench uninterrupted;
  Emulation(&uninterrupted).Run(200.0);
  ASSERT_EQ(uninterrupted.conductor().status(), Status::kSucceeded);
  const viraal::RunResults& expected = uninterrupted.conductor().results();

  // Stopped in session 0 after 2 trials, and in session 1 after 1 trial (session 0 with its mean).
  const double one_trial_s = 0.2 + 0.1 + 0.003;
  for (const double stop_after_s :
       {0.052 + 2 * one_trial_s + 0.1, 0.052 + 3 * one_trial_s + 0.005 + one_trial_s + 0.1}) {
    Bench stopped;
    Emulation(&stopped).Run(100.0 + stop_after_s);
    ASSERT_EQ(stopped.conductor().status(), Status::kRunning);
    ConductorOptions options = Bench::Options();
    options.kept_sessions = KeptSessions(stopped.conductor().results(), "emu", 0, options.config);
    options.resumed_from = "/runs/1/results.json";
    const size_t kept_sessions = options.kept_sessions.size();
    const size_t kept_trials = options.kept_sessions.back().trials.size();
    Bench resumed(options);
    Emulation(&resumed).Run(200.0);
    ASSERT_EQ(resumed.conductor().status(), Status::kSucceeded) << resumed.conductor().results().error;
    EXPECT_TRUE(resumed.refusals().empty());

    // START, the kept trials re-sent, then only the trials that were left.
    std::vector<std::string> labels(3, "PLAN_CHECK_REQUEST");
    labels.push_back("SESSION_CONTROL START");
    for (size_t i = 0; i < kept_trials; ++i) labels.push_back("ALIGNMENT_TRIAL");
    for (size_t mode = kept_sessions - 1; mode < 2; ++mode) {
      if (mode == kept_sessions) labels.push_back("SESSION_CONTROL START");
      for (size_t i = mode == kept_sessions - 1 ? kept_trials : 0; i < 3; ++i) {
        for (const char* label : {"IIWA_COMMAND", "SESSION_CONTROL REQUEST_TRIAL", "MISALIGNMENT_REQUEST"})
          labels.push_back(label);
      }
      for (const char* label : {"SESSION_CONTROL COMPUTE", "MISALIGNMENT_REQUEST", "SESSION_CONTROL STOP"})
        labels.push_back(label);
    }
    EXPECT_EQ(resumed.Labels(), labels);
    const std::vector<Publication> resent = resumed.Sent("ALIGNMENT_TRIAL");
    for (size_t i = 0; i < resent.size(); ++i) {
      const auto& trial = std::get<orbed::alignment_trial_t>(resent[i].message);
      EXPECT_EQ(trial.session_id, options.kept_sessions.back().session_id);
      EXPECT_EQ(trial.trial_index, static_cast<int>(i));
    }

    const viraal::RunResults& got = resumed.conductor().results();
    EXPECT_EQ(got.resumed_from, "/runs/1/results.json");
    ASSERT_EQ(got.sessions.size(), expected.sessions.size());
    for (size_t m = 0; m < got.sessions.size(); ++m) {
      ASSERT_EQ(got.sessions[m].trials.size(), 3u);
      ASSERT_TRUE(got.sessions[m].mean.has_value());
      const auto same = [&](const viraal::ErrorMeasures& a, const viraal::ErrorMeasures& b,
                            const std::string& what) {
        EXPECT_NEAR(a.translation_error_mm, b.translation_error_mm, 1e-9) << what;
        EXPECT_NEAR(a.misalignment_mm, b.misalignment_mm, 1e-9) << what;
        EXPECT_NEAR(a.misalignment_mean_pair_distance_mm, b.misalignment_mean_pair_distance_mm, 1e-9) << what;
      };
      for (size_t i = 0; i < 3; ++i) {
        same(got.sessions[m].trials[i].errors, expected.sessions[m].trials[i].errors,
             "session " + std::to_string(m) + " trial " + std::to_string(i));
      }
      same(got.sessions[m].mean->errors, expected.sessions[m].mean->errors, "mean " + std::to_string(m));
    }
  }
}

TEST(ViraalConductor, AResumedSessionWithAllItsTrialsAsksForItsMeanAtOnce) {
  Bench stopped;
  Emulation(&stopped).Run(100.0 + 0.052 + 3 * (0.2 + 0.1 + 0.003) + 0.001);  // before the mean
  ASSERT_EQ(stopped.conductor().results().sessions[0].trials.size(), 3u);
  ConductorOptions options = Bench::Options();
  options.kept_sessions = KeptSessions(stopped.conductor().results(), "emu", 0, options.config);
  // The kept trials carry the real landmarks their user annotated (results.json's
  // annotated_real_W_m): the mean is measured against them, trial by trial, in order.
  std::vector<std::vector<double>> annotated;
  for (size_t i = 0; i < options.kept_sessions[0].trials.size(); ++i) {
    auto& kept = options.kept_sessions[0].trials[i].annotated_real_W_m;
    for (int l = 0; l < 3; ++l) {
      kept.emplace_back(0.1 * static_cast<double>(i), 0.01 * l, 1.0);
      annotated.push_back({0.1 * static_cast<double>(i), 0.01 * l, 1.0});
    }
  }
  Bench resumed(options);
  resumed.Start();
  resumed.Send(RobotState(std::vector<double>(7, 0.0)));
  for (const Publication& p : resumed.Sent("PLAN_CHECK_REQUEST")) {
    resumed.Send(PlanReply(std::get<orbed::plan_check_request_t>(p.message).request_id));
  }
  const std::vector<std::string> labels = resumed.Labels();
  EXPECT_EQ(std::vector<std::string>(labels.begin() + 3, labels.end()),
            (std::vector<std::string>{"SESSION_CONTROL START", "ALIGNMENT_TRIAL", "ALIGNMENT_TRIAL",
                                      "ALIGNMENT_TRIAL", "SESSION_CONTROL COMPUTE"}));
  EXPECT_EQ(resumed.conductor().phase(), Phase::kAwaitMean);
  const auto compute = std::get<orbed::session_control_t>(resumed.sent().back().message);
  orbed::registration_t mean{};
  mean.utime = compute.utime;
  mean.session_id = compute.session_id;
  mean.reason = orbed::registration_t::REASON_COMPUTE;
  mean.method = orbed::registration_t::METHOD_KARCHER;
  mean.valid = true;
  mean.X_WV_mean = ToPose(SceneBase());
  mean.num_trials = mean.num_used = 3;
  mean.request_id = compute.request_id;
  resumed.Send(mean);
  ASSERT_EQ(resumed.Sent("MISALIGNMENT_REQUEST").size(), 1u);
  const auto request =
      std::get<orbed::misalignment_request_t>(resumed.Sent("MISALIGNMENT_REQUEST")[0].message);
  EXPECT_EQ(request.p_W_real_m, annotated);
}

// The request id a publication carries (STOP and IIWA_COMMAND, which are not retried: none).
std::optional<int64_t> RetriedRequestId(const Publication& p) {
  if (const auto* m = std::get_if<orbed::plan_check_request_t>(&p.message)) return m->request_id;
  if (const auto* m = std::get_if<orbed::misalignment_request_t>(&p.message)) return m->request_id;
  if (const auto* m = std::get_if<orbed::session_control_t>(&p.message)) {
    if (m->command != orbed::session_control_t::STOP) return m->request_id;
  }
  return std::nullopt;
}

// Every exchange loses its first request and its first answer, and every answer arrives twice: the
// retries carry the run through, every request is re-sent byte for byte, no duplicate is refused,
// and the results are those of the lossless run.
TEST(ViraalConductor, AWholeRunOverALossyNetworkHasTheLosslessResults) {
  Bench clean;
  Emulation(&clean).Run(200.0);
  ASSERT_EQ(clean.conductor().status(), Status::kSucceeded) << clean.conductor().results().error;
  Bench lossy;
  Emulation(&lossy, true).Run(400.0);
  ASSERT_EQ(lossy.conductor().status(), Status::kSucceeded) << lossy.conductor().results().error;
  EXPECT_TRUE(lossy.refusals().empty());

  std::map<int64_t, std::vector<Publication>> by_id;
  for (const Publication& p : lossy.sent()) {
    if (const auto id = RetriedRequestId(p)) by_id[*id].push_back(p);
  }
  EXPECT_EQ(by_id.size(), 3u + 2 * (1 + 3 * 2 + 2));  // plans; per session START, trials, COMPUTE, mean
  for (const auto& [id, copies] : by_id) {
    EXPECT_GE(copies.size(), 2u) << Label(copies[0]) << " " << id;
    for (const Publication& copy : copies) EXPECT_EQ(Bytes(copy), Bytes(copies[0])) << Label(copies[0]);
  }
  EXPECT_GE(lossy.conductor().retries(), static_cast<int64_t>(by_id.size()));

  viraal::RunResults a = clean.conductor().results(), b = lossy.conductor().results();
  EXPECT_GT(b.duration_s, a.duration_s);
  a.duration_s = b.duration_s = 0;
  EXPECT_EQ(viraal::ResultsJson(a), viraal::ResultsJson(b));
}

}  // namespace
}  // namespace orbed::scenario
