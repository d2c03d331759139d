// orbed-scenario without processes: the error measures against hand-computed values, the scenario
// file's checks, results.json's shape, and the whole conductor on memq:// against a fake sim,
// registration server and user living on the same bus (the user misplaces the virtual robot by a
// known offset, so every error is known by hand).
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/iiwa_command_t.hpp>
#include <orbed/misalignment_request_t.hpp>
#include <orbed/misalignment_t.hpp>
#include <orbed/plan_check_reply_t.hpp>
#include <orbed/plan_check_request_t.hpp>
#include <orbed/registration_t.hpp>
#include <orbed/robot_state_t.hpp>
#include <orbed/session_control_t.hpp>

#include "procs/common/conversions.h"
#include "viraal/protocol.h"
#include "viraal/metrics.h"
#include "viraal/results.h"
#include "procs/scenario/viraal_scenario.h"

namespace orbed::scenario {
namespace {

constexpr double kDeg = M_PI / 180.0;

// The trocar_or scene's base: (0.25, -0.55, 0.75), yaw 90 deg.
Eigen::Isometry3d SceneBase() {
  Eigen::Isometry3d X_WR = Eigen::Isometry3d::Identity();
  X_WR.linear() = Eigen::AngleAxisd(90 * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X_WR.translation() = Eigen::Vector3d(0.25, -0.55, 0.75);
  return X_WR;
}

std::string Source(const std::string& relative) { return ScenarioSourcePath(relative); }

TEST(ViraalErrors, RotationAngleIsTheGeodesicAngle) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Matrix3d dR = Eigen::AngleAxisd(1 * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_NEAR(viraal::RotationAngle(R, R * dR), 1 * kDeg, 1e-14);
  EXPECT_NEAR(viraal::RotationAngle(R, dR * R), 1 * kDeg, 1e-14);
  EXPECT_NEAR(viraal::RotationAngle(R, R), 0.0, 1e-15);
  // Near π the quaternion form keeps its precision.
  const Eigen::Matrix3d flip = Eigen::AngleAxisd(M_PI - 1e-7, Eigen::Vector3d::UnitX()).toRotationMatrix();
  EXPECT_NEAR(viraal::RotationAngle(Eigen::Matrix3d::Identity(), flip), M_PI - 1e-7, 1e-12);
}

// X_WV = X_WR shifted 10 mm along the base's x and turned 1 deg about its z: X_RV = [Rz(1°), (0.01,0,0)].
TEST(ViraalErrors, TenMillimetresAndOneDegreeInTheBaseFrame) {
  const Eigen::Isometry3d X_WR = SceneBase();
  Eigen::Isometry3d X_RV = Eigen::Isometry3d::Identity();
  X_RV.linear() = Eigen::AngleAxisd(1 * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X_RV.translation() = Eigen::Vector3d(0.01, 0, 0);
  const Eigen::Isometry3d X_WV = X_WR * X_RV;
  viraal::RobotPoints points;
  points.p_RC = Eigen::Vector3d(1, 0, 0);  // 1 m along the base x
  points.p_RF = Eigen::Vector3d(0, 0, 2);  // on the rotation axis: only the shift remains
  points.p_RL = {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 0, 1)};
  const viraal::AlignmentError e = viraal::EvaluateAlignment(X_WR, X_WV, points);
  EXPECT_NEAR(e.rotation_rad, 1 * kDeg, 1e-14);
  EXPECT_NEAR(e.base_translation_m, 0.010, 1e-15);
  // |(cos 1° − 1 + 0.01, sin 1°, 0)| = 0.020039051632882905 m (hand/calculator).
  EXPECT_NEAR(e.centroid_translation_m, 0.020039051632882905, 1e-14);
  EXPECT_NEAR(e.flange_translation_m, 0.010, 1e-14);
  ASSERT_EQ(e.p_W_real.size(), 2u);
  ASSERT_EQ(e.p_W_virtual.size(), 2u);
  // Real landmark 0: base x = W +y (yaw 90°) → p_WR + (0, 1, 0).
  EXPECT_NEAR((e.p_W_real[0] - Eigen::Vector3d(0.25, 0.45, 0.75)).norm(), 0.0, 1e-14);
  // Virtual landmark 0 in R: (cos 1° + 0.01, sin 1°, 0) → in W: (−sin 1°, cos 1° + 0.01, 0) + p_WR.
  const Eigen::Vector3d expected(0.25 - std::sin(1 * kDeg), -0.55 + std::cos(1 * kDeg) + 0.01, 0.75);
  EXPECT_NEAR((e.p_W_virtual[0] - expected).norm(), 0.0, 1e-14);
}

// X_WV = X_WR shifted 10 mm along W x and turned 1 deg about W z at its own origin.
TEST(ViraalErrors, TenMillimetresAndOneDegreeInTheWorldFrame) {
  const Eigen::Isometry3d X_WR = SceneBase();
  Eigen::Isometry3d X_WV = X_WR;
  X_WV.linear() = Eigen::AngleAxisd(1 * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix() * X_WR.linear();
  X_WV.translation() += Eigen::Vector3d(0.01, 0, 0);
  viraal::RobotPoints points;
  points.p_RC = Eigen::Vector3d(0, 0, 0.634);  // on the (vertical) base z axis: only the shift
  points.p_RF = Eigen::Vector3d(0.5, 0, 0);    // 0.5 m out along base x = W y
  const viraal::AlignmentError e = viraal::EvaluateAlignment(X_WR, X_WV, points);
  EXPECT_NEAR(e.rotation_rad, 1 * kDeg, 1e-14);
  EXPECT_NEAR(e.base_translation_m, 0.010, 1e-15);
  EXPECT_NEAR(e.centroid_translation_m, 0.010, 1e-14);
  // W offset of the flange: (0.01 − 0.5 sin 1°, 0.5 (cos 1° − 1), 0).
  EXPECT_NEAR(e.flange_translation_m,
              std::hypot(0.01 - 0.5 * std::sin(1 * kDeg), 0.5 * (std::cos(1 * kDeg) - 1)), 1e-14);
}

TEST(ViraalErrors, MeanOverConfigurationsAveragesPointErrorsAndPoolsLandmarks) {
  const Eigen::Isometry3d X_WR = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d X_WV = Eigen::Isometry3d::Identity();
  X_WV.linear() = Eigen::AngleAxisd(90 * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  viraal::RobotPoints a, b;
  a.p_RC = Eigen::Vector3d(1, 0, 0);  // moves to (0, 1, 0): sqrt(2)
  b.p_RC = Eigen::Vector3d(0, 0, 1);  // on the axis: 0
  a.p_RL = {Eigen::Vector3d(1, 0, 0)};
  b.p_RL = {Eigen::Vector3d(2, 0, 0), Eigen::Vector3d(0, 0, 3)};
  const viraal::AlignmentError e = viraal::EvaluateOverConfigurations(X_WR, X_WV, {a, b});
  EXPECT_NEAR(e.centroid_translation_m, std::sqrt(2.0) / 2, 1e-15);
  EXPECT_EQ(e.p_W_real.size(), 3u);
  EXPECT_THROW(viraal::EvaluateOverConfigurations(X_WR, X_WV, {}), std::invalid_argument);
}

TEST(ViraalErrors, RobotPointsOfTheIiwaUpright) {
  const auto model = orbed::sim::RobotModel::LoadFile(Source("sim/models/iiwa7.urdf"));
  const viraal::RobotPointSet set(model, {"iiwa_link_4", "iiwa_link_6", "iiwa_link_ee"});
  const viraal::RobotPoints p = set.At(Eigen::VectorXd::Zero(7));
  // DH d = (0.34, 0, 0.4, 0, 0.4, 0, 0.126): origins of link 0..7 and the flange at z = 0, 0,
  // 0.34, 0.34, 0.74, 0.74, 1.14, 1.14, 1.266 → centroid z = 5.706 / 9 = 0.634.
  EXPECT_NEAR((p.p_RC - Eigen::Vector3d(0, 0, 0.634)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((p.p_RF - Eigen::Vector3d(0, 0, 1.266)).norm(), 0.0, 1e-12);
  ASSERT_EQ(p.p_RL.size(), 3u);
  EXPECT_NEAR(p.p_RL[0].z(), 0.74, 1e-12);
  EXPECT_NEAR(p.p_RL[1].z(), 1.14, 1e-12);
  EXPECT_NEAR(p.p_RL[2].z(), 1.266, 1e-12);
  EXPECT_THROW(viraal::RobotPointSet(model, {"iiwa_link_9"}), std::invalid_argument);
}

TEST(viraal::ScenarioConfig, TheShippedFileLoads) {
  const viraal::ScenarioConfig c = viraal::LoadScenarioFile(Source(viraal::kDefaultScenarioRelativePath));
  EXPECT_EQ(c.trials, 3);
  ASSERT_EQ(c.modes.size(), 2u);
  EXPECT_EQ(c.modes[0].name, "ar_reflective");
  EXPECT_EQ(c.modes[0].display_mode, +orbed::alignment_trial_t::MODE_AR_REFLECTIVE);
  EXPECT_EQ(c.modes[0].num_mirrors, 1);
  EXPECT_EQ(c.modes[1].name, "ar");
  EXPECT_EQ(c.modes[1].num_mirrors, 0);
  EXPECT_EQ(c.method, +orbed::registration_t::METHOD_KARCHER);
  EXPECT_EQ(c.configurations_deg.size(), 3u);
  EXPECT_EQ(c.landmarks.size(), 3u);
}

void ExpectError(const std::string& yaml, const std::string& pattern) {
  try {
    viraal::LoadScenarioString(yaml, "s.yaml");
    ADD_FAILURE() << "no error for:\n" << yaml;
  } catch (const std::runtime_error& e) {
    EXPECT_TRUE(std::regex_search(std::string(e.what()), std::regex(pattern))) << e.what();
  }
}

TEST(viraal::ScenarioConfig, CommandLineOverrides) {
  viraal::ScenarioConfig config = viraal::LoadScenarioFile(Source(viraal::kDefaultScenarioRelativePath));
  viraal::ApplyOverrides(&config, 2, "ar,ar_reflective", {"0,10,0,-20,0,30,0", "5,10,0,-20,0,30,0"});
  EXPECT_EQ(config.trials, 2);
  ASSERT_EQ(config.modes.size(), 2u);
  EXPECT_EQ(config.modes[0].num_mirrors, 0);
  EXPECT_EQ(config.modes[1].num_mirrors, 1);
  ASSERT_EQ(config.configurations_deg.size(), 2u);
  EXPECT_EQ(config.configurations_deg[1][0], 5.0);
  EXPECT_EQ(config.configurations_deg[1][6], 0.0);
  viraal::ScenarioConfig untouched = viraal::LoadScenarioFile(Source(viraal::kDefaultScenarioRelativePath));
  const int trials = untouched.trials;
  viraal::ApplyOverrides(&untouched, 0, "", {});
  EXPECT_EQ(untouched.trials, trials);
  EXPECT_THROW(viraal::ApplyOverrides(&untouched, 0, "ar,mirror", {}), std::invalid_argument);
  EXPECT_THROW(viraal::ApplyOverrides(&untouched, 0, "", {"1,x,3"}), std::invalid_argument);
  viraal::ApplyOverrides(&untouched, 0, "", {"1,2,3"});  // parses; the size is checked with the rest:
  EXPECT_THROW(viraal::ValidateScenarioConfig(untouched, 7), std::invalid_argument);
}

TEST(viraal::ScenarioConfig, ErrorsNameTheLineAndTheFix) {
  const std::string good = "configurations_deg:\n  - [0, 30, 0, -60, 0, 45, 0]\nlandmarks: [iiwa_link_ee]\n";
  EXPECT_NO_THROW(viraal::LoadScenarioString(good, "s.yaml"));
  ExpectError("trails: 3\n" + good, "s.yaml:1: trails: unknown key");
  ExpectError(good + "modes: [ar, vr]\n",
              "s.yaml:4: modes\\[1\\]: unknown mode 'vr', expected ar_reflective or ar");
  ExpectError(good + "trials: 0\n", "s.yaml:4: trials: expected a whole number >= 1");
  ExpectError(good + "method: mean\n", "s.yaml:4: method: expected chordal, karcher or robust");
  ExpectError("configurations_deg:\n  - [0, 30, 0, x, 0, 45, 0]\nlandmarks: [a]\n",
              "s.yaml:2: configurations_deg\\[0\\]\\[3\\]: expected a number");
  ExpectError(
      "configurations_deg:\n  - [0, 30, 0, -60, 0, 45, 0]\n  - [0, 30, 0, -60, 0, 45, 0.5]\nlandmarks: [a]\n",
      "configurations 0 and 1 are the same");
  ExpectError("landmarks: [a]\n", "s.yaml:1: configurations_deg: missing");
  EXPECT_THROW(viraal::ParseJointList("1,2,x", "--q-deg"), std::invalid_argument);
  EXPECT_EQ(viraal::ParseJointList("1, 2.5,-3", "--q-deg"), (std::vector<double>{1, 2.5, -3}));
}

TEST(ViraalResults, MeanStdWithTheSampleDenominator) {
  const viraal::MeanStd s = viraal::ComputeMeanStd({1, 2, 3});
  EXPECT_DOUBLE_EQ(s.mean, 2.0);
  EXPECT_DOUBLE_EQ(s.std, 1.0);
  EXPECT_DOUBLE_EQ(viraal::ComputeMeanStd({5}).std, 0.0);
}

int Count(const std::string& text, const std::string& pattern) {
  const std::regex re(pattern);
  return static_cast<int>(
      std::distance(std::sregex_iterator(text.begin(), text.end(), re), std::sregex_iterator()));
}

TEST(ViraalResults, JsonHasTheDocumentedShape) {
  viraal::RunResults r;
  r.run_id = "t";
  r.ok = true;
  for (const char* mode : {"ar_reflective", "ar"}) {
    viraal::SessionResult s;
    s.mode = mode;
    for (int i = 0; i < 3; ++i) {
      viraal::TrialResult t;
      t.index = i;
      t.q_deg = {0, 30, 0, -60, 0, 45, 0};
      t.errors.translation_error_mm = 10 + i;
      s.trials.push_back(t);
    }
    s.mean = viraal::MeanResult{};
    r.sessions.push_back(s);
  }
  const std::string json = viraal::ResultsJson(r);
  EXPECT_EQ(Count(json, "\"mode\": \"ar_reflective\""), 1);
  EXPECT_EQ(Count(json, "\"mode\": \"ar\""), 1);
  EXPECT_EQ(Count(json, "\"index\": [0-2]"), 6);
  EXPECT_EQ(Count(json, "\"q_deg\": \\["), 6);
  EXPECT_EQ(Count(json, "\"mean\": \\{"), 2);
  // Per trial and per mean, the three required measures.
  EXPECT_EQ(Count(json, "\"translation_error_mm\": "), 6 + 2 + 2);  // + trial_statistics
  EXPECT_EQ(Count(json, "\"rotation_error_deg\": "), 6 + 2 + 2);
  EXPECT_EQ(Count(json, "\"misalignment_mm\": "), 6 + 2 + 2 + 3);  // + paper_reference
  EXPECT_NE(json.find("\"status\": \"ok\""), std::string::npos);
  // translation_error_mm 10, 11, 12: mean 11, std 1.
  EXPECT_NE(json.find("\"translation_error_mm\": {\n          \"mean\": 11,\n          \"std\": 1"),
            std::string::npos)
      << json;
  const std::string table = viraal::ResultsTable(r);
  EXPECT_NE(table.find("paper: 16.5 +/- 11.0 mm"), std::string::npos) << table;
}

// ----------------------------------------------------------------------------------------------
// The conductor on memq://, with a fake sim, registration server and user on the same LCM.

class FakeTestbed {
 public:
  // The user places the virtual robot at X_WV = X_WR·X_RV.
  FakeTestbed(lcm::LCM* lcm, const Eigen::Isometry3d& X_RV, bool user_answers)
      : lcm_(lcm), X_RV_(X_RV), user_answers_(user_answers) {
    lcm_->subscribe("IIWA_COMMAND", &FakeTestbed::OnCommand, this);
    lcm_->subscribe("PLAN_CHECK_REQUEST", &FakeTestbed::OnPlanCheck, this);
    lcm_->subscribe("SESSION_CONTROL", &FakeTestbed::OnSession, this);
    lcm_->subscribe("ALIGNMENT_TRIAL", &FakeTestbed::OnTrial, this);
    lcm_->subscribe("MISALIGNMENT_REQUEST", &FakeTestbed::OnMisalignment, this);
    q_.assign(7, 0.0);
    PublishState();
  }
  void PublishState() {
    orbed::robot_state_t s{};
    s.utime = NowMicros();
    s.robot_name = "iiwa7";
    s.X_WR = ToPose(SceneBase());
    s.X_RF = ToPose(Eigen::Isometry3d::Identity());
    s.X_RT = s.X_RF;
    s.num_joints = 7;
    s.joint_position = q_;
    s.joint_limit_hit.assign(7, 0);
    s.num_links = 0;
    s.motion_state = orbed::robot_state_t::MOTION_IDLE;
    lcm_->publish("ROBOT_STATE", &s);
  }
  void OnCommand(const lcm::ReceiveBuffer*, const std::string&, const orbed::iiwa_command_t* msg) {
    q_ = msg->joint_position;  // teleports: the arm is there at once
    PublishState();
  }
  void OnPlanCheck(const lcm::ReceiveBuffer*, const std::string&, const orbed::plan_check_request_t* msg) {
    orbed::plan_check_reply_t reply{};
    reply.utime = NowMicros();
    reply.request_id = msg->request_id;
    reply.request_valid = true;
    reply.within_limits = true;
    reply.feasible = !infeasible_;
    reply.in_collision = infeasible_;
    reply.reason = infeasible_ ? "in collision: iiwa_link_7 vs patient_torso" : "";
    lcm_->publish("PLAN_CHECK_REPLY", &reply);
  }
  void OnSession(const lcm::ReceiveBuffer*, const std::string&, const orbed::session_control_t* msg) {
    commands_.push_back(msg->command);
    if (msg->command == orbed::session_control_t::START) {
      session_ = msg->session_id;
      mode_ = msg->display_mode;
      mirrors_ = msg->num_mirrors;
      trials_ = 0;
      p_sum_.setZero();
    } else if (msg->command == orbed::session_control_t::REQUEST_TRIAL && user_answers_) {
      orbed::alignment_trial_t t{};
      t.utime = NowMicros();
      t.session_id = session_;
      t.trial_index = trials_;
      t.display_mode = mode_;
      t.num_mirrors = mirrors_;
      t.num_joints = 7;
      t.joint_position = q_;
      t.X_WV = ToPose(SceneBase() * X_RV_);
      t.duration_s = 12.5;
      t.user_id = "fake";
      lcm_->publish("ALIGNMENT_TRIAL", &t);
    } else if (msg->command == orbed::session_control_t::COMPUTE) {
      orbed::registration_t r = Registration(msg->utime, orbed::registration_t::REASON_COMPUTE);
      lcm_->publish("REGISTRATION", &r);
    }
  }
  // Stands in for orbed-registration: the trials all share one rotation, so the mean is theirs.
  void OnTrial(const lcm::ReceiveBuffer*, const std::string&, const orbed::alignment_trial_t* msg) {
    ++trials_;
    p_sum_ += ToVector3(msg->X_WV.position_m);
    q_WV_ = msg->X_WV;
    orbed::registration_t r = Registration(msg->utime, orbed::registration_t::REASON_TRIAL);
    lcm_->publish("REGISTRATION", &r);
  }
  orbed::registration_t Registration(int64_t utime, int8_t reason) {
    orbed::registration_t r{};
    r.utime = utime;
    r.session_id = session_;
    r.reason = reason;
    r.method = orbed::registration_t::METHOD_KARCHER;
    r.valid = trials_ > 0;
    r.X_WV_mean = q_WV_;
    FromVector3(p_sum_ / std::max(1, trials_), r.X_WV_mean.position_m);
    r.num_trials = r.num_used = trials_;
    r.converged = r.unique = true;
    return r;
  }
  // Stands in for the server's Table 1 evaluation: mean |virtual − real| per axis and its norm.
  void OnMisalignment(const lcm::ReceiveBuffer*, const std::string&,
                      const orbed::misalignment_request_t* msg) {
    orbed::misalignment_t m{};
    m.utime = msg->utime;
    m.request_id = msg->request_id;
    m.session_id = msg->session_id;
    m.valid = true;
    m.num_pairs = msg->num_pairs;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    double distance = 0;
    for (int k = 0; k < msg->num_pairs; ++k) {
      Eigen::Vector3d d;
      for (int i = 0; i < 3; ++i) d[i] = msg->p_W_virtual_m[k][i] - msg->p_W_real_m[k][i];
      m.error_W_m.push_back({std::abs(d.x()), std::abs(d.y()), std::abs(d.z())});
      m.error_norm_m.push_back(d.norm());
      mean += d.cwiseAbs();
      distance += d.norm();
    }
    mean /= msg->num_pairs;
    FromVector3(mean, m.mean_error_W_m);
    m.mean_error_norm_m = mean.norm();
    m.mean_pair_distance_m = distance / msg->num_pairs;
    pairs_seen_.push_back(msg->num_pairs);
    lcm_->publish("MISALIGNMENT", &m);
  }

  bool infeasible_ = false;
  std::vector<int8_t> commands_;
  std::vector<int> pairs_seen_;

 private:
  lcm::LCM* lcm_;
  Eigen::Isometry3d X_RV_;
  bool user_answers_;
  std::vector<double> q_;
  std::string session_;
  int8_t mode_ = 0;
  int32_t mirrors_ = 0;
  int trials_ = 0;
  Eigen::Vector3d p_sum_ = Eigen::Vector3d::Zero();
  orbed::pose_t q_WV_{};
};

ScenarioOptions MemqOptions(const std::string& dir) {
  ScenarioOptions options;
  options.conductor.config = viraal::LoadScenarioFile(Source(viraal::kDefaultScenarioRelativePath));
  options.conductor.run_id = "memq";
  options.results_dir = dir;
  options.conductor.trial_timeout_s = 1.0;
  options.conductor.reply_timeout_s = 1.0;
  return options;
}

CommonFlags MemqFlags() {
  CommonFlags flags("orbed-scenario-test");
  flags.lcm_url = "memq://";
  flags.duration_sec = 30;  // a safety net: the run itself takes well under a second
  return flags;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The trial configurations of the full run: q2 = q6 = 0, so the iiwa is a vertical column up to
// the elbow and its forward kinematics is known by hand (HandForwardKinematics).
const std::vector<std::vector<double>> kHandConfigurationsDeg = {
    {0, 0, 0, -60, 0, 0, 0},
    {90, 0, -30, 45, 0, 0, 0},
    {-40, 0, 10, 90, 30, 0, 60},
};

// Hand forward kinematics of the iiwa 7 (sim/models/iiwa7.urdf) at q with q2 = q6 = 0, in the base
// frame R [m]. Links 0 and 1 are at the base origin, links 2 and 3 at h₁ = (0, 0, 0.34), links 4 and
// 5 (the elbow) at h₂ = (0, 0, 0.74). Joint 4 tilts the forearm to the unit direction
// d = Rz(q1 + q3)·(−sin q4, 0, cos q4) (joints 1 and 3 both turn about the vertical); links 6 and 7
// are 0.4 m along d from the elbow, the flange (iiwa_link_ee) 0.526 m. Joints 5 and 7 turn about d
// and move no origin. The centroid is the mean of the 9 origins (links 0-7 and the flange):
// p_RC = (0.68 ẑ + 5 h₂ + 1.326 d) / 9 = (4.38 ẑ + 1.326 d) / 9.
struct HandPoints {
  Eigen::Vector3d p_RC, p_RF;
  std::vector<Eigen::Vector3d> p_RL;  // iiwa_link_4, iiwa_link_6, iiwa_link_ee (viraal.yaml)
};
HandPoints HandForwardKinematics(const std::vector<double>& q_deg) {
  EXPECT_EQ(q_deg[1], 0.0);
  EXPECT_EQ(q_deg[5], 0.0);
  const double q4 = q_deg[3] * kDeg;
  const Eigen::Vector3d d = Eigen::AngleAxisd((q_deg[0] + q_deg[2]) * kDeg, Eigen::Vector3d::UnitZ()) *
                            Eigen::Vector3d(-std::sin(q4), 0, std::cos(q4));
  const Eigen::Vector3d elbow(0, 0, 0.74);
  HandPoints p;
  p.p_RC = (4.38 * Eigen::Vector3d::UnitZ() + 1.326 * d) / 9;
  p.p_RF = elbow + 0.526 * d;
  p.p_RL = {elbow, elbow + 0.4 * d, p.p_RF};
  return p;
}

TEST(ViraalScenario, AFullRunOnMemqGivesTheUsersKnownRotatedOffset) {
  const std::string dir = std::filesystem::temp_directory_path() / "orbed_scenario_test_ok";
  std::filesystem::remove_all(dir);
  ScenarioOptions options = MemqOptions(dir);
  ASSERT_EQ(options.conductor.config.landmarks,
            (std::vector<std::string>{"iiwa_link_4", "iiwa_link_6", "iiwa_link_ee"}));
  options.conductor.config.configurations_deg = kHandConfigurationsDeg;
  ViraalScenario scenario(MemqFlags(), options);
  // The user misplaces the virtual robot by X_RV: 5 deg about the tilted axis u = (1, −2, 2)/3 and
  // t = (4, −6, 3) mm, both in the base frame R: X_WV = X_WR·X_RV.
  const Eigen::Vector3d u = Eigen::Vector3d(1, -2, 2) / 3;
  const Eigen::Matrix3d R_RV = Eigen::AngleAxisd(5 * kDeg, u).toRotationMatrix();
  const Eigen::Vector3d p_RV(0.004, -0.006, 0.003);
  Eigen::Isometry3d X_RV = Eigen::Isometry3d::Identity();
  X_RV.linear() = R_RV;
  X_RV.translation() = p_RV;
  FakeTestbed fake(&scenario.process().lcm(), X_RV, true);
  ASSERT_EQ(scenario.Run(), 0) << scenario.results().error;
  const viraal::RunResults& r = scenario.results();
  ASSERT_TRUE(r.ok);
  ASSERT_EQ(r.sessions.size(), 2u);

  // A point p_RQ of the robot is at X_WR·p_RQ really and at X_WV·p_RQ = X_WR·(R_RV·p_RQ + p_RV)
  // virtually: the error is R_WR·((R_RV − I)·p_RQ + p_RV), of norm ‖(R_RV − I)·p_RQ + p_RV‖.
  const Eigen::Matrix3d R_WR = SceneBase().linear();
  auto error_W = [&](const Eigen::Vector3d& p_RQ) -> Eigen::Vector3d {
    return R_WR * ((R_RV - Eigen::Matrix3d::Identity()) * p_RQ + p_RV);
  };
  // The fake server's t̄: the mean over the pairs of |error| per W axis.
  struct Expected {
    double centroid_mm{0}, flange_mm{0};
    Eigen::Vector3d t_bar_mm{Eigen::Vector3d::Zero()};
  };
  Expected mean;  // of the session mean, over the three configurations
  std::vector<Expected> trials;
  for (const std::vector<double>& q_deg : kHandConfigurationsDeg) {
    const HandPoints p = HandForwardKinematics(q_deg);
    Expected e;
    e.centroid_mm = error_W(p.p_RC).norm() * 1e3;
    e.flange_mm = error_W(p.p_RF).norm() * 1e3;
    for (const Eigen::Vector3d& p_RL : p.p_RL) e.t_bar_mm += error_W(p_RL).cwiseAbs() * 1e3 / 3;
    trials.push_back(e);
    mean.centroid_mm += e.centroid_mm / 3;
    mean.flange_mm += e.flange_mm / 3;
    mean.t_bar_mm += e.t_bar_mm / 3;  // 9 pairs: the mean of the three means of 3
  }
  auto expect_measures = [&](const viraal::ErrorMeasures& got, const Expected& want, const std::string& what) {
    SCOPED_TRACE(what);
    EXPECT_NEAR(got.rotation_error_deg, 5.0, 1e-9);
    EXPECT_NEAR(got.base_translation_error_mm, std::sqrt(61.0), 1e-9);  // ‖(4, −6, 3)‖ mm
    EXPECT_NEAR(got.translation_error_mm, want.centroid_mm, 1e-9);
    EXPECT_NEAR(got.flange_translation_error_mm, want.flange_mm, 1e-9);
    EXPECT_NEAR((got.misalignment_axes_mm - want.t_bar_mm).norm(), 0.0, 1e-9);
    EXPECT_NEAR(got.misalignment_mm, want.t_bar_mm.norm(), 1e-9);
  };
  // The expectations tell R_RV from its transpose (the turn the wrong way round): that would move
  // some centroid or flange error by millimetres. A world pose inverted (X_VW for X_WV) would put
  // the virtual robot about a metre away. Either fails the comparisons at 1e-9 mm.
  double transposed_change_mm = 0;
  for (const std::vector<double>& q_deg : kHandConfigurationsDeg) {
    const HandPoints p = HandForwardKinematics(q_deg);
    for (const Eigen::Vector3d& p_RQ : {p.p_RC, p.p_RF}) {
      const double transposed_mm =
          ((R_RV.transpose() - Eigen::Matrix3d::Identity()) * p_RQ + p_RV).norm() * 1e3;
      transposed_change_mm =
          std::max(transposed_change_mm, std::abs(transposed_mm - error_W(p_RQ).norm() * 1e3));
    }
  }
  EXPECT_GT(transposed_change_mm, 2.0);
  for (const viraal::SessionResult& s : r.sessions) {
    ASSERT_EQ(s.trials.size(), 3u);
    ASSERT_TRUE(s.mean.has_value());
    for (int i = 0; i < 3; ++i) {
      expect_measures(s.trials[i].errors, trials[i], s.mode + " trial " + std::to_string(i));
      EXPECT_EQ(s.trials[i].index, i);
      for (int j = 0; j < 7; ++j) EXPECT_NEAR(s.trials[i].q_deg[j], kHandConfigurationsDeg[i][j], 1e-9);
    }
    expect_measures(s.mean->errors, mean, s.mode + " mean");
  }
  EXPECT_EQ(r.sessions[0].session_id, "memq-ar_reflective");
  EXPECT_EQ(r.sessions[1].session_id, "memq-ar");
  EXPECT_EQ(r.sessions[1].num_mirrors, 0);
  // Three landmark pairs per trial, nine for each mean (three configurations).
  EXPECT_EQ(fake.pairs_seen_, (std::vector<int>{3, 3, 3, 9, 3, 3, 3, 9}));
  // START, 3 × REQUEST_TRIAL, COMPUTE, STOP per session. The last STOP leaves as the run ends; on
  // memq:// nobody dispatches it any more.
  const std::vector<int8_t> session = {0, 4, 4, 4, 2, 3};
  std::vector<int8_t> expected = session;
  expected.insert(expected.end(), session.begin(), session.end() - 1);
  EXPECT_EQ(fake.commands_, expected);
  const std::string json = ReadFile(dir + "/results.json");
  EXPECT_EQ(scenario.results_path(), dir + "/results.json");
  EXPECT_NE(json.find("\"status\": \"ok\""), std::string::npos);
  EXPECT_EQ(Count(json, "\"index\": [0-2]"), 6);
  EXPECT_EQ(Count(json, "\"mean\": \\{"), 2);
}

TEST(ViraalScenario, NoUserFailsNamingOrbedHmd) {
  const std::string dir = std::filesystem::temp_directory_path() / "orbed_scenario_test_no_user";
  std::filesystem::remove_all(dir);
  ViraalScenario scenario(MemqFlags(), MemqOptions(dir));
  FakeTestbed fake(&scenario.process().lcm(), Eigen::Isometry3d::Identity(), false);
  EXPECT_EQ(scenario.Run(), 1);
  EXPECT_NE(scenario.results().error.find("orbed-hmd"), std::string::npos) << scenario.results().error;
  EXPECT_NE(ReadFile(dir + "/results.json").find("\"status\": \"failed\""), std::string::npos);
}

TEST(ViraalScenario, AnInfeasibleConfigurationFailsBeforeAnythingMoves) {
  const std::string dir = std::filesystem::temp_directory_path() / "orbed_scenario_test_infeasible";
  ViraalScenario scenario(MemqFlags(), MemqOptions(dir));
  FakeTestbed fake(&scenario.process().lcm(), Eigen::Isometry3d::Identity(), true);
  fake.infeasible_ = true;
  EXPECT_EQ(scenario.Run(), 1);
  EXPECT_NE(scenario.results().error.find("infeasible"), std::string::npos) << scenario.results().error;
  EXPECT_NE(scenario.results().error.find("patient_torso"), std::string::npos);
  EXPECT_TRUE(fake.commands_.empty());
}

TEST(ViraalScenario, BadMessagesAreCountedAndIgnored) {
  const std::string dir = std::filesystem::temp_directory_path() / "orbed_scenario_test_bad";
  ViraalScenario scenario(MemqFlags(), MemqOptions(dir));
  FakeTestbed fake(&scenario.process().lcm(), Eigen::Isometry3d::Identity(), true);
  // A ROBOT_STATE with a non-unit quaternion and one with 6 joints come first.
  orbed::robot_state_t bad{};
  bad.X_WR = ToPose(Eigen::Isometry3d::Identity());
  bad.X_WR.quaternion_wxyz[0] = 0.5;
  bad.num_joints = 7;
  bad.joint_position.assign(7, 0.0);
  bad.joint_limit_hit.assign(7, 0);
  scenario.process().lcm().publish("ROBOT_STATE", &bad);
  bad.X_WR = ToPose(Eigen::Isometry3d::Identity());
  bad.num_joints = 6;
  bad.joint_position.assign(6, 0.0);
  bad.joint_limit_hit.assign(6, 0);
  scenario.process().lcm().publish("ROBOT_STATE", &bad);
  // Undecodable bytes on ALIGNMENT_TRIAL.
  const char junk[5] = {1, 2, 3, 4, 5};
  scenario.process().lcm().publish("ALIGNMENT_TRIAL", junk, sizeof(junk));
  ASSERT_EQ(scenario.Run(), 0) << scenario.results().error;
  EXPECT_EQ(scenario.process().rejections().total(), 3);
  EXPECT_EQ(scenario.results().rejected_inputs, 3);
}

TEST(ViraalScenario, ConfigurationsOutsideTheLimitsAreRefusedAtConstruction) {
  ScenarioOptions options = MemqOptions(std::filesystem::temp_directory_path().string());
  options.conductor.config.configurations_deg[1][1] = 130;  // joint 2 limit is ±120 deg
  try {
    ViraalScenario scenario(MemqFlags(), options);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(std::regex_search(std::string(e.what()), std::regex("configuration 1: .*iiwa_joint_2")))
        << e.what();
  }
}

}  // namespace
}  // namespace orbed::scenario
