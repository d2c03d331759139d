// orbed-foxglove-bridge beside the real orbed-iiwa-sim over real LCM, in a private network namespace,
// read by a client built on Foxglove's own @foxglove/ws-protocol (tests/foxglove/client.test.mjs in
// node's test runner). This side writes what the bus says into the file the client checks against:
// ROBOT_STATE's X_WR, the model's forward kinematics of its joints to iiwa_link_ee, the JPEG it
// publishes on HMD_CAMERA (the client compares the image bytes exactly), a scene object's name, and
// the fixed monitor's picture and camera pose as orbed-fixed-display put them on FIXED_VIEW. The
// client must see them on /tf, /hmd/camera, /fixed_view and /scene and exit 0; and the same
// (without the monitor) from a log replayed through the bridge by LCM's lcm-logplayer.
#include <fstream>
#include <mutex>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <orbed/image_t.hpp>
#include <orbed/robot_state_t.hpp>

#include "lcmtypes/contract/conversions.h"
#include "procs/logger/event_log_writer.h"
#include "sim/robot_model.h"
#include "sim/scene.h"
#include "tests/integration/testbed_util.h"

namespace orbed::testing {
namespace {

// The latest message of one channel.
template <typename Msg>
class LatestWatcher {
 public:
  LatestWatcher(BusWatcher* bus, const std::string& channel) {
    bus->lcm().subscribe(channel, &LatestWatcher::On, this);
  }
  bool Latest(Msg* out) const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!have_) return false;
    *out = msg_;
    return true;
  }

 private:
  void On(const lcm::ReceiveBuffer*, const std::string&, const Msg* msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    msg_ = *msg;
    have_ = true;
  }
  mutable std::mutex mutex_;
  Msg msg_{};
  bool have_{false};
};

void WriteBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), bytes.size());
}

nlohmann::json PoseJson(const Eigen::Isometry3d& X) {
  const Eigen::Quaterniond q(X.linear());
  return {{"translation", {X.translation().x(), X.translation().y(), X.translation().z()}},
          {"rotation", {q.x(), q.y(), q.z(), q.w()}}};
}

TEST(FoxgloveBridge, FoxglovesOwnClientSeesTheTestbed) {
  BusWatcher bus;
  LatestWatcher<orbed::robot_state_t> watcher(&bus, "ROBOT_STATE");
  LatestWatcher<orbed::image_t> fixed_views(&bus, "FIXED_VIEW");
  bus.Start();
  lcm::LCM publisher;
  ASSERT_TRUE(publisher.good());
  RunningProcess sim({BinPath("orbed-iiwa-sim")});
  RunningProcess bridge({BinPath("orbed-foxglove-bridge"), "--port", "8765", "--image-hz", "20"});
  // The fixed monitor showing a target: its picture does not change while the target, the base
  // and the view stay, so the client must receive these very bytes.
  RunningProcess guidance(
      {BinPath("orbed-guidance"), "--target-deg", "20,40,0,-70,10,50,0", "--mode", "fixed"});
  RunningProcess fixed_display({BinPath("orbed-fixed-display")});
  orbed::robot_state_t state{};
  ASSERT_TRUE(WaitFor([&] { return watcher.Latest(&state); }, 30)) << "no ROBOT_STATE";
  orbed::image_t fixed_view{};
  ASSERT_TRUE(WaitFor([&] { return fixed_views.Latest(&fixed_view); }, 30)) << "no FIXED_VIEW";

  // What the bus says (the arm does not move: this state is the one the bridge sends).
  const sim::RobotModel model = sim::RobotModel::LoadFile(SourcePath("sim/models/iiwa7.urdf"));
  const sim::Scene scene = sim::LoadSceneFile(SourcePath("sim/models/scenes/trocar_or.yaml"));
  ASSERT_FALSE(scene.objects.empty());
  const Eigen::Isometry3d X_R_ee =
      model.CalcLinkPoses(ToVectorX(state.joint_position))[model.FindLink("iiwa_link_ee")];
  const std::string dir = MakeTempDir("foxglove");
  std::vector<uint8_t> jpeg;
  cv::imencode(".jpg", cv::Mat(48, 64, CV_8UC3, cv::Scalar(30, 60, 90)), jpeg);
  WriteBytes(dir + "/camera.jpg", jpeg);
  WriteBytes(dir + "/fixed_view.jpg", fixed_view.data);
  const nlohmann::json expected = {{"X_WR", PoseJson(FromPose(state.X_WR))},
                                   {"X_R_ee", PoseJson(X_R_ee)},
                                   {"jpeg_path", dir + "/camera.jpg"},
                                   {"X_WD", PoseJson(FromPose(fixed_view.X_WC))},
                                   {"fixed_view_jpeg_path", dir + "/fixed_view.jpg"},
                                   {"scene_object", scene.objects[0].name}};
  std::ofstream(dir + "/expected.json") << expected.dump(2);

  orbed::image_t image{};
  image.width = 64;
  image.height = 48;
  image.pixel_format = orbed::image_t::FORMAT_JPEG;
  image.fx_px = image.fy_px = 500;
  image.X_WC.quaternion_wxyz[0] = 1;
  image.data = jpeg;
  image.num_bytes = static_cast<int32_t>(jpeg.size());

  RunningProcess client(
      {ORBED_NODE, "--test", std::string(ORBED_FOXGLOVE_CLIENT_DIR) + "/client.test.mjs"},
      {{"ORBED_EXPECT_JSON", dir + "/expected.json"}, {"ORBED_FOXGLOVE_URL", "ws://127.0.0.1:8765"}});
  // The camera keeps sending while the client runs (it may subscribe at any moment).
  ASSERT_TRUE(WaitFor(
      [&] {
        image.utime = NowMicros();
        publisher.publish("HMD_CAMERA", &image);
        return !client.running();
      },
      120))
      << "the Foxglove client did not finish";
  EXPECT_EQ(client.exit_code(), 0) << "see the client's output above";
  const auto beats = bus.Heartbeats("orbed-foxglove-bridge");
  ASSERT_FALSE(beats.empty());
  EXPECT_EQ(beats.back().status.rejected_inputs, 0);
}

// A recorded session replayed through the bridge: a log written here (ROBOT_STATE at 50 Hz with a
// base and joints of its own, HMD_CAMERA at 10 Hz, 30 s), played by LCM's lcm-logplayer with no
// sim running; the same client must see the log's poses and image.
TEST(FoxgloveBridge, AReplayedLogShowsTheRecordedSession) {
  const sim::RobotModel model = sim::RobotModel::LoadFile(SourcePath("sim/models/iiwa7.urdf"));
  const sim::Scene scene = sim::LoadSceneFile(SourcePath("sim/models/scenes/trocar_or.yaml"));
  orbed::robot_state_t state{};
  Eigen::Isometry3d X_WR = Eigen::Isometry3d::Identity();
  X_WR.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X_WR.translation() = Eigen::Vector3d(0.1, 0.2, 0.3);
  state.X_WR = ToPose(X_WR);
  state.robot_name = "iiwa";
  state.num_joints = 7;
  state.joint_position = {0.5, 0.4, -0.3, -1.2, 0.1, 0.7, 0.2};
  state.joint_limit_hit.assign(7, 0);
  const std::string dir = MakeTempDir("foxglove_replay");
  std::vector<uint8_t> jpeg;
  cv::imencode(".jpg", cv::Mat(24, 32, CV_8UC3, cv::Scalar(200, 100, 50)), jpeg);
  WriteBytes(dir + "/camera.jpg", jpeg);
  orbed::image_t image{};
  image.width = 32;
  image.height = 24;
  image.pixel_format = orbed::image_t::FORMAT_JPEG;
  image.fx_px = image.fy_px = 300;
  image.X_WC.quaternion_wxyz[0] = 1;
  image.data = jpeg;
  image.num_bytes = static_cast<int32_t>(jpeg.size());
  {
    logger::EventLogWriter log(dir + "/session.lcmlog");
    ASSERT_TRUE(log.ok()) << log.error();
    const auto write = [&log](int64_t t_us, const char* channel, const auto& msg) {
      std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
      msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
      log.Write(t_us, channel, bytes.data(), bytes.size());
    };
    const int64_t start_us = 1'700'000'000'000'000;
    for (int i = 0; i < 1500; ++i) {
      state.utime = start_us + i * 20'000;
      write(state.utime, "ROBOT_STATE", state);
      if (i % 5 == 0) {
        image.utime = state.utime;
        write(image.utime, "HMD_CAMERA", image);
      }
    }
  }
  const nlohmann::json expected = {
      {"X_WR", PoseJson(FromPose(state.X_WR))},
      {"X_R_ee",
       PoseJson(model.CalcLinkPoses(ToVectorX(state.joint_position))[model.FindLink("iiwa_link_ee")])},
      {"jpeg_path", dir + "/camera.jpg"},
      {"scene_object", scene.objects[0].name}};
  std::ofstream(dir + "/expected.json") << expected.dump(2);

  BusWatcher bus;
  bus.Start();
  RunningProcess bridge({BinPath("orbed-foxglove-bridge"), "--port", "8765", "--image-hz", "20"});
  RunningProcess player({"/usr/bin/lcm-logplayer", dir + "/session.lcmlog"});
  RunningProcess client(
      {ORBED_NODE, "--test", std::string(ORBED_FOXGLOVE_CLIENT_DIR) + "/client.test.mjs"},
      {{"ORBED_EXPECT_JSON", dir + "/expected.json"}, {"ORBED_FOXGLOVE_URL", "ws://127.0.0.1:8765"}});
  ASSERT_TRUE(client.Wait(120)) << "the Foxglove client did not finish";
  EXPECT_EQ(client.exit_code(), 0) << "see the client's output above";
}

}  // namespace
}  // namespace orbed::testing
