// orbed-igtl-bridge beside the real orbed-iiwa-sim over real LCM, in a private network namespace,
// seen through OpenIGTLink the way 3D Slicer sees it:
//   - a client on the OpenIGTLink library's own socket receives TRANSFORMs (CRC checked by the
//     library) whose millimetres equal ROBOT_STATE's X_WR and the model's forward kinematics at
//     ROBOT_STATE's joints; a STATUS for orbed-iiwa-sim with code OK; and, for a JPEG published on
//     HMD_CAMERA by the test, an IMAGE of its size whose RGB pixels are its colour;
//   - a TRANSFORM the client sends comes out on IGTL_TARGET in metres;
//   - the library's example ReceiveClient (built from Debian's openigtlink-examples sources) reads
//     TRANSFORM and STATUS messages from the bridge;
//   - the library's example TrackerClient's TRANSFORMs (a circle of 50 mm radius with x = z) come
//     out on IGTL_TARGET as such, and the bridge refuses none of them;
//   - a "Trocar" TRANSFORM planned in Slicer becomes orbed-guidance's target: the GUIDANCE target's
//     forward kinematics puts the tool tip at the sent point and the tool axis along its z.
#include <cmath>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <igtlClientSocket.h>
#include <igtlImageMessage.h>
#include <igtlMessageHeader.h>
#include <igtlStatusMessage.h>
#include <igtlTransformMessage.h>
#include <lcm/lcm-cpp.hpp>
#include <opencv2/imgcodecs.hpp>
#include <orbed/guidance_t.hpp>
#include <orbed/image_t.hpp>
#include <orbed/robot_state_t.hpp>
#include <orbed/target_pose_t.hpp>

#include "lcmtypes/contract/conversions.h"
#include "sim/robot_model.h"
#include "sim/scene.h"
#include "tests/integration/testbed_util.h"

namespace orbed::testing {
namespace {

constexpr int kPort = 18944;  // Slicer's default; the namespace is the test's own

class Watcher {
 public:
  explicit Watcher(BusWatcher* bus) {
    bus->lcm().subscribe("ROBOT_STATE", &Watcher::OnState, this);
    bus->lcm().subscribe("IGTL_TARGET", &Watcher::OnTarget, this);
    bus->lcm().subscribe("GUIDANCE", &Watcher::OnGuidance, this);
  }
  bool Guidance(orbed::guidance_t* out) const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!have_guidance_) return false;
    *out = guidance_;
    return true;
  }
  bool State(orbed::robot_state_t* out) const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!have_state_) return false;
    *out = state_;
    return true;
  }
  std::vector<orbed::target_pose_t> Targets(const std::string& name) const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<orbed::target_pose_t> out;
    for (const auto& t : targets_)
      if (t.name == name) out.push_back(t);
    return out;
  }

 private:
  void OnState(const lcm::ReceiveBuffer*, const std::string&, const orbed::robot_state_t* msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    state_ = *msg;
    have_state_ = true;
  }
  void OnTarget(const lcm::ReceiveBuffer*, const std::string&, const orbed::target_pose_t* msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    targets_.push_back(*msg);
  }
  void OnGuidance(const lcm::ReceiveBuffer*, const std::string&, const orbed::guidance_t* msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    guidance_ = *msg;
    have_guidance_ = true;
  }
  mutable std::mutex mutex_;
  orbed::guidance_t guidance_{};
  bool have_guidance_{false};
  orbed::robot_state_t state_{};
  bool have_state_{false};
  std::vector<orbed::target_pose_t> targets_;
};

// One message as the library reads it: its header, and its whole packed bytes.
struct Received {
  std::string type, device;
  std::vector<uint8_t> body;
  igtl::MessageHeader::Pointer header;
};

bool ReceiveOne(igtl::ClientSocket* socket, Received* out) {
  out->header = igtl::MessageHeader::New();
  out->header->InitPack();
  if (socket->Receive(out->header->GetPackPointer(), out->header->GetPackSize()) !=
      out->header->GetPackSize())
    return false;
  out->header->Unpack();
  out->type = out->header->GetDeviceType();
  out->device = out->header->GetDeviceName();
  out->body.resize(static_cast<size_t>(out->header->GetBodySizeToRead()));
  return out->body.empty() || socket->Receive(out->body.data(), static_cast<int>(out->body.size())) ==
                                  static_cast<int>(out->body.size());
}

// Unpacks a received message into `msg` with the library's CRC check.
template <class Pointer>
bool Unpack(const Received& r, Pointer& msg) {
  msg->SetMessageHeader(r.header);
  msg->AllocatePack();
  std::memcpy(msg->GetPackBodyPointer(), r.body.data(), r.body.size());
  return msg->Unpack(1) & igtl::MessageHeader::UNPACK_BODY;
}

TEST(IgtlBridge, SlicersViewOfTheTestbedAndTargetsBack) {
  BusWatcher bus;
  Watcher watcher(&bus);
  bus.Start();
  lcm::LCM publisher;
  ASSERT_TRUE(publisher.good());
  RunningProcess sim({BinPath("orbed-iiwa-sim")});
  RunningProcess bridge({BinPath("orbed-igtl-bridge"), "--port", std::to_string(kPort), "--image-hz", "50"});
  orbed::robot_state_t state{};
  ASSERT_TRUE(WaitFor([&] { return watcher.State(&state); }, 30)) << "no ROBOT_STATE";

  igtl::ClientSocket::Pointer client;
  ASSERT_TRUE(WaitFor(
      [&] {
        client = igtl::ClientSocket::New();
        return client->ConnectToServer("127.0.0.1", kPort) == 0;
      },
      30))
      << "the bridge does not listen on " << kPort;
  client->SetReceiveTimeout(20000);

  // TRANSFORMs and a STATUS: read until the flange, the base and the sim's status have come.
  const sim::RobotModel model = sim::RobotModel::LoadFile(SourcePath("sim/models/iiwa7.urdf"));
  const int ee = model.FindLink("iiwa_link_ee");
  bool have_ee = false, have_base = false, have_status = false;
  for (int i = 0; i < 2000 && !(have_ee && have_base && have_status); ++i) {
    Received r;
    ASSERT_TRUE(ReceiveOne(client, &r)) << "message " << i;
    if (r.type == "TRANSFORM" && (r.device == "iiwa_link_ee" || r.device == "RobotBase")) {
      igtl::TransformMessage::Pointer msg = igtl::TransformMessage::New();
      ASSERT_TRUE(Unpack(r, msg)) << "CRC";
      igtl::Matrix4x4 m;
      msg->GetMatrix(m);
      ASSERT_TRUE(watcher.State(&state));  // the arm does not move: any state is the one sent
      const Eigen::Isometry3d X_WR = FromPose(state.X_WR);
      const Eigen::Isometry3d X_WL =
          r.device == "RobotBase" ? X_WR : X_WR * model.CalcLinkPoses(ToVectorX(state.joint_position))[ee];
      for (int row = 0; row < 3; ++row) {
        for (int col = 0; col < 3; ++col) EXPECT_NEAR(m[row][col], X_WL.linear()(row, col), 1e-6);
        EXPECT_NEAR(m[row][3], X_WL.translation()(row) * 1000.0, 1e-3) << r.device << " row " << row;
      }
      (r.device == "RobotBase" ? have_base : have_ee) = true;
    }
    if (r.type == "STATUS" && r.device == "orbed-iiwa-sim") {
      igtl::StatusMessage::Pointer msg = igtl::StatusMessage::New();
      ASSERT_TRUE(Unpack(r, msg));
      EXPECT_EQ(msg->GetCode(), igtl::StatusMessage::STATUS_OK) << msg->GetErrorName();
      EXPECT_STREQ(msg->GetErrorName(), "RUNNING");
      have_status = true;
    }
  }
  EXPECT_TRUE(have_ee && have_base && have_status) << have_ee << have_base << have_status;

  // An image on HMD_CAMERA (published here, a uniform BGR (30, 60, 90) JPEG) comes as an RGB IMAGE.
  orbed::image_t image{};
  image.width = 64;
  image.height = 48;
  image.pixel_format = orbed::image_t::FORMAT_JPEG;
  image.fx_px = image.fy_px = 500;
  image.cx_px = 32;
  image.cy_px = 24;
  image.X_WC.quaternion_wxyz[0] = 1;
  std::vector<uint8_t> jpeg;
  cv::imencode(".jpg", cv::Mat(48, 64, CV_8UC3, cv::Scalar(30, 60, 90)), jpeg);
  image.data = jpeg;
  image.num_bytes = static_cast<int32_t>(jpeg.size());
  bool have_image = false;
  for (int i = 0; i < 5000 && !have_image; ++i) {
    image.utime = NowMicros();
    publisher.publish("HMD_CAMERA", &image);
    Received r;
    ASSERT_TRUE(ReceiveOne(client, &r));
    if (r.type != "IMAGE") continue;
    EXPECT_EQ(r.device, "HMDCamera");
    igtl::ImageMessage::Pointer msg = igtl::ImageMessage::New();
    ASSERT_TRUE(Unpack(r, msg));
    int size[3];
    msg->GetDimensions(size);
    EXPECT_EQ(size[0], 64);
    EXPECT_EQ(size[1], 48);
    EXPECT_EQ(msg->GetNumComponents(), 3);
    const auto* rgb = static_cast<const uint8_t*>(msg->GetScalarPointer());
    EXPECT_NEAR(rgb[0], 90, 3);  // R (JPEG is lossy by a grey level or two)
    EXPECT_NEAR(rgb[1], 60, 3);
    EXPECT_NEAR(rgb[2], 30, 3);
    have_image = true;
  }
  EXPECT_TRUE(have_image);

  // A TRANSFORM from the client: on IGTL_TARGET in metres.
  igtl::TransformMessage::Pointer target = igtl::TransformMessage::New();
  target->SetDeviceName("SlicerTarget");
  igtl::Matrix4x4 m;
  igtl::IdentityMatrix(m);
  m[0][3] = 120.0f;
  m[1][3] = -340.0f;
  m[2][3] = 905.5f;
  target->SetMatrix(m);
  target->Pack();
  ASSERT_EQ(client->Send(target->GetPackPointer(), target->GetPackSize()), 1);
  ASSERT_TRUE(WaitFor([&] { return !watcher.Targets("SlicerTarget").empty(); }, 30)) << "no IGTL_TARGET";
  const orbed::target_pose_t t = watcher.Targets("SlicerTarget")[0];
  EXPECT_EQ(t.source, "igtl");
  EXPECT_NEAR(t.X_WT.position_m[0], 0.120, 1e-6);
  EXPECT_NEAR(t.X_WT.position_m[1], -0.340, 1e-6);
  EXPECT_NEAR(t.X_WT.position_m[2], 0.9055, 1e-6);
  EXPECT_NEAR(t.X_WT.quaternion_wxyz[0], 1.0, 1e-9);

  // The library's own example receiver.
  const std::string dir = MakeTempDir("igtl");
  const std::string printed = dir + "/receive_client.txt";
  const auto text = [&printed] {
    std::ifstream in(printed);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  {
    RunningProcess receiver({"/bin/sh", "-c",
                             std::string("exec '") + ORBED_IGTL_RECEIVE_CLIENT + "' 127.0.0.1 " +
                                 std::to_string(kPort) + " 2>'" + printed + "'"});
    EXPECT_TRUE(WaitFor(
        [&] {
          const std::string s = text();
          return s.find("Receiving TRANSFORM data type.") != std::string::npos &&
                 s.find("Receiving STATUS data type.") != std::string::npos;
        },
        60))
        << text().substr(0, 2000);
  }
  EXPECT_NE(text().find(" Code      : 1"), std::string::npos);  // a RUNNING process: STATUS_OK

  // The library's own example tracker: TRANSFORMs on a circle of 50 mm with x = z.
  {
    RunningProcess tracker({ORBED_IGTL_TRACKER_CLIENT, "127.0.0.1", std::to_string(kPort), "20"});
    ASSERT_TRUE(WaitFor([&] { return watcher.Targets("Tracker").size() >= 5; }, 60));
  }
  for (const orbed::target_pose_t& p : watcher.Targets("Tracker")) {
    const double* x = p.X_WT.position_m;
    EXPECT_NEAR(x[0], x[2], 1e-6);
    EXPECT_NEAR(std::hypot(x[0], x[1]), 0.050, 1e-6);
  }
  const auto beats = bus.Heartbeats("orbed-igtl-bridge");
  ASSERT_FALSE(beats.empty());
  EXPECT_EQ(beats.back().status.rejected_inputs, 0);
}

TEST(IgtlBridge, ATrocarPlannedInSlicerBecomesTheGuidanceTarget) {
  BusWatcher bus;
  Watcher watcher(&bus);
  bus.Start();
  RunningProcess sim({BinPath("orbed-iiwa-sim")});
  RunningProcess bridge({BinPath("orbed-igtl-bridge"), "--port", std::to_string(kPort)});
  RunningProcess guidance({BinPath("orbed-guidance")});  // no target until one comes
  igtl::ClientSocket::Pointer client;
  ASSERT_TRUE(WaitFor(
      [&] {
        client = igtl::ClientSocket::New();
        return client->ConnectToServer("127.0.0.1", kPort) == 0;
      },
      30));

  // A trocar 3 cm beside the scene's, tilted 10 degrees about x: tip at its origin, axis along z.
  const sim::Scene scene = sim::LoadSceneFile(SourcePath("sim/models/scenes/trocar_or.yaml"));
  const Eigen::Vector3d p_WT = scene.trocar.p_WT + Eigen::Vector3d(0.03, 0, 0);
  const Eigen::Vector3d axis_W =
      Eigen::AngleAxisd(10 * M_PI / 180, Eigen::Vector3d::UnitX()) * scene.trocar.insertion_direction_W;
  const Eigen::Matrix3d R_WT =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis_W).toRotationMatrix();
  igtl::TransformMessage::Pointer trocar = igtl::TransformMessage::New();
  trocar->SetDeviceName("Trocar");
  igtl::Matrix4x4 m;
  igtl::IdentityMatrix(m);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m[r][c] = static_cast<float>(R_WT(r, c));
    m[r][3] = static_cast<float>(p_WT(r) * 1000.0);
  }
  trocar->SetMatrix(m);
  trocar->Pack();
  ASSERT_EQ(client->Send(trocar->GetPackPointer(), trocar->GetPackSize()), 1);

  orbed::guidance_t g{};
  ASSERT_TRUE(WaitFor([&] { return watcher.Guidance(&g); }, 60)) << "no GUIDANCE from the Slicer target";
  const sim::RobotModel model =
      sim::LoadRobotForScene(SourcePath("sim/models/iiwa7.urdf"), scene);  // with the scene's tool
  const Eigen::Isometry3d X_WT = scene.X_WR * model.CalcToolTipPose(ToVectorX(g.target_position));
  // The sent pose went through 32-bit floats (in mm): about 1e-4 mm and 1e-7 rad.
  EXPECT_LT((X_WT.translation() - p_WT).norm(), 1e-4) << X_WT.translation().transpose();
  EXPECT_LT(std::acos(std::min(1.0, X_WT.linear().col(2).dot(axis_W.normalized()))), 1e-3);
}

}  // namespace
}  // namespace orbed::testing
