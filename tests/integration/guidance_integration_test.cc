// orbed-guidance beside the real orbed-iiwa-sim over real LCM, in a private network namespace:
// the test plays the assistant, moving the arm with IIWA_COMMAND as the guidance says, joint by joint.
//   - at the start (arm at 0) GUIDANCE names joint 1, its error (current − target) is −20 deg;
//   - with joint 1 brought to its target, the next joint named is joint 2;
//   - with the whole target commanded, GUIDANCE says done, every error within the tolerance, and
//     the errors equal IIWA_STATUS's measured joints minus the target;
//   - the guidance rejected nothing.
#include <cmath>
#include <mutex>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <orbed/guidance_t.hpp>
#include <orbed/iiwa_command_t.hpp>

#include "base/units.h"
#include "procs/common/conversions.h"
#include "tests/integration/testbed_util.h"

namespace orbed::testing {
namespace {

const std::vector<double> kTargetDeg = {20, 30, 0, -60, 0, 45, 0};
constexpr double kToleranceDeg = 0.5;

class GuidanceWatcher {
 public:
  explicit GuidanceWatcher(BusWatcher* bus) { bus->lcm().subscribe("GUIDANCE", &GuidanceWatcher::On, this); }
  std::vector<orbed::guidance_t> seen() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return seen_;
  }
  bool Latest(orbed::guidance_t* out) const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (seen_.empty()) return false;
    *out = seen_.back();
    return true;
  }

 private:
  void On(const lcm::ReceiveBuffer*, const std::string&, const orbed::guidance_t* msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    seen_.push_back(*msg);
  }
  mutable std::mutex mutex_;
  std::vector<orbed::guidance_t> seen_;
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
  for (int i = 0; i < 7; ++i) {
    EXPECT_LE(std::abs(g.error_deg[i]), kToleranceDeg) << "joint " << i + 1;
    EXPECT_NEAR(g.error_deg[i], (g.current_position[i] - g.target_position[i]) * kRadToDeg, 1e-9);
    EXPECT_NEAR(g.target_position[i], kTargetDeg[i] * kDegToRad, 1e-12);
  }
  EXPECT_EQ(g.next_joint, -1);

  ASSERT_TRUE(WaitFor([&] { return !bus.Heartbeats("orbed-guidance").empty(); }, 10));
  EXPECT_EQ(bus.Heartbeats("orbed-guidance").back().status.rejected_inputs, 0);
}

}  // namespace
}  // namespace orbed::testing
