// The registration server's message logic (RegistrationService, no bus) and the process on
// memq:// (in-process LCM). Oracles: hand-computable means of trials on one axis, hand-computed
// landmark and misalignment values, byte equality of replayed outputs.
#include "procs/registration_server/registration_server_cli.h"
#include "procs/registration_server/registration_server_process.h"

#include <cmath>
#include <map>
#include <vector>

#include <gtest/gtest.h>

#include "base/source_paths.h"
#include "base/test_command.h"
#include "base/units.h"
#include "geometry/test_rotations.h"
#include "lcmtypes/contract/conversions.h"

namespace orbed::registration {
namespace {

orbed::session_control_t Control(int8_t command, const std::string& id, int64_t utime,
                                 int8_t method = orbed::registration_t::METHOD_KARCHER) {
  orbed::session_control_t msg{};
  msg.utime = utime;
  msg.session_id = id;
  msg.command = command;
  msg.display_mode = orbed::alignment_trial_t::MODE_AR_REFLECTIVE;
  msg.num_mirrors = 1;
  msg.method = method;
  return msg;
}

orbed::alignment_trial_t Trial(const std::string& id, int index, double angle_about_z_rad,
                               const Eigen::Vector3d& p, int64_t utime) {
  orbed::alignment_trial_t msg{};
  msg.utime = utime;
  msg.session_id = id;
  msg.trial_index = index;
  msg.display_mode = orbed::alignment_trial_t::MODE_AR_REFLECTIVE;
  msg.num_mirrors = 1;
  msg.num_joints = 7;
  msg.joint_position.assign(7, 0.1);
  Eigen::Isometry3d X_WV = Eigen::Isometry3d::Identity();
  X_WV.linear() = Eigen::AngleAxisd(angle_about_z_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X_WV.translation() = p;
  msg.X_WV = ToPose(X_WV);
  msg.duration_s = 12.5;
  msg.user_id = "emulated-1";
  return msg;
}

template <class Msg>
std::vector<uint8_t> Bytes(const Msg& msg) {
  std::vector<uint8_t> bytes(msg.getEncodedSize());
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

struct Fixture {
  std::map<std::string, int> rejections;
  std::vector<std::string> reasons;
  RegistrationService service{RegistrationServiceOptions{},
                              [this](const std::string& key, const std::string& reason) {
                                ++rejections[key];
                                reasons.push_back(reason);
                              }};
};

TEST(RegistrationServiceTest, ThreeTrialsGiveTheClosedFormMean) {
  Fixture f;
  EXPECT_FALSE(f.service.HandleSessionControl(Control(orbed::session_control_t::START, "s1", 100)));
  std::optional<orbed::registration_t> state;
  const double angles_deg[3] = {10, 20, 45};
  for (int i = 0; i < 3; ++i) {
    state = f.service.HandleTrial(
        Trial("s1", i, angles_deg[i] * kDegToRad, Eigen::Vector3d(i + 1.0, -1.0, 0.5), 1000 + i));
    ASSERT_TRUE(state.has_value());
    EXPECT_EQ(state->num_trials, i + 1);
    EXPECT_EQ(state->utime, 1000 + i);
    EXPECT_EQ(state->reason, int{orbed::registration_t::REASON_TRIAL});
  }
  EXPECT_TRUE(state->valid);
  EXPECT_EQ(state->session_id, "s1");
  EXPECT_EQ(state->num_used, 3);
  EXPECT_EQ(state->num_rejected, 0);
  EXPECT_TRUE(state->converged);
  EXPECT_TRUE(state->unique);
  // On one axis the Karcher mean is the mean angle, 25°; translations average to (2, −1, 0.5).
  const Eigen::Quaterniond q_mean = QuaternionFromWxyz(state->X_WV_mean.quaternion_wxyz);
  EXPECT_NEAR(Eigen::AngleAxisd(q_mean.conjugate() * Eigen::Quaterniond(Eigen::AngleAxisd(
                                                         25 * kDegToRad, Eigen::Vector3d::UnitZ())))
                  .angle(),
              0.0, 1e-12);
  EXPECT_NEAR(state->X_WV_mean.position_m[0], 2.0, 1e-15);
  EXPECT_NEAR(state->X_WV_mean.position_m[1], -1.0, 1e-15);
  EXPECT_NEAR(state->X_WV_mean.position_m[2], 0.5, 1e-15);
  EXPECT_NEAR(state->rotation_max_deg, 20.0, 1e-9);
  EXPECT_NEAR(state->rotation_median_deg, 15.0, 1e-9);
  EXPECT_NEAR(state->rotation_covariance_rad2[2][2],
              (std::pow(15 * kDegToRad, 2) + std::pow(5 * kDegToRad, 2) + std::pow(20 * kDegToRad, 2)) / 3,
              1e-12);
  EXPECT_NEAR(state->translation_rms_m, std::sqrt(2.0 / 3.0), 1e-15);
  EXPECT_TRUE(f.rejections.empty());

  // COMPUTE answers with the command's utime; the periodic state carries the last input's.
  const auto computed =
      f.service.HandleSessionControl(Control(orbed::session_control_t::COMPUTE, "s1", 5000));
  ASSERT_TRUE(computed.has_value());
  EXPECT_EQ(computed->utime, 5000);
  EXPECT_EQ(computed->reason, int{orbed::registration_t::REASON_COMPUTE});
  EXPECT_EQ(f.service.PeriodicState()->utime, 1002);
  EXPECT_EQ(Bytes(*f.service.PeriodicState()).size(), Bytes(*state).size());
}

// Retries and duplicated datagrams: a command id acted on is answered with its first answer and
// changes nothing; a trial the session holds is registered once, its repeat answered with its
// REGISTRATION again (the latest trial) or ignored (an older one). None of it is a rejection.
TEST(RegistrationServiceTest, RepeatsAreAnsweredAsTheFirstTimeAndChangeNothing) {
  Fixture f;
  auto start = Control(orbed::session_control_t::START, "s1", 100);
  start.request_id = 11;
  f.service.HandleSessionControl(start);
  auto trial0 = Trial("s1", 0, 0.1, Eigen::Vector3d(1, 0, 0), 1000);
  trial0.request_id = 21;
  auto trial1 = Trial("s1", 1, 0.3, Eigen::Vector3d(3, 0, 0), 1001);
  trial1.request_id = 22;
  const auto first = f.service.HandleTrial(trial0);
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->request_id, 21);  // echoes the trial's request
  const auto repeat = f.service.HandleTrial(trial0);
  ASSERT_TRUE(repeat.has_value());
  EXPECT_EQ(Bytes(*repeat), Bytes(*first));
  const auto second = f.service.HandleTrial(trial1);
  ASSERT_TRUE(second.has_value());
  EXPECT_EQ(second->num_trials, 2);
  EXPECT_FALSE(f.service.HandleTrial(trial0).has_value());  // an older trial's late repeat: ignored
  EXPECT_EQ(Bytes(*f.service.HandleTrial(trial1)), Bytes(*second));
  EXPECT_EQ(f.service.num_trials(), 2);
  // A retried START of the session keeps its trials.
  f.service.HandleSessionControl(start);
  EXPECT_EQ(f.service.num_trials(), 2);
  // COMPUTE answered once, its repeat with the same bytes even after the state moved on.
  auto compute = Control(orbed::session_control_t::COMPUTE, "s1", 5000);
  compute.request_id = 31;
  const auto mean = f.service.HandleSessionControl(compute);
  ASSERT_TRUE(mean.has_value());
  EXPECT_EQ(mean->request_id, 31);
  EXPECT_EQ(mean->num_trials, 2);
  auto trial2 = Trial("s1", 2, 0.2, Eigen::Vector3d(2, 0, 0), 1002);
  trial2.request_id = 23;
  ASSERT_TRUE(f.service.HandleTrial(trial2).has_value());
  EXPECT_EQ(Bytes(*f.service.HandleSessionControl(compute)), Bytes(*mean));
  // A late START of this session, after another one started, is not a new START.
  auto other = Control(orbed::session_control_t::START, "s2", 6000);
  other.request_id = 12;
  f.service.HandleSessionControl(other);
  f.service.HandleSessionControl(start);
  EXPECT_EQ(f.service.session_id(), "s2");
  // The periodic state answers no request.
  EXPECT_EQ(f.service.PeriodicState()->request_id, 0);
  // The same index with other content is not a repeat: refused as before.
  f.service.HandleSessionControl(Control(orbed::session_control_t::START, "s3", 7000));
  auto trial = Trial("s3", 0, 0.1, Eigen::Vector3d(1, 0, 0), 7001);
  ASSERT_TRUE(f.service.HandleTrial(trial).has_value());
  trial.X_WV.position_m[0] = 1.5;
  EXPECT_FALSE(f.service.HandleTrial(trial).has_value());
  EXPECT_EQ(f.rejections, (std::map<std::string, int>{{"ALIGNMENT_TRIAL/trial_index", 1}}));
}

TEST(RegistrationServiceTest, BadTrialsAndCommandsAreRejectedCountedAndChangeNothing) {
  Fixture f;
  EXPECT_FALSE(f.service.PeriodicState().has_value());
  EXPECT_FALSE(f.service.HandleTrial(Trial("s1", 0, 0, Eigen::Vector3d::Zero(), 1)));  // no session
  f.service.HandleSessionControl(Control(orbed::session_control_t::START, "s1", 2));
  EXPECT_TRUE(f.service.HandleTrial(Trial("s1", 0, 0, Eigen::Vector3d::Zero(), 3)));
  EXPECT_FALSE(f.service.HandleTrial(Trial("other", 1, 0, Eigen::Vector3d::Zero(), 4)));  // wrong session
  EXPECT_FALSE(f.service.HandleTrial(Trial("s1", 0, 0, Eigen::Vector3d::Zero(), 5)));     // duplicate index
  auto non_unit = Trial("s1", 2, 0, Eigen::Vector3d::Zero(), 6);
  non_unit.X_WV.quaternion_wxyz[0] = 0.5;
  EXPECT_FALSE(f.service.HandleTrial(non_unit));
  auto nan_position = Trial("s1", 3, 0, Eigen::Vector3d::Zero(), 7);
  nan_position.X_WV.position_m[1] = std::nan("");
  EXPECT_FALSE(f.service.HandleTrial(nan_position));
  auto wrong_mode = Trial("s1", 4, 0, Eigen::Vector3d::Zero(), 8);
  wrong_mode.display_mode = orbed::alignment_trial_t::MODE_AR;  // a valid AR trial, in a reflective session
  wrong_mode.num_mirrors = 0;
  EXPECT_FALSE(f.service.HandleTrial(wrong_mode));
  auto bad_joints = Trial("s1", 5, 0, Eigen::Vector3d::Zero(), 9);
  bad_joints.joint_position[3] = INFINITY;
  EXPECT_FALSE(f.service.HandleTrial(bad_joints));
  // Finite but absurd: 1e300 m would overflow the covariance sums.
  EXPECT_FALSE(f.service.HandleTrial(Trial("s1", 6, 0, Eigen::Vector3d(1e300, 0, 0), 9)));
  auto bad_control = Control(orbed::session_control_t::START, "s2", 10);
  bad_control.method = 9;
  EXPECT_FALSE(f.service.HandleSessionControl(bad_control));
  EXPECT_FALSE(f.service.HandleSessionControl(Control(orbed::session_control_t::COMPUTE, "nope", 11)));

  EXPECT_EQ(f.service.num_trials(), 1);
  EXPECT_EQ(f.service.session_id(), "s1");
  EXPECT_EQ(f.rejections["ALIGNMENT_TRIAL/session"], 2);
  EXPECT_EQ(f.rejections["ALIGNMENT_TRIAL/trial_index"], 1);
  // The message's contract (lcmtypes/contract/alignment_trial.h), by field; then the session's rules.
  EXPECT_EQ(f.rejections["ALIGNMENT_TRIAL/X_WV"], 3);
  EXPECT_EQ(f.rejections["ALIGNMENT_TRIAL/joint_position"], 1);
  EXPECT_EQ(f.rejections["ALIGNMENT_TRIAL/session_mode"], 1);
  EXPECT_EQ(f.rejections["SESSION_CONTROL/method"], 1);
  EXPECT_EQ(f.rejections["SESSION_CONTROL/session"], 1);
  for (const auto& reason : f.reasons) EXPECT_FALSE(reason.empty());
}

// Rays from 1e308 m would overflow the normal equations into a NaN point marked valid.
TEST(RegistrationServiceTest, HugeLandmarkCoordinatesAreRejected) {
  Fixture f;
  orbed::landmark_request_t request{};
  request.num_rays = 2;
  request.origin_W_m = {{1e308, 0, 0}, {0, 1e308, 0}};
  request.direction_W = {{0, 1, 0}, {1, 0, 0}};
  const orbed::landmark_t out = f.service.HandleLandmarkRequest(request);
  EXPECT_FALSE(out.valid);
  EXPECT_NE(out.reason.find("expected |x| <= "), std::string::npos) << out.reason;
  EXPECT_EQ(f.rejections["LANDMARK_REQUEST/invalid"], 1);
}

TEST(RegistrationServiceTest, ResetStopAndRestart) {
  Fixture f;
  f.service.HandleSessionControl(Control(orbed::session_control_t::START, "s1", 1));
  f.service.HandleTrial(Trial("s1", 0, 0, Eigen::Vector3d::Zero(), 2));
  f.service.HandleSessionControl(Control(orbed::session_control_t::RESET, "s1", 3));
  EXPECT_EQ(f.service.num_trials(), 0);
  const auto empty = f.service.PeriodicState();
  ASSERT_TRUE(empty.has_value());
  EXPECT_FALSE(empty->valid);
  EXPECT_EQ(empty->utime, 3);
  f.service.HandleTrial(Trial("s1", 0, 0.1, Eigen::Vector3d::Zero(), 4));
  f.service.HandleSessionControl(Control(orbed::session_control_t::STOP, "s1", 5));
  EXPECT_FALSE(f.service.HandleTrial(Trial("s1", 1, 0, Eigen::Vector3d::Zero(), 6)));
  EXPECT_TRUE(f.service.PeriodicState()->valid);  // the stopped session's state stays available
  f.service.HandleSessionControl(Control(orbed::session_control_t::START, "s2", 7));
  EXPECT_EQ(f.service.num_trials(), 0);
  EXPECT_TRUE(f.service.session_active());
}

// The contract shared with the headset (lcmtypes/contract/session_control.h): a repeated START of the
// active session keeps its trials; a START with mirrors in AR mode is refused by the same rule.
TEST(RegistrationServiceTest, RepeatedStartKeepsTrialsAndMirrorsFollowTheMode) {
  Fixture f;
  f.service.HandleSessionControl(Control(orbed::session_control_t::START, "s1", 1));
  f.service.HandleTrial(Trial("s1", 0, 0, Eigen::Vector3d::Zero(), 2));
  f.service.HandleSessionControl(Control(orbed::session_control_t::START, "s1", 3));
  EXPECT_EQ(f.service.num_trials(), 1);
  auto ar_with_mirror = Control(orbed::session_control_t::START, "s2", 4);
  ar_with_mirror.display_mode = orbed::alignment_trial_t::MODE_AR;
  f.service.HandleSessionControl(ar_with_mirror);
  EXPECT_EQ(f.rejections["SESSION_CONTROL/num_mirrors"], 1);
  EXPECT_EQ(f.service.session_id(), "s1");
  EXPECT_EQ(f.service.num_trials(), 1);
  // The same id with another mode is a new session: its trials start over.
  auto reflective_two = Control(orbed::session_control_t::START, "s1", 5);
  reflective_two.num_mirrors = 2;
  f.service.HandleSessionControl(reflective_two);
  EXPECT_EQ(f.service.num_trials(), 0);
}

TEST(RegistrationServiceTest, RobustSessionReportsTheRejectedTrialIndex) {
  Fixture f;
  f.service.HandleSessionControl(
      Control(orbed::session_control_t::START, "r", 1, orbed::registration_t::METHOD_ROBUST));
  std::optional<orbed::registration_t> state;
  const double offsets_deg[6] = {-0.4, 0.3, 0.0, 0.2, -0.1, 120.0};
  for (int i = 0; i < 6; ++i) {
    state = f.service.HandleTrial(
        Trial("r", 10 + i, (30 + offsets_deg[i]) * kDegToRad, Eigen::Vector3d(1, 1, 1), 100 + i));
  }
  ASSERT_TRUE(state && state->valid);
  EXPECT_EQ(state->method, int{orbed::registration_t::METHOD_ROBUST});
  EXPECT_EQ(state->num_used, 5);
  ASSERT_EQ(state->num_rejected, 1);
  EXPECT_EQ(state->rejected_indices, std::vector<int32_t>{15});
  const Eigen::Quaterniond q_mean = QuaternionFromWxyz(state->X_WV_mean.quaternion_wxyz);
  EXPECT_NEAR(2.0 * std::atan2(q_mean.z(), q_mean.w()) / kDegToRad, 30.0, 1e-9);  // mean of the offsets is 0
}

TEST(RegistrationServiceTest, LandmarkAndMisalignmentRequests) {
  Fixture f;
  orbed::landmark_request_t request{};
  request.utime = 42;
  request.request_id = 7;
  request.name = "real/flange_edge";
  request.num_rays = 2;
  const Eigen::Vector3d p_WX(0.2, 0.3, 1.0);
  for (const Eigen::Vector3d& h : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0)}) {
    const Eigen::Vector3d u = (p_WX - h).normalized();
    request.origin_W_m.push_back({h.x(), h.y(), h.z()});
    request.direction_W.push_back({u.x(), u.y(), u.z()});
  }
  orbed::landmark_t landmark = f.service.HandleLandmarkRequest(request);
  EXPECT_TRUE(landmark.valid) << landmark.reason;
  EXPECT_EQ(landmark.utime, 42);
  EXPECT_EQ(landmark.request_id, 7);
  EXPECT_EQ(landmark.name, "real/flange_edge");
  EXPECT_NEAR(landmark.p_W_m[0], 0.2, 1e-12);
  EXPECT_NEAR(landmark.p_W_m[1], 0.3, 1e-12);
  EXPECT_NEAR(landmark.p_W_m[2], 1.0, 1e-12);
  EXPECT_LT(landmark.gap_m, 1e-12);

  request.direction_W[1] = request.direction_W[0];
  landmark = f.service.HandleLandmarkRequest(request);
  EXPECT_FALSE(landmark.valid);
  EXPECT_NE(landmark.reason.find("parallel"), std::string::npos);
  EXPECT_EQ(f.rejections["LANDMARK_REQUEST/invalid"], 1);

  orbed::misalignment_request_t pairs{};
  pairs.utime = 43;
  pairs.request_id = 8;
  pairs.session_id = "s1";
  pairs.num_pairs = 2;
  pairs.p_W_real_m = {{0, 0, 0}, {1, 1, 1}};
  pairs.p_W_virtual_m = {{0.003, -0.004, 0}, {1.006, 1.008, 1}};
  const orbed::misalignment_t m = f.service.HandleMisalignmentRequest(pairs);
  ASSERT_TRUE(m.valid) << m.reason;
  EXPECT_EQ(m.num_pairs, 2);
  EXPECT_NEAR(m.error_norm_m[0], 0.005, 1e-15);
  EXPECT_NEAR(m.mean_error_W_m[0], 0.0045, 1e-15);
  EXPECT_NEAR(m.mean_error_norm_m, 0.0075, 1e-15);
  EXPECT_NEAR(m.mean_pair_distance_m, 0.0075, 1e-15);
  EXPECT_EQ(Bytes(m).size(), static_cast<size_t>(m.getEncodedSize()));

  pairs.num_pairs = 0;
  pairs.p_W_real_m.clear();
  pairs.p_W_virtual_m.clear();
  const orbed::misalignment_t empty = f.service.HandleMisalignmentRequest(pairs);
  EXPECT_FALSE(empty.valid);
  EXPECT_FALSE(Bytes(empty).empty());  // encodable with no pairs
}

// The same inputs twice into fresh services give the same REGISTRATION bytes.
TEST(RegistrationServiceTest, ReplayIsBitIdentical) {
  auto run = [] {
    Fixture f;
    std::vector<std::vector<uint8_t>> out;
    f.service.HandleSessionControl(
        Control(orbed::session_control_t::START, "replay", 1, orbed::registration_t::METHOD_ROBUST));
    for (int i = 0; i < 8; ++i) {
      const double angle = (i == 5 ? 100.0 : 3.0 * std::sin(i)) * kDegToRad;
      if (auto s =
              f.service.HandleTrial(Trial("replay", i, angle, Eigen::Vector3d(0.01 * i, 0, 1), 10 + i))) {
        out.push_back(Bytes(*s));
      }
    }
    out.push_back(
        Bytes(*f.service.HandleSessionControl(Control(orbed::session_control_t::COMPUTE, "replay", 99))));
    out.push_back(Bytes(*f.service.PeriodicState()));
    return out;
  };
  const auto first = run();
  const auto second = run();
  ASSERT_EQ(first.size(), 10u);
  EXPECT_EQ(first, second);
}

// The process on memq://: a session and three trials in, REGISTRATION out (per trial and periodic).
TEST(RegistrationServerTest, ServesOverInProcessLcm) {
  orbed::CommonFlags flags("orbed-registration-test");
  flags.lcm_url = "memq://";
  flags.duration_s = 0.35;
  RegistrationServerOptions options;
  options.state_period_s = 0.1;
  RegistrationServer server(flags, options);

  struct Collector {
    std::vector<orbed::registration_t> states;
    std::vector<orbed::landmark_t> landmarks;
    void OnState(const lcm::ReceiveBuffer*, const std::string&, const orbed::registration_t* msg) {
      states.push_back(*msg);
    }
    void OnLandmark(const lcm::ReceiveBuffer*, const std::string&, const orbed::landmark_t* msg) {
      landmarks.push_back(*msg);
    }
  } collector;
  server.lcm().subscribe(channels::kRegistration, &Collector::OnState, &collector);
  server.lcm().subscribe(channels::kLandmark, &Collector::OnLandmark, &collector);

  auto start = Control(orbed::session_control_t::START, "live", 1);
  server.lcm().publish(channels::kSessionControl, &start);
  for (int i = 0; i < 3; ++i) {
    auto trial = Trial("live", i, (10.0 * i) * kDegToRad, Eigen::Vector3d(0, 0, i), 10 + i);
    server.lcm().publish(channels::kAlignmentTrial, &trial);
  }
  orbed::landmark_request_t request{};
  request.utime = 50;
  request.num_rays = 1;
  request.origin_W_m = {{0, 0, 0}};
  request.direction_W = {{0, 0, 1}};
  server.lcm().publish(channels::kLandmarkRequest, &request);
  const char garbage[] = "not a message";
  server.lcm().publish(channels::kAlignmentTrial, garbage, sizeof(garbage));

  EXPECT_EQ(server.Run(), 0);

  std::vector<orbed::registration_t> per_trial, periodic;
  for (const auto& s : collector.states) {
    (s.reason == orbed::registration_t::REASON_TRIAL ? per_trial : periodic).push_back(s);
  }
  ASSERT_EQ(per_trial.size(), 3u);
  EXPECT_EQ(per_trial[2].num_trials, 3);
  EXPECT_TRUE(per_trial[2].valid);
  const Eigen::Quaterniond q_mean = QuaternionFromWxyz(per_trial[2].X_WV_mean.quaternion_wxyz);
  EXPECT_NEAR(2.0 * std::atan2(q_mean.z(), q_mean.w()) / kDegToRad, 10.0, 1e-9);
  EXPECT_NEAR(per_trial[2].X_WV_mean.position_m[2], 1.0, 1e-15);
  EXPECT_GE(periodic.size(), 1u);
  for (const auto& s : periodic) EXPECT_EQ(s.utime, 12);
  ASSERT_EQ(collector.landmarks.size(), 1u);
  EXPECT_FALSE(collector.landmarks[0].valid);
  EXPECT_NE(collector.landmarks[0].reason.find("at least 2"), std::string::npos);
  EXPECT_EQ(server.rejections().total(), 2);  // the landmark request and the undecodable trial
}

// The command line, in-process.
TEST(RegistrationCliTest, HelpGoesToOutAndExitsZero) {
  test::CommandRun r = test::RunCommand(RunRegistration, "orbed-registration", {"--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("--state-period-s"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("mean"), std::string::npos) << r.out;
  EXPECT_TRUE(r.err.empty()) << r.err;
  r = test::RunCommand(RunRegistration, "orbed-registration", {"send", "--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("--timeout-s"), std::string::npos) << r.out;
}

TEST(RegistrationCliTest, RefusesAnUnknownFlagAndBadValues) {
  test::CommandRun r = test::RunCommand(RunRegistration, "orbed-registration", {"--no-such-flag"});
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("--no-such-flag"), std::string::npos) << r.err;
  r = test::RunCommand(RunRegistration, "orbed-registration", {"--state-period-s", "-1"});
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("--state-period-s"), std::string::npos) << r.err;
  r = test::RunCommand(RunRegistration, "orbed-registration", {"mean", "--json"});
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("--input"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST(RegistrationCliTest, MeanPrintsTheJsonOnOut) {
  const std::string input = SourceTreePath("procs/registration_server/testdata/robust_trials.txt");
  const test::CommandRun r = test::RunCommand(RunRegistration, "orbed-registration",
                                              {"mean", "--input", input, "--robust", "--json"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"n_used\":10,\"rejected\":[10]"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace orbed::registration
