// orbed-iiwa-sim as a real process over real LCM, in a private network namespace (ctest wraps this
// binary in scripts/netns-exec), driven by a client built from Drake's own lcmt_iiwa_command /
// lcmt_iiwa_status definitions (tests/drake, generated into the build tree): if the fingerprints
// did not match, no status would decode and no command would be accepted.
//   - a command beyond the joint limits stops on the limits, and says so;
//   - a command whose straight joint-space path runs into the table (established at run time with
//     `orbed-robot check` along the path) stops short of contact;
//   - joint speeds measured from the status stamps (the sim clock: tick k at start + k x 5 ms) never
//     exceed the iiwa 7's published speeds (data sheet), message to message and over 0.5 s;
//   - IIWA_STATUS arrives at 200 Hz within 5 % over 5 s, as the subscriber counts it;
//   - stale and wrong-size commands are rejected and counted on the heartbeat.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <drake/lcmt_iiwa_command.hpp>
#include <drake/lcmt_iiwa_status.hpp>
#include <lcm/lcm-cpp.hpp>
#include <orbed/collision_status_t.hpp>
#include <orbed/robot_state_t.hpp>

#include "base/units.h"
#include "lcmtypes/contract/conversions.h"
#include "tests/integration/testbed_util.h"

namespace orbed::testing {
namespace {

constexpr double kPeriodS = 0.005;  // the sim's default tick
constexpr int64_t kPeriodUs = 5000;
constexpr double kStopMarginM = 0.01;                               // the sim's default --stop-margin-m
const double kSpeedDegPerS[7] = {98, 98, 100, 130, 140, 180, 180};  // iiwa 7 R800 data sheet

// Everything the sim publishes, seen by a Drake-typed client (IIWA_STATUS) and orbed types.
class SimClient {
 public:
  SimClient() {
    bus_.lcm().subscribe("IIWA_STATUS", &SimClient::OnStatus, this);
    bus_.lcm().subscribe("ROBOT_STATE", &SimClient::OnState, this);
    bus_.lcm().subscribe("COLLISION_STATUS", &SimClient::OnCollision, this);
    bus_.Start();
    if (!pub_.good()) throw std::runtime_error("LCM publisher not available");
  }

  /// One IIWA_STATUS and when it was handed to this client (monotonic clock).
  struct ReceivedStatus {
    drake::lcmt_iiwa_status msg;
    std::chrono::steady_clock::time_point received;
  };

  std::vector<drake::lcmt_iiwa_status> status() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<drake::lcmt_iiwa_status> out;
    for (const auto& r : status_) out.push_back(r.msg);
    return out;
  }
  size_t num_status() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return status_.size();
  }
  /// Every IIWA_STATUS with its receive time, taken under one lock (one moment).
  std::vector<ReceivedStatus> status_log() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return status_;
  }
  std::vector<orbed::robot_state_t> state() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return state_;
  }
  std::vector<orbed::collision_status_t> collision() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return collision_;
  }
  void Clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    status_.clear();
    state_.clear();
    collision_.clear();
  }
  BusWatcher& bus() { return bus_; }

  void Command(const std::vector<double>& q_deg, int64_t utime = NowMicros()) {
    drake::lcmt_iiwa_command cmd{};
    cmd.utime = utime;
    cmd.num_joints = static_cast<int32_t>(q_deg.size());
    for (double q : q_deg) cmd.joint_position.push_back(q * kDegToRad);
    cmd.num_torques = 0;
    pub_.publish("IIWA_COMMAND", &cmd);
  }

 private:
  void OnStatus(const lcm::ReceiveBuffer*, const std::string&, const drake::lcmt_iiwa_status* m) {
    const auto now = std::chrono::steady_clock::now();
    std::lock_guard<std::mutex> lock(mutex_);
    status_.push_back({*m, now});
  }
  void OnState(const lcm::ReceiveBuffer*, const std::string&, const orbed::robot_state_t* m) {
    std::lock_guard<std::mutex> lock(mutex_);
    state_.push_back(*m);
  }
  void OnCollision(const lcm::ReceiveBuffer*, const std::string&, const orbed::collision_status_t* m) {
    std::lock_guard<std::mutex> lock(mutex_);
    collision_.push_back(*m);
  }

  mutable std::mutex mutex_;
  std::vector<ReceivedStatus> status_;
  std::vector<orbed::robot_state_t> state_;
  std::vector<orbed::collision_status_t> collision_;
  lcm::LCM pub_{""};
  BusWatcher bus_;  // last: its thread stops before the vectors go
};

std::unique_ptr<RunningProcess> StartSim(SimClient* client, std::vector<std::string> extra = {}) {
  std::vector<std::string> argv{BinPath("orbed-iiwa-sim"), "--name", "sim"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  auto sim = std::make_unique<RunningProcess>(argv);
  const bool up = WaitFor([&] { return sim->running() && client->num_status() > 10; }, 15);
  EXPECT_TRUE(up) << "orbed-iiwa-sim published no IIWA_STATUS that a Drake lcmt_iiwa_status decodes";
  return sim;
}

// Waits until the last ROBOT_STATE has `motion_state` and the arm has not moved for `still_s`.
bool WaitForRest(SimClient* client, RunningProcess* sim, int8_t motion_state, double timeout_s,
                 double still_s = 0.2) {
  const size_t still_ticks = static_cast<size_t>(still_s / kPeriodS);
  return WaitFor(
      [&] {
        sim->running();  // drains its output
        const auto state = client->state();
        if (state.size() < still_ticks + 1 || state.back().motion_state != motion_state) return false;
        for (size_t k = state.size() - still_ticks; k < state.size(); ++k) {
          if (state[k].joint_position != state.back().joint_position) return false;
        }
        return true;
      },
      timeout_s);
}

// The stamps are the sim clock (sim/iiwa_sim.h): consecutive messages are a whole number of
// periods apart (more than one only if a datagram was lost), and each tick steps at most
// v_max * period. So the speed read from the stamps is bounded exactly, however loaded the machine:
// between consecutive messages no joint moves more than v_max * (utime difference), and neither
// does it over 0.5 s windows (100 messages). Returns the peak windowed speed per joint [deg/s].
std::vector<double> ExpectWithinJointSpeeds(const std::vector<drake::lcmt_iiwa_status>& s) {
  std::vector<double> peak(7, 0.0);
  constexpr size_t kWindow = 100;
  constexpr double kRoundOff = 1 + 1e-9;  // relative round-off of the motion law's steps
  for (size_t k = 1; k < s.size(); ++k) {
    const int64_t dt_us = s[k].utime - s[k - 1].utime;
    EXPECT_GT(dt_us, 0) << "utime not increasing between messages " << k - 1 << " and " << k;
    EXPECT_EQ(dt_us % kPeriodUs, 0) << "utime off the sim clock between messages " << k - 1 << " and " << k;
    const double dt_s = dt_us * 1e-6;
    for (int i = 0; i < 7; ++i) {
      const double step = std::abs(s[k].joint_position_measured[i] - s[k - 1].joint_position_measured[i]);
      EXPECT_LE(step, kSpeedDegPerS[i] * kDegToRad * dt_s * kRoundOff)
          << "joint " << i + 1 << " between messages " << k - 1 << " and " << k;
    }
    if (k < kWindow) continue;
    const double window_s = (s[k].utime - s[k - kWindow].utime) * 1e-6;
    for (int i = 0; i < 7; ++i) {
      const double speed_deg_per_s =
          std::abs(s[k].joint_position_measured[i] - s[k - kWindow].joint_position_measured[i]) / window_s /
          kDegToRad;
      EXPECT_LE(speed_deg_per_s, kSpeedDegPerS[i] * kRoundOff) << "joint " << i + 1 << " at message " << k;
      peak[i] = std::max(peak[i], speed_deg_per_s);
    }
  }
  return peak;
}

std::string RunAndCapture(const std::string& command) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return out;
  char buffer[4096];
  size_t n;
  while ((n = fread(buffer, 1, sizeof(buffer), pipe)) > 0) out.append(buffer, n);
  pclose(pipe);
  return out;
}

std::string JoinDeg(const std::vector<double>& q_deg) {
  std::string text;
  char item[32];
  for (double q : q_deg) {
    std::snprintf(item, sizeof(item), "%s%.6f", text.empty() ? "" : ",", q);
    text += item;
  }
  return text;
}

TEST(IiwaSim, DrakeCommandBeyondTheLimitsStopsOnTheLimitsWithinTheJointSpeeds) {
  SimClient client;
  auto sim = StartSim(&client);
  client.Clear();
  // Joint 2 to -130 deg (limit -120: the arm tips back, away from the table) and joint 7 to 200
  // deg (limit 175). Joint 2 sets the pace: 120 deg at 98 deg/s = 1.22 s.
  client.Command({0, -130, 0, 0, 0, 0, 200});
  ASSERT_TRUE(WaitForRest(&client, sim.get(), orbed::robot_state_t::MOTION_STOPPED_AT_LIMIT, 10))
      << "the arm did not come to rest at the limits";
  const auto status = client.status();
  const drake::lcmt_iiwa_status& last = status.back();
  ASSERT_EQ(last.num_joints, 7);
  EXPECT_NEAR(last.joint_position_measured[1], -120 * kDegToRad, 1e-9);
  EXPECT_NEAR(last.joint_position_measured[6], 175 * kDegToRad, 1e-9);
  for (int i : {0, 2, 3, 4, 5}) EXPECT_EQ(last.joint_position_measured[i], 0.0);
  EXPECT_NEAR(last.joint_position_commanded[6], 200 * kDegToRad, 1e-12);
  const orbed::robot_state_t state = client.state().back();
  EXPECT_NE(state.stop_reason.find("iiwa_joint_2"), std::string::npos) << state.stop_reason;
  EXPECT_NE(state.stop_reason.find("iiwa_joint_7"), std::string::npos) << state.stop_reason;
  EXPECT_EQ(state.joint_limit_hit, (std::vector<int8_t>{0, -1, 0, 0, 0, 0, 1}));

  const std::vector<double> peak = ExpectWithinJointSpeeds(status);
  // The limit was reached, not merely respected: joint 2 ran at (about) its 98 deg/s.
  EXPECT_GT(peak[1], 0.9 * 98) << "joint 2 never reached its speed";
  sim->Signal(SIGINT);
  ASSERT_TRUE(sim->Wait(10));
  EXPECT_EQ(sim->exit_code(), 0);
}

// Upright start; the target tips the arm forward and down beside the patient's legs. Sampling the
// straight joint-space path with `orbed-robot check` (an independent tool on the engines, run
// here) shows where it first touches the table top; the sim must stop before that point, with
// positive clearance throughout, and say why.
TEST(IiwaSim, CommandIntoTheTableStopsShortOfContact) {
  const std::vector<double> target_deg{-30, 80, 0, -30, 0, 60, 0};
  const std::string scene = SourcePath("sim/models/scenes/trocar_or.yaml");
  double first_contact = -1;
  std::string first_contact_json;
  for (int k = 0; k <= 100 && first_contact < 0; ++k) {
    std::vector<double> q(7);
    for (int i = 0; i < 7; ++i) q[i] = target_deg[i] * k / 100.0;
    const std::string json =
        RunAndCapture(BinPath("orbed-robot") + " check --scene " + scene + " --q-deg " + JoinDeg(q));
    ASSERT_NE(json.find("\"in_collision\":"), std::string::npos) << json;
    if (json.find("\"in_collision\":true") != std::string::npos) {
      first_contact = k / 100.0;
      first_contact_json = json;
    }
  }
  ASSERT_GT(first_contact, 0) << "the path to the target must run into the table";
  ASSERT_NE(first_contact_json.find("\"b\":\"table_top\""), std::string::npos)
      << "the first contact on the path must be with the table: " << first_contact_json;

  SimClient client;
  auto sim = StartSim(&client);
  client.Clear();
  client.Command(target_deg);
  ASSERT_TRUE(WaitForRest(&client, sim.get(), orbed::robot_state_t::MOTION_STOPPED_BEFORE_COLLISION, 10))
      << "the arm did not stop before the table";
  const auto collision = client.collision();
  ASSERT_FALSE(collision.empty());
  for (const auto& c : collision) {
    EXPECT_FALSE(c.in_collision);
    EXPECT_GT(c.min_distance_m, 0.0);
    EXPECT_GE(c.min_distance_m, kStopMarginM - 1e-9);
  }
  EXPECT_LT(collision.back().min_distance_m, kStopMarginM + 0.01) << "stopped needlessly early";
  const orbed::robot_state_t state = client.state().back();
  EXPECT_NE(state.stop_reason.find("table_top"), std::string::npos) << state.stop_reason;
  EXPECT_NE(state.stop_reason.find("iiwa_tool"), std::string::npos) << state.stop_reason;

  // Where it stopped: on the straight line, before the first contact.
  const auto status = client.status();
  const drake::lcmt_iiwa_status& last = status.back();
  const double fraction = last.joint_position_measured[1] / (target_deg[1] * kDegToRad);
  EXPECT_GT(fraction, 0.5);
  EXPECT_LT(fraction, first_contact);
  for (int i = 0; i < 7; ++i) {
    EXPECT_NEAR(last.joint_position_measured[i], fraction * target_deg[i] * kDegToRad, 1e-9)
        << "joint " << i + 1;
  }
  ExpectWithinJointSpeeds(status);
  std::printf("stopped at %.1f %% of the path (first contact at %.0f %%), clearance %.4f m: %s\n",
              100 * fraction, 100 * first_contact, collision.back().min_distance_m,
              state.stop_reason.c_str());
}

// The rate as the subscriber sees it: IIWA_STATUS messages handed to the client within a 5 s window
// of its own monotonic clock, after a 0.5 s warm-up (the window's edges cost at most a message or
// two, 0.2 %). The sim's loop runs missed ticks back to back when it falls behind, so the count
// holds under moderate load. The stamps tell the sim clock's side: the ticks the window spans and
// any datagrams lost.
TEST(IiwaSim, StatusRateIs200HzWithin5PercentOver5s) {
  SimClient client;
  auto sim = StartSim(&client);
  auto wait = [&](std::chrono::steady_clock::time_point until) {
    while (std::chrono::steady_clock::now() < until) {
      sim->running();  // drains its output
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  };
  const auto begin = std::chrono::steady_clock::now() + std::chrono::milliseconds(500);
  const auto end = begin + std::chrono::seconds(5);
  wait(end + std::chrono::milliseconds(200));  // messages received before `end` are all handled
  // One snapshot of messages and receive times together: two reads at two moments would disagree
  // while messages keep arriving.
  const auto log = client.status_log();
  size_t first = log.size(), count = 0;
  for (size_t k = 0; k < log.size(); ++k) {
    if (log[k].received < begin || log[k].received >= end) continue;
    if (count++ == 0) first = k;
  }
  ASSERT_GT(count, 1u) << "no IIWA_STATUS in the window";
  const double rate_hz = count / 5.0;
  const int64_t span_ticks = (log[first + count - 1].msg.utime - log[first].msg.utime) / kPeriodUs;
  const int64_t lost = span_ticks + 1 - static_cast<int64_t>(count);
  std::printf(
      "IIWA_STATUS: %zu messages received in 5 s = %.1f Hz; they span %lld ticks of the sim clock "
      "(%lld lost)\n",
      count, rate_hz, static_cast<long long>(span_ticks + 1), static_cast<long long>(lost));
  EXPECT_NEAR(rate_hz, 200.0, 10.0);
  EXPECT_TRUE(sim->running());
}

TEST(IiwaSim, StaleAndWrongSizeDrakeCommandsAreRejectedAndCounted) {
  SimClient client;
  auto sim = StartSim(&client);
  client.Command({10, 0, 0, 0, 0, 0, 0}, NowMicros() - 10'000'000);  // 10 s old
  client.Command({10, 0, 0, 0, 0, 0});                               // 6 joints
  bool counted = false;
  ASSERT_TRUE(WaitFor(
      [&] {
        sim->running();
        const auto beats = client.bus().Heartbeats("sim");
        if (beats.empty()) return false;
        const orbed::process_status_t& s = beats.back().status;
        int found = 0;
        for (int r = 0; r < s.num_reasons; ++r) {
          if (s.reject_reason[r] == "IIWA_COMMAND/stale" && s.reject_count[r] == 1) ++found;
          if (s.reject_reason[r] == "IIWA_COMMAND/num_joints" && s.reject_count[r] == 1) ++found;
        }
        counted = found == 2 && s.rejected_inputs == 2;
        return counted;
      },
      5))
      << "the heartbeat did not count both rejections";
  // Neither command moved the arm; it is still publishing.
  const auto status = client.status();
  ASSERT_FALSE(status.empty());
  EXPECT_EQ(status.back().joint_position_measured[0], 0.0);
  EXPECT_TRUE(sim->running());
}

}  // namespace
}  // namespace orbed::testing
