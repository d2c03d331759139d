// orbed-guidance beside the real orbed-iiwa-sim over real LCM, in a private network namespace:
// the test plays the assistant, moving the arm with IIWA_COMMAND as the guidance says, joint by joint.
//   - at the start (arm at 0) GUIDANCE names joint 1, its error (current − target) is −20 deg;
//   - with joint 1 brought to its target, the next joint named is joint 2;
//   - with the whole target commanded, GUIDANCE says done; once the arm is at rest, its errors equal
//     IIWA_STATUS's measured joints minus the target;
//   - the guidance's heartbeat, after it has handled statuses, counts no rejected input.
#include <cmath>
#include <mutex>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <orbed/guidance_t.hpp>
#include <orbed/iiwa_command_t.hpp>
#include <orbed/iiwa_status_t.hpp>

#include "base/units.h"
#include "lcmtypes/contract/conversions.h"
#include "tests/integration/testbed_util.h"

namespace orbed::testing {
namespace {

const std::vector<double> kTargetDeg = {20, 30, 0, -60, 0, 45, 0};
constexpr double kToleranceDeg = 0.5;

class GuidanceWatcher {
 public:
  explicit GuidanceWatcher(BusWatcher* bus) {
    bus->lcm().subscribe("GUIDANCE", &GuidanceWatcher::On, this);
    bus->lcm().subscribe("IIWA_STATUS", &GuidanceWatcher::OnStatus, this);
  }
  size_t count() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return seen_.size();
  }
  bool Latest(orbed::guidance_t* out) const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (seen_.empty()) return false;
    *out = seen_.back();
    return true;
  }
  bool LatestStatus(orbed::iiwa_status_t* out) const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!have_status_) return false;
    *out = status_;
    return true;
  }

 private:
  void On(const lcm::ReceiveBuffer*, const std::string&, const orbed::guidance_t* msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    seen_.push_back(*msg);
  }
  void OnStatus(const lcm::ReceiveBuffer*, const std::string&, const orbed::iiwa_status_t* msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    status_ = *msg;
    have_status_ = true;
  }
  mutable std::mutex mutex_;
  std::vector<orbed::guidance_t> seen_;
  orbed::iiwa_status_t status_{};
  bool have_status_{false};
};

void Command(lcm::LCM* lcm, const std::vector<double>& q_deg) {
  orbed::iiwa_command_t command{};
  command.utime = NowMicros();
  command.num_joints = 7;
  for (double q : q_deg) command.joint_position.push_back(q * kDegToRad);
  command.num_torques = 0;
  lcm->publish("IIWA_COMMAND", &command);
}

// Re-sends the command (the sim refuses commands older than 1 s) until `condition` holds.
bool CommandUntil(lcm::LCM* lcm, const std::vector<double>& q_deg, const std::function<bool()>& condition,
                  double timeout_s) {
  return WaitFor(
      [&] {
        Command(lcm, q_deg);
        return condition();
      },
      timeout_s);
}

TEST(Guidance, LeadsTheArmJointByJointToDone) {
  BusWatcher bus;
  GuidanceWatcher guidance(&bus);
  bus.Start();
  lcm::LCM publisher;
  ASSERT_TRUE(publisher.good());
  std::string target;
  for (double q : kTargetDeg) target += (target.empty() ? "" : ",") + std::to_string(q);
  RunningProcess sim({BinPath("orbed-iiwa-sim")});
  RunningProcess guide({BinPath("orbed-guidance"), "--target-deg", target, "--tolerance-deg",
                        std::to_string(kToleranceDeg), "--mode", "ar_reflective"});

  orbed::guidance_t g{};
  ASSERT_TRUE(WaitFor([&] { return guidance.Latest(&g); }, 30)) << "no GUIDANCE";
  EXPECT_EQ(g.mode, int{orbed::guidance_t::MODE_AR_REFLECTIVE});
  EXPECT_EQ(g.next_joint, 0);
  EXPECT_NEAR(g.error_deg[0], -20.0, 0.01);
  EXPECT_FALSE(g.done);

  // Joint 1 to its target, the others where they are (0): joint 2 is next.
  EXPECT_TRUE(CommandUntil(
      &publisher, {20, 0, 0, 0, 0, 0, 0}, [&] { return guidance.Latest(&g) && g.next_joint == 1; }, 60))
      << "next_joint " << g.next_joint;
  EXPECT_NEAR(g.error_deg[1], -30.0, 0.01);

  // The whole target: done.
  EXPECT_TRUE(CommandUntil(
      &publisher, kTargetDeg, [&] { return guidance.Latest(&g) && g.done; }, 60));
  EXPECT_EQ(g.next_joint, -1);
  // At rest on the target (the measured joints are the commanded ones), two GUIDANCE later: its
  // errors are the status's measured joints minus the target.
  orbed::iiwa_status_t status{};
  ASSERT_TRUE(WaitFor(
      [&] {
        if (!guidance.LatestStatus(&status) || status.joint_position_measured.size() != 7) return false;
        for (int i = 0; i < 7; ++i) {
          if (std::abs(status.joint_position_measured[i] - kTargetDeg[i] * kDegToRad) > 1e-9) return false;
        }
        return true;
      },
      30));
  const size_t at_rest = guidance.count();
  ASSERT_TRUE(WaitFor([&] { return guidance.count() >= at_rest + 2; }, 10));
  ASSERT_TRUE(guidance.Latest(&g));
  for (int i = 0; i < 7; ++i) {
    EXPECT_NEAR(g.error_deg[i], (status.joint_position_measured[i] - kTargetDeg[i] * kDegToRad) * kRadToDeg,
                1e-9)
        << "joint " << i + 1;
    EXPECT_NEAR(g.target_position[i], kTargetDeg[i] * kDegToRad, 1e-12);
  }
  EXPECT_TRUE(g.done);

  // A heartbeat sent after the guidance had handled statuses: nothing rejected.
  ASSERT_TRUE(WaitFor(
      [&] {
        const auto beats = bus.Heartbeats("orbed-guidance");
        return !beats.empty() && beats.back().status.messages_in > 0;
      },
      10));
  EXPECT_EQ(bus.Heartbeats("orbed-guidance").back().status.rejected_inputs, 0);
}

}  // namespace
}  // namespace orbed::testing
