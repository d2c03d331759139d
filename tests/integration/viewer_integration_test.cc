// orbed-drake-viewer beside the real sim over real LCM, in a private network namespace, read with
// Drake's own message definitions (restated in tests/drake, generated apart from orbed's): the load
// message lists both robots' links and the scene's objects; a draw message's real-robot link poses
// equal ROBOT_STATE's X_WR · X_RL for the arm at rest; with a registration published, the virtual
// robot's base link sits at its X_WV.
#include <cmath>
#include <mutex>
#include <optional>
#include <string>

#include <gtest/gtest.h>
#include <drake/lcmt_viewer_draw.hpp>
#include <drake/lcmt_viewer_load_robot.hpp>
#include <lcm/lcm-cpp.hpp>
#include <orbed/registration_t.hpp>
#include <orbed/robot_state_t.hpp>

#include "lcmtypes/contract/conversions.h"
#include "tests/integration/testbed_util.h"

namespace orbed::testing {
namespace {

class ViewerWatcher {
 public:
  explicit ViewerWatcher(BusWatcher* bus) {
    bus->lcm().subscribe("DRAKE_VIEWER_LOAD_ROBOT", &ViewerWatcher::OnLoad, this);
    bus->lcm().subscribe("DRAKE_VIEWER_DRAW", &ViewerWatcher::OnDraw, this);
    bus->lcm().subscribe("ROBOT_STATE", &ViewerWatcher::OnState, this);
  }
  template <class T>
  bool Get(const std::optional<T>& source, T* out) const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!source) return false;
    *out = *source;
    return true;
  }
  std::optional<drake::lcmt_viewer_load_robot> load;
  std::optional<drake::lcmt_viewer_draw> draw;
  std::optional<orbed::robot_state_t> state;

 private:
  void OnLoad(const lcm::ReceiveBuffer*, const std::string&, const drake::lcmt_viewer_load_robot* m) {
    std::lock_guard<std::mutex> lock(mutex_);
    load = *m;
  }
  void OnDraw(const lcm::ReceiveBuffer*, const std::string&, const drake::lcmt_viewer_draw* m) {
    std::lock_guard<std::mutex> lock(mutex_);
    draw = *m;
  }
  void OnState(const lcm::ReceiveBuffer*, const std::string&, const orbed::robot_state_t* m) {
    std::lock_guard<std::mutex> lock(mutex_);
    state = *m;
  }
  mutable std::mutex mutex_;
};

int Find(const drake::lcmt_viewer_draw& d, const std::string& name, int robot) {
  for (int i = 0; i < d.num_links; ++i) {
    if (d.link_name[i] == name && d.robot_num[i] == robot) return i;
  }
  return -1;
}

TEST(DrakeViewer, DrawsTheSimsArmAndTheRegistrationForDrakesReaders) {
  BusWatcher bus;
  ViewerWatcher watch(&bus);
  bus.Start();
  lcm::LCM publisher;
  ASSERT_TRUE(publisher.good());
  RunningProcess sim({BinPath("orbed-iiwa-sim"), "--initial-q-deg", "10,30,0,-60,0,45,0"});
  RunningProcess viewer({BinPath("orbed-drake-viewer"), "--load-period-s", "0.5"});

  drake::lcmt_viewer_load_robot load;
  ASSERT_TRUE(WaitFor([&] { return watch.Get(watch.load, &load); }, 30)) << "no DRAKE_VIEWER_LOAD_ROBOT";
  int real = 0, virtual_links = 0, scene = 0;
  for (const auto& link : load.link)
    (link.robot_num == 0 ? real : link.robot_num == 1 ? virtual_links : scene)++;
  EXPECT_EQ(real, virtual_links);
  EXPECT_GE(real, 8);  // iiwa_link_0 ... 7 and more
  EXPECT_GT(scene, 0);

  // A draw made after a ROBOT_STATE of the arm at rest: the real links are where the sim says.
  orbed::robot_state_t state{};
  drake::lcmt_viewer_draw draw;
  ASSERT_TRUE(WaitFor([&] { return watch.Get(watch.state, &state) && watch.Get(watch.draw, &draw); }, 30));
  ASSERT_TRUE(
      WaitFor([&] { return watch.Get(watch.draw, &draw) && draw.timestamp > state.utime / 1000 + 50; }, 30));
  const Eigen::Isometry3d X_WR = FromPose(state.X_WR);
  for (int k = 0; k < state.num_links; ++k) {
    const int i = Find(draw, state.link_names[k], 0);
    ASSERT_GE(i, 0) << state.link_names[k];
    const Eigen::Vector3d p_W = X_WR * FromPose(state.X_RL[k]).translation();
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(draw.position[i][a], p_W[a], 1e-5) << state.link_names[k];
  }

  // A registration: the virtual base link goes to its X_WV.
  orbed::registration_t reg{};
  reg.utime = NowMicros();
  reg.session_id = "viewer-test";
  reg.valid = true;
  reg.X_WV_mean = state.X_WR;
  reg.X_WV_mean.position_m[0] += 0.2;
  ASSERT_TRUE(WaitFor(
      [&] {
        publisher.publish("REGISTRATION", &reg);
        if (!watch.Get(watch.draw, &draw)) return false;
        const int i = Find(draw, "iiwa_link_0", 1);
        return i >= 0 && std::abs(draw.position[i][0] - reg.X_WV_mean.position_m[0]) < 1e-5;
      },
      30));
  ASSERT_TRUE(WaitFor(
      [&] {
        const auto beats = bus.Heartbeats("orbed-drake-viewer");
        return !beats.empty() && beats.back().status.messages_in > 0;
      },
      10));
  EXPECT_EQ(bus.Heartbeats("orbed-drake-viewer").back().status.rejected_inputs, 0);
}

}  // namespace
}  // namespace orbed::testing
