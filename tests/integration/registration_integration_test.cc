// orbed-registration over real LCM in a private network namespace: a session of three trials in,
// the closed-form SE(3) mean out; a landmark from two rays; a bad trial counted; the same inputs
// replayed into a fresh server give the same REGISTRATION bytes.
#include <signal.h>
#include <sys/wait.h>

#include <cstdio>
#include <regex>

#include <cmath>

#include <Eigen/Core>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <orbed/alignment_trial_t.hpp>
#include <orbed/landmark_request_t.hpp>
#include <orbed/landmark_t.hpp>
#include <orbed/registration_t.hpp>
#include <orbed/session_control_t.hpp>

#include "base/units.h"
#include "tests/integration/testbed_util.h"

namespace orbed::testing {
namespace {

// Collects raw REGISTRATION and LANDMARK messages on its own thread.
class Collector {
 public:
  Collector() : lcm_("") {
    lcm_.subscribe("REGISTRATION", &Collector::OnRaw, this);
    lcm_.subscribe("LANDMARK", &Collector::OnRaw, this);
    thread_ = std::thread([this] {
      while (!stop_) lcm_.handleTimeout(20);
    });
  }
  ~Collector() {
    stop_ = true;
    thread_.join();
  }
  void OnRaw(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    std::lock_guard<std::mutex> lock(mutex_);
    messages_[channel].emplace_back(static_cast<const char*>(rbuf->data), rbuf->data_size);
  }
  std::vector<std::string> Get(const std::string& channel) {
    std::lock_guard<std::mutex> lock(mutex_);
    return messages_[channel];
  }
  void Clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    messages_.clear();
  }

 private:
  lcm::LCM lcm_;
  std::mutex mutex_;
  std::map<std::string, std::vector<std::string>> messages_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

template <class T>
T Decode(const std::string& bytes) {
  T msg;
  EXPECT_EQ(msg.decode(bytes.data(), 0, bytes.size()), static_cast<int>(bytes.size()));
  return msg;
}

orbed::alignment_trial_t Trial(int index, double angle_deg, Eigen::Vector3d p, int64_t utime) {
  orbed::alignment_trial_t trial{};
  trial.utime = utime;
  trial.session_id = "it-session";
  trial.trial_index = index;
  trial.display_mode = orbed::alignment_trial_t::MODE_AR_REFLECTIVE;
  trial.num_mirrors = 1;
  trial.num_joints = 7;
  trial.joint_position.assign(7, 0.1 * index);
  // Rotation about z by angle: q = (cos a/2, 0, 0, sin a/2).
  trial.X_WV.quaternion_wxyz[0] = std::cos(angle_deg * kDegToRad / 2);
  trial.X_WV.quaternion_wxyz[3] = std::sin(angle_deg * kDegToRad / 2);
  for (int i = 0; i < 3; ++i) trial.X_WV.position_m[i] = p[i];
  trial.duration_s = 30;
  trial.user_id = "test";
  return trial;
}

// Publishes the session and returns the REGISTRATION messages with reason TRIAL.
std::vector<std::string> RunSession(lcm::LCM* lcm, Collector* collector) {
  orbed::session_control_t start{};
  start.utime = 1000;
  start.session_id = "it-session";
  start.command = orbed::session_control_t::START;
  start.display_mode = orbed::alignment_trial_t::MODE_AR_REFLECTIVE;
  start.num_mirrors = 1;
  start.method = orbed::registration_t::METHOD_KARCHER;
  lcm->publish("SESSION_CONTROL", &start);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const std::vector<orbed::alignment_trial_t> trials = {
      Trial(0, 0.0, {1.00, 2.00, 0.50}, 2000),
      Trial(1, 10.0, {std::nan(""), 2.0, 0.5}, 2500),  // rejected: NaN position
      Trial(1, 10.0, {1.03, 2.00, 0.50}, 3000), Trial(2, 20.0, {1.00, 2.03, 0.50}, 4000)};
  for (const auto& trial : trials) lcm->publish("ALIGNMENT_TRIAL", &trial);
  std::vector<std::string> per_trial;
  WaitFor(
      [&] {
        per_trial.clear();
        for (const std::string& bytes : collector->Get("REGISTRATION")) {
          if (Decode<orbed::registration_t>(bytes).reason == orbed::registration_t::REASON_TRIAL) {
            per_trial.push_back(bytes);
          }
        }
        return per_trial.size() >= 3;
      },
      10);
  return per_trial;
}

TEST(Registration, ThreeTrialsInClosedFormMeanOutAndReplaysBitForBit) {
  BusWatcher bus;
  bus.Start();
  Collector collector;
  lcm::LCM lcm("");
  std::vector<std::string> first_run;
  {
    RunningProcess server({BinPath("orbed-registration"), "--name", "registration"});
    ASSERT_TRUE(WaitFor([&] { return !bus.Heartbeats("registration").empty(); }, 10));
    first_run = RunSession(&lcm, &collector);
    ASSERT_EQ(first_run.size(), 3u);
    const orbed::registration_t mean = Decode<orbed::registration_t>(first_run.back());
    EXPECT_TRUE(mean.valid);
    EXPECT_EQ(mean.num_used, 3);
    EXPECT_TRUE(mean.converged);
    EXPECT_TRUE(mean.unique);
    // Rotations about one axis at 0°, 10°, 20°: the geodesic mean is 10° about z.
    EXPECT_NEAR(mean.X_WV_mean.quaternion_wxyz[0], std::cos(5 * kDegToRad), 1e-9);
    EXPECT_NEAR(mean.X_WV_mean.quaternion_wxyz[1], 0.0, 1e-9);
    EXPECT_NEAR(mean.X_WV_mean.quaternion_wxyz[2], 0.0, 1e-9);
    EXPECT_NEAR(mean.X_WV_mean.quaternion_wxyz[3], std::sin(5 * kDegToRad), 1e-9);
    // Translation mean (paper eq. 3): (1.01, 2.01, 0.5).
    EXPECT_NEAR(mean.X_WV_mean.position_m[0], 1.01, 1e-12);
    EXPECT_NEAR(mean.X_WV_mean.position_m[1], 2.01, 1e-12);
    EXPECT_NEAR(mean.X_WV_mean.position_m[2], 0.50, 1e-12);
    // Residual angles 10°, 0°, 10°: RMS = sqrt(200/3) = 8.1650°, max 10°.
    EXPECT_NEAR(mean.rotation_rms_deg, std::sqrt(200.0 / 3.0), 1e-9);
    EXPECT_NEAR(mean.rotation_max_deg, 10.0, 1e-9);

    // Landmark from two rays through (1, 2, 0.5).
    orbed::landmark_request_t request{};
    request.utime = 5000;
    request.request_id = 77;
    request.name = "real/flange";
    request.num_rays = 2;
    request.origin_W_m = {{0, 0, 0.5}, {2, 0, 0.5}};
    const double s = 1 / std::sqrt(5.0);
    request.direction_W = {{s, 2 * s, 0}, {-s, 2 * s, 0}};
    lcm.publish("LANDMARK_REQUEST", &request);
    ASSERT_TRUE(WaitFor([&] { return !collector.Get("LANDMARK").empty(); }, 5));
    const orbed::landmark_t landmark = Decode<orbed::landmark_t>(collector.Get("LANDMARK")[0]);
    EXPECT_EQ(landmark.request_id, 77);
    EXPECT_TRUE(landmark.valid) << landmark.reason;
    EXPECT_NEAR(landmark.p_W_m[0], 1.0, 1e-9);
    EXPECT_NEAR(landmark.p_W_m[1], 2.0, 1e-9);
    EXPECT_NEAR(landmark.p_W_m[2], 0.5, 1e-9);

    // The NaN trial was counted on the heartbeat.
    ASSERT_TRUE(WaitFor(
        [&] {
          const auto beats = bus.Heartbeats("registration");
          return !beats.empty() && beats.back().status.rejected_inputs >= 1;
        },
        3));
    server.Signal(SIGINT);
    ASSERT_TRUE(server.Wait(5));
    EXPECT_EQ(server.exit_code(), 0);
  }
  // The same inputs into a fresh server: the same bytes.
  collector.Clear();
  RunningProcess again({BinPath("orbed-registration"), "--name", "registration-2"});
  ASSERT_TRUE(WaitFor([&] { return !bus.Heartbeats("registration-2").empty(); }, 10));
  const std::vector<std::string> second_run = RunSession(&lcm, &collector);
  ASSERT_EQ(second_run.size(), first_run.size());
  for (size_t i = 0; i < first_run.size(); ++i) EXPECT_EQ(second_run[i], first_run[i]) << i;
}

std::string Capture(const std::string& command, int* exit_code) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  char buffer[4096];
  while (size_t n = fread(buffer, 1, sizeof(buffer), pipe)) out.append(buffer, n);
  *exit_code = WEXITSTATUS(pclose(pipe));
  return out;
}

// The numbers of a JSON text, in order.
std::vector<double> Numbers(const std::string& text) {
  std::vector<double> numbers;
  const std::regex number(R"(-?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?)");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), number); it != std::sregex_iterator(); ++it) {
    numbers.push_back(std::stod(it->str()));
  }
  return numbers;
}

// `orbed-registration send` feeds a trial file through the bus to a running server; its answer
// must equal the offline `mean --json` of the same file (one code path): same keys and flags,
// numbers within 1e-12 (the server's pose goes through a rotation matrix, the offline mean not).
TEST(Registration, LiveServerAgreesWithTheOfflineMean) {
  BusWatcher bus;
  bus.Start();
  RunningProcess server({BinPath("orbed-registration"), "--name", "registration-send"});
  ASSERT_TRUE(WaitFor([&] { return !bus.Heartbeats("registration-send").empty(); }, 10));
  const std::string trials = SourcePath("procs/registration_server/testdata/robust_trials.txt");
  int offline_code = -1, live_code = -1;
  const std::string offline =
      Capture(BinPath("orbed-registration") + " mean --robust --json --input " + trials + " 2>/dev/null",
              &offline_code);
  const std::string live =
      Capture(BinPath("orbed-registration") + " send --robust --input " + trials, &live_code);
  EXPECT_EQ(offline_code, 0);
  EXPECT_EQ(live_code, 0);
  EXPECT_NE(offline.find("\"rejected\":[10]"), std::string::npos) << offline;
  const std::regex numbers_out(R"(-?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?)");
  EXPECT_EQ(std::regex_replace(live, numbers_out, "#"), std::regex_replace(offline, numbers_out, "#"));
  const std::vector<double> a = Numbers(live), b = Numbers(offline);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(a[i], b[i], 1e-12) << "number " << i;
}

}  // namespace
}  // namespace orbed::testing
