// orbed-scenario without processes: the error measures against hand-computed values, the scenario
// file's checks, results.json's shape, and the whole conductor on memq:// against a fake sim,
// registration server and user living on the same bus (the user misplaces the virtual robot by a
// known offset, so every error is known by hand).
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
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

#include "base/units.h"
#include "experiments/viraal/metrics.h"
#include "experiments/viraal/protocol.h"
#include "experiments/viraal/results.h"
#include "lcmtypes/contract/conversions.h"
#include "procs/scenario/scenario_process.h"
#include "sim/scene.h"

namespace orbed::scenario {
namespace {

std::string Source(const std::string& relative) { return ScenarioSourcePath(relative); }

// The shipped scene's robot base X_WR (the fake sim's truth).
Eigen::Isometry3d SceneBase() { return sim::LoadSceneFile(Source(sim::kDefaultSceneRelativePath)).X_WR; }

int Count(const std::string& text, const std::string& pattern) {
  const std::regex re(pattern);
  return static_cast<int>(
      std::distance(std::sregex_iterator(text.begin(), text.end(), re), std::sregex_iterator()));
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
  // Like the real headset and server: a repeated request id (a retry, should an answer be late)
  // gets its first answer again and changes nothing.
  void OnSession(const lcm::ReceiveBuffer*, const std::string&, const orbed::session_control_t* msg) {
    if (const auto it = answers_.find(msg->request_id); it != answers_.end()) {
      if (it->second) it->second();
      return;
    }
    answers_[msg->request_id] = nullptr;
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
      t.request_id = msg->request_id;
      answers_[msg->request_id] = [this, t] { lcm_->publish("ALIGNMENT_TRIAL", &t); };
      lcm_->publish("ALIGNMENT_TRIAL", &t);
    } else if (msg->command == orbed::session_control_t::COMPUTE) {
      orbed::registration_t r =
          Registration(msg->utime, orbed::registration_t::REASON_COMPUTE, msg->request_id);
      answers_[msg->request_id] = [this, r] { lcm_->publish("REGISTRATION", &r); };
      lcm_->publish("REGISTRATION", &r);
    }
  }
  // Stands in for orbed-registration: the trials all share one rotation, so the mean is theirs.
  // A repeated trial is registered once and answered with its first registration.
  void OnTrial(const lcm::ReceiveBuffer*, const std::string&, const orbed::alignment_trial_t* msg) {
    auto it = registrations_.find(msg->request_id);
    if (it == registrations_.end()) {
      ++trials_;
      p_sum_ += ToVector3(msg->X_WV.position_m);
      q_WV_ = msg->X_WV;
      it = registrations_
               .emplace(msg->request_id,
                        Registration(msg->utime, orbed::registration_t::REASON_TRIAL, msg->request_id))
               .first;
    }
    lcm_->publish("REGISTRATION", &it->second);
  }
  orbed::registration_t Registration(int64_t utime, int8_t reason, int64_t request_id) {
    orbed::registration_t r{};
    r.utime = utime;
    r.request_id = request_id;
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
  std::map<int64_t, std::function<void()>> answers_;        // by SESSION_CONTROL request id
  std::map<int64_t, orbed::registration_t> registrations_;  // by the trial's request id
};

ScenarioOptions MemqOptions(const std::string& dir) {
  ScenarioOptions options;
  options.conductor.config = viraal::LoadScenarioFile(Source(viraal::kDefaultScenarioRelativePath));
  options.conductor.run_id = "memq";
  options.results_dir = dir;
  options.conductor.request_deadline_s = 1.0;
  return options;
}

CommonFlags MemqFlags() {
  CommonFlags flags("orbed-scenario-test");
  flags.lcm_url = "memq://";
  flags.duration_s = 30;  // a safety net: the run itself takes well under a second
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
  const double q4 = q_deg[3] * kDegToRad;
  const Eigen::Vector3d d = Eigen::AngleAxisd((q_deg[0] + q_deg[2]) * kDegToRad, Eigen::Vector3d::UnitZ()) *
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
  const Eigen::Matrix3d R_RV = Eigen::AngleAxisd(5 * kDegToRad, u).toRotationMatrix();
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
  auto expect_measures = [&](const viraal::ErrorMeasures& got, const Expected& want,
                             const std::string& what) {
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
