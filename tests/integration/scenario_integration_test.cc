// orbed-scenario conducting the ViRAAl run over real LCM in a private network namespace, with the
// real orbed-iiwa-sim and orbed-registration and a fake user on a thread of this test (it stands in
// for orbed-hmd: it answers SESSION_CONTROL REQUEST_TRIAL with an ALIGNMENT_TRIAL placed at a known
// offset from the sim's true base pose). The errors in results.json must equal the offsets, worked
// out here from the sim's own ROBOT_STATE link poses.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <map>
#include <mutex>
#include <regex>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <lcm/lcm-cpp.hpp>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/robot_state_t.hpp>
#include <orbed/session_control_t.hpp>

#include "base/units.h"
#include "lcmtypes/contract/conversions.h"
#include "tests/integration/testbed_util.h"

namespace orbed::testing {
namespace {

// The user's misplacement of the virtual robot per mode, about the virtual base's own origin:
// R_WV = R_offset · R_WR, p_WV = p_WR + p_offset.
struct Offset {
  Eigen::Vector3d p_W;
  double yaw_deg;  // about W z
};
const std::map<std::string, Offset> kOffsets = {
    {"ar_reflective", {Eigen::Vector3d(0.010, 0, 0), 0.0}},  // a pure 10 mm shift
    {"ar", {Eigen::Vector3d(0, 0.020, 0), 1.0}},             // 20 mm and 1 deg
};

// Answers REQUEST_TRIAL like orbed-hmd's emulated user would, instantly, and remembers the
// ROBOT_STATE each trial was made at. Like orbed-hmd, it answers a repeated request id (the
// conductor's retry, should an answer be late) with the same trial, and a repeated START of its
// session changes nothing.
class FakeUser {
 public:
  explicit FakeUser(bool answers) : lcm_(""), answers_(answers) {
    lcm_.subscribe("SESSION_CONTROL", &FakeUser::OnSession, this);
    lcm_.subscribe("ROBOT_STATE", &FakeUser::OnState, this);
    thread_ = std::thread([this] {
      while (!stop_) lcm_.handleTimeout(20);
    });
  }
  ~FakeUser() {
    stop_ = true;
    thread_.join();
  }
  void OnState(const lcm::ReceiveBuffer*, const std::string&, const orbed::robot_state_t* msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    state_ = *msg;
    has_state_ = true;
  }
  void OnSession(const lcm::ReceiveBuffer*, const std::string&, const orbed::session_control_t* msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (msg->command == orbed::session_control_t::START) {
      if (msg->session_id != session_) {
        session_ = msg->session_id;
        mode_ = msg->display_mode;
        mirrors_ = msg->num_mirrors;
        next_index_ = 0;
      }
      return;
    }
    if (msg->command != orbed::session_control_t::REQUEST_TRIAL || msg->session_id != session_ || !answers_ ||
        !has_state_) {
      return;
    }
    if (const auto it = trials_.find(msg->request_id); it != trials_.end()) {
      lcm_.publish("ALIGNMENT_TRIAL", &it->second);
      return;
    }
    const std::string mode = mode_ == orbed::alignment_trial_t::MODE_AR_REFLECTIVE ? "ar_reflective" : "ar";
    const Offset& offset = kOffsets.at(mode);
    const Eigen::Isometry3d X_WR = FromPose(state_.X_WR);
    Eigen::Isometry3d X_WV = X_WR;
    X_WV.linear() =
        Eigen::AngleAxisd(offset.yaw_deg * kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
        X_WR.linear();
    X_WV.translation() += offset.p_W;
    orbed::alignment_trial_t trial{};
    trial.utime = NowMicros();
    trial.session_id = session_;
    trial.trial_index = next_index_++;
    trial.display_mode = mode_;
    trial.num_mirrors = mirrors_;
    trial.num_joints = state_.num_joints;
    trial.joint_position = state_.joint_position;
    trial.X_WV = ToPose(X_WV);
    trial.duration_s = 20.0;
    trial.user_id = "fake-user";
    trial.request_id = msg->request_id;
    states_[mode].push_back(state_);
    trials_[msg->request_id] = trial;
    lcm_.publish("ALIGNMENT_TRIAL", &trial);
  }
  std::vector<orbed::robot_state_t> States(const std::string& mode) {
    std::lock_guard<std::mutex> lock(mutex_);
    return states_[mode];
  }

 private:
  lcm::LCM lcm_;
  bool answers_;
  std::mutex mutex_;
  orbed::robot_state_t state_{};
  bool has_state_ = false;
  std::string session_;
  int8_t mode_ = 0;
  int32_t mirrors_ = 0;
  int next_index_ = 0;
  std::map<int64_t, orbed::alignment_trial_t> trials_;  // by request id
  std::map<std::string, std::vector<orbed::robot_state_t>> states_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Every number that follows "key": in the text, in order.
std::vector<double> Values(const std::string& json, const std::string& key) {
  std::vector<double> out;
  const std::regex re("\"" + key + "\": (-?[0-9.]+(e[-+]?[0-9]+)?)");
  for (auto it = std::sregex_iterator(json.begin(), json.end(), re); it != std::sregex_iterator(); ++it) {
    out.push_back(std::stod((*it)[1].str()));
  }
  return out;
}

// The expected point errors, from the sim's link poses (independent of the scenario's FK).
struct Expected {
  double centroid_mm;
  double misalignment_mm;
};
Expected ExpectedErrors(const std::vector<orbed::robot_state_t>& states, const Offset& offset) {
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(offset.yaw_deg * kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  double centroid = 0;
  Eigen::Vector3d t_bar = Eigen::Vector3d::Zero();
  int pairs = 0;
  for (const orbed::robot_state_t& s : states) {
    const Eigen::Matrix3d R_WR = FromPose(s.X_WR).linear();
    // p_WQ_virtual − p_WQ_real = (R − I)·R_WR·p_RQ + p_offset for the offset about the base origin.
    const auto d = [&](const Eigen::Vector3d& p_RQ) {
      return Eigen::Vector3d((R - Eigen::Matrix3d::Identity()) * R_WR * p_RQ + offset.p_W);
    };
    Eigen::Vector3d p_RC = Eigen::Vector3d::Zero();
    int n = 0;
    for (int i = 0; i < s.num_links; ++i) {
      const Eigen::Vector3d p_RL = ToVector3(s.X_RL[i].position_m);
      ++n;
      p_RC += p_RL;
      if (s.link_names[i] == "iiwa_link_4" || s.link_names[i] == "iiwa_link_6" ||
          s.link_names[i] == "iiwa_link_ee") {
        t_bar += d(p_RL).cwiseAbs();
        ++pairs;
      }
      if (s.link_names[i] == "iiwa_link_ee") break;  // the centroid runs from the base to the flange
    }
    centroid += d(p_RC / n).norm();
  }
  return {1e3 * centroid / states.size(), 1e3 * (t_bar / pairs).norm()};
}

std::vector<std::string> ScenarioArgs(const std::string& dir) {
  return {BinPath("orbed-scenario"),
          "--name",
          "scenario",
          "--run-id",
          "it",
          "--results-dir",
          dir,
          "--request-deadline-s",
          "5",
          "--move-timeout-s",
          "20",
          "--startup-timeout-s",
          "10"};
}

TEST(Scenario, TheViraalRunMeasuresTheUsersKnownOffsets) {
  BusWatcher bus;
  bus.Start();
  RunningProcess sim({BinPath("orbed-iiwa-sim"), "--name", "sim"});
  RunningProcess registration({BinPath("orbed-registration"), "--name", "registration"});
  ASSERT_TRUE(
      WaitFor([&] { return !bus.Heartbeats("sim").empty() && !bus.Heartbeats("registration").empty(); }, 15));
  FakeUser user(true);
  const std::string dir = MakeTempDir("scenario_it");
  RunningProcess scenario(ScenarioArgs(dir));
  ASSERT_TRUE(scenario.Wait(90)) << "orbed-scenario did not finish";
  ASSERT_EQ(scenario.exit_code(), 0);

  const std::string json = ReadFile(dir + "/results.json");
  ASSERT_FALSE(json.empty());
  EXPECT_NE(json.find("\"status\": \"ok\""), std::string::npos) << json;
  // 2 sessions × 3 trials + 2 means; values in order: session 0 trials 0-2, its mean, session 1 ...
  EXPECT_EQ(Values(json, "index").size(), 6u);
  const std::vector<double> t = Values(json, "translation_error_mm");
  const std::vector<double> r = Values(json, "rotation_error_deg");
  const std::vector<double> base = Values(json, "base_translation_error_mm");
  std::vector<double> m = Values(json, "misalignment_mm");
  ASSERT_EQ(t.size(), 8u) << json;
  ASSERT_EQ(r.size(), 8u);
  ASSERT_EQ(base.size(), 8u);
  ASSERT_EQ(m.size(), 8u + 3u);  // the first three are the paper's reference figures
  m.erase(m.begin(), m.begin() + 3);
  EXPECT_NE(json.find("\"mode\": \"ar_reflective\""), std::string::npos);
  EXPECT_LT(json.find("\"mode\": \"ar_reflective\""), json.find("\"mode\": \"ar\""));

  // ar_reflective: a pure 10 mm shift moves every point by 10 mm; t̄ = (10, 0, 0) mm.
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(t[k], 10.0, 1e-6) << k;
    EXPECT_NEAR(base[k], 10.0, 1e-6) << k;
    EXPECT_NEAR(r[k], 0.0, 1e-6) << k;
    EXPECT_NEAR(m[k], 10.0, 1e-6) << k;
  }
  // ar: 20 mm at the base and 1 deg, the point errors from the sim's link poses.
  const std::vector<orbed::robot_state_t> states = user.States("ar");
  ASSERT_EQ(states.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    const Expected e = ExpectedErrors({states[k]}, kOffsets.at("ar"));
    EXPECT_NEAR(base[4 + k], 20.0, 1e-6) << k;
    EXPECT_NEAR(r[4 + k], 1.0, 1e-6) << k;
    EXPECT_NEAR(t[4 + k], e.centroid_mm, 1e-5) << k;
    EXPECT_NEAR(m[4 + k], e.misalignment_mm, 1e-5) << k;
  }
  // The mean of three identical misplacements is that misplacement; its point errors are averaged
  // over the three configurations, its landmark pairs pooled.
  const Expected mean = ExpectedErrors(states, kOffsets.at("ar"));
  EXPECT_NEAR(base[7], 20.0, 1e-6);
  EXPECT_NEAR(r[7], 1.0, 1e-6);
  EXPECT_NEAR(t[7], mean.centroid_mm, 1e-5);
  EXPECT_NEAR(m[7], mean.misalignment_mm, 1e-5);
  // The trials were made at the three configurations of the scenario file, per session.
  const std::vector<double> q = Values(json, "index");
  EXPECT_EQ(q, (std::vector<double>{0, 1, 2, 0, 1, 2}));
}

TEST(Scenario, WithoutAUserItFailsNamingOrbedHmd) {
  BusWatcher bus;
  bus.Start();
  RunningProcess sim({BinPath("orbed-iiwa-sim"), "--name", "sim-2"});
  RunningProcess registration({BinPath("orbed-registration"), "--name", "registration-2"});
  ASSERT_TRUE(WaitFor(
      [&] { return !bus.Heartbeats("sim-2").empty() && !bus.Heartbeats("registration-2").empty(); }, 15));
  const std::string dir = MakeTempDir("scenario_it_no_user");
  std::vector<std::string> args = ScenarioArgs(dir);
  args.push_back("--trials");
  args.push_back("1");
  args[std::find(args.begin(), args.end(), "--request-deadline-s") - args.begin() + 1] = "2";
  RunningProcess scenario(args);
  ASSERT_TRUE(scenario.Wait(60));
  EXPECT_EQ(scenario.exit_code(), 1);
  const std::string json = ReadFile(dir + "/results.json");
  EXPECT_NE(json.find("\"status\": \"failed\""), std::string::npos) << json;
  EXPECT_NE(json.find("is orbed-hmd running"), std::string::npos) << json;
}

}  // namespace
}  // namespace orbed::testing
