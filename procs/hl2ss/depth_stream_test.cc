// The depth stream without sockets or bus: inputs refused with their field's class, the mode-2
// answer, one render per frame for every client due (divisors), the packets' framing, stamp and
// mode-1 pose (RigNodePoseForClient of the estimate, not of the truth), the robot drawn only once
// its joints and base are both known.
#include "procs/hl2ss/depth_stream.h"

#include <cmath>
#include <cstring>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "geometry/camera_model.h"
#include "lcmtypes/contract/conversions.h"
#include "procs/hl2ss/frames.h"

namespace orbed::hl2ss {
namespace {

constexpr double kWaitS = 20.0;  // generous: the worker renders in milliseconds

class DepthStreamTest : public ::testing::Test {
 protected:
  DepthStreamTest() : stream_(Options(), TimeBase{1'000'000}) {
    X_WR_.translation() = Eigen::Vector3d(1.0, 0.5, 0.75);
  }
  static DepthStreamOptions Options() {
    DepthStreamOptions o;
    o.scene_path = "none";  // the robot alone: everything else is out of range
    return o;
  }
  orbed::hmd_pose_t Head(const Eigen::Isometry3d& X_WH, int64_t utime) const {
    orbed::hmd_pose_t m{};
    m.utime = utime;
    m.hmd_name = "hmd";
    m.X_WH = ToPose(X_WH);
    m.X_WC = m.X_WH;
    m.tracking_state = orbed::hmd_pose_t::TRACKING;
    return m;
  }
  orbed::iiwa_status_t Joints(int n) const {
    orbed::iiwa_status_t m{};
    m.num_joints = n;
    for (auto* v : {&m.joint_position_measured, &m.joint_velocity_estimated, &m.joint_position_commanded,
                    &m.joint_position_ipo, &m.joint_torque_measured, &m.joint_torque_commanded,
                    &m.joint_torque_external})
      v->assign(n, 0.0);
    return m;
  }
  orbed::robot_state_t Base() const {
    orbed::robot_state_t m{};
    m.X_WR = ToPose(X_WR_);
    return m;
  }
  // A head whose depth camera is 1.5 m from the base's axis, looking at it.
  Eigen::Isometry3d HeadLookingAtBase() const {
    const Eigen::Vector3d axis = X_WR_ * Eigen::Vector3d(0, 0, 0.075);
    return geometry::LookAt(axis + Eigen::Vector3d(-1.5, 0, 0.2), axis) *
           LongThrowOptions::DefaultX_HZ().inverse();
  }
  // The depth picture of a packet (hl2ss.py's decoding: PNG then the u64 sensor ticks).
  static cv::Mat Depth(const std::vector<uint8_t>& packet, bool mode1) {
    const uint32_t size = GetU32(packet.data() + 8);
    EXPECT_EQ(packet.size(), kHeaderBytes + size + (mode1 ? kPoseBytes : 0));
    const cv::Mat png(1, static_cast<int>(size - 8), CV_8UC1,
                      const_cast<uint8_t*>(packet.data() + kHeaderBytes));
    const cv::Mat bgra = cv::imdecode(png, cv::IMREAD_UNCHANGED);
    return cv::Mat(kLongThrowHeight, kLongThrowWidth, CV_16UC1, const_cast<uint8_t*>(bgra.data)).clone();
  }
  DepthPackets Frame(int64_t now_us) {
    EXPECT_FALSE(stream_.Tick(now_us));
    EXPECT_TRUE(stream_.WaitReady(kWaitS));
    std::optional<DepthPackets> p = stream_.TakeReady();
    EXPECT_TRUE(p.has_value());
    return p ? *p : DepthPackets{};
  }

  Eigen::Isometry3d X_WR_{Eigen::Isometry3d::Identity()};
  DepthStream stream_;
};

TEST_F(DepthStreamTest, BadInputsAreRefusedWithTheirClass) {
  const int n = stream_.robot().num_joints();
  ASSERT_EQ(n, 7);
  EXPECT_EQ(stream_.OnJoints(Joints(6))->key, "num_joints");
  orbed::iiwa_status_t far = Joints(n);
  far.joint_position_measured[1] = 3.0;  // beyond A2's ±120°
  EXPECT_EQ(stream_.OnJoints(far)->key, "limits");
  EXPECT_FALSE(stream_.OnJoints(Joints(n)));
  orbed::robot_state_t base = Base();
  base.X_WR.position_m[0] = NAN;
  EXPECT_EQ(stream_.OnRobotState(base)->key, "pose");
  orbed::hmd_pose_t head = Head(HeadLookingAtBase(), 2'000'000);
  head.X_WH.quaternion_wxyz[0] = 3.0;  // not a unit quaternion
  EXPECT_EQ(stream_.OnTruth(head, 0)->key, "field");
}

TEST_F(DepthStreamTest, ModeTwoAnswersTheCalibration) {
  RmDepthLongThrowConfig c;
  c.mode = kMode2;
  const Decision d = stream_.Configure(7, c);
  EXPECT_EQ(d.kind, Decision::kReplyAndClose);
  EXPECT_EQ(d.reply, PackLongThrowCalibration(LongThrowOptions{}));
}

TEST_F(DepthStreamTest, OneRenderPerFrameForEveryClientDue) {
  RmDepthLongThrowConfig every, second;
  every.mode = kMode1;
  second.mode = kMode0;
  second.divisor = 2;
  EXPECT_EQ(stream_.Configure(1, every).kind, Decision::kServe);
  EXPECT_EQ(stream_.Configure(2, second).kind, Decision::kServe);
  EXPECT_FALSE(stream_.Tick(0));  // no head yet: nothing rendered
  EXPECT_FALSE(stream_.TakeReady());

  // The truth and a different estimate; the robot's joints only (its base unknown: not drawn).
  const Eigen::Isometry3d X_WH_true = HeadLookingAtBase();
  Eigen::Isometry3d X_WH_est = X_WH_true;
  X_WH_est.translation() += Eigen::Vector3d(0.01, -0.02, 0.03);
  const int64_t utime = 3'000'000;
  ASSERT_FALSE(stream_.OnTruth(Head(X_WH_true, utime), 0));
  stream_.OnEstimate(X_WH_est, utime);
  ASSERT_FALSE(stream_.OnJoints(Joints(7)));

  DepthPackets f = Frame(1000);
  ASSERT_EQ(f.error, "");
  EXPECT_EQ(f.mode1, std::vector<int>{1});
  EXPECT_EQ(f.mode0, std::vector<int>{2});
  EXPECT_EQ(f.stamp, 20'000'000u);  // (3 s − 1 s) in 100 ns ticks
  EXPECT_EQ(GetU64(f.packet1.data()), f.stamp);
  EXPECT_EQ(GetU64(f.packet0.data()), f.stamp);
  EXPECT_EQ(cv::countNonZero(Depth(f.packet1, true)), 0) << "no robot drawn before ROBOT_STATE";
  const std::array<float, 16> pose = PoseMatrixRowMajor(RigNodePoseForClient(X_WH_est, LongThrowOptions{}));
  EXPECT_EQ(std::memcmp(f.packet1.data() + f.packet1.size() - kPoseBytes, pose.data(), kPoseBytes), 0);

  ASSERT_FALSE(stream_.OnRobotState(Base()));
  f = Frame(2000);  // the divisor-2 client skips this one
  EXPECT_EQ(f.mode1, std::vector<int>{1});
  EXPECT_TRUE(f.mode0.empty());
  EXPECT_TRUE(f.packet0.empty());
  const cv::Mat depth = Depth(f.packet1, true);
  // The principal pixel looks at the base's axis 1.5 m away horizontally: the base's surface
  // 0.1 m before it, along a ray pitched by atan(0.2 / 1.5).
  const double expected_mm = 1000.0 * (std::hypot(1.5, 0.2) - 0.1 / std::cos(std::atan2(0.2, 1.5)));
  EXPECT_NEAR(depth.at<uint16_t>(144, 160), expected_mm,
              3.0);  // the 24-gon's flat face: within 1 mm + rounding
  f = Frame(3000);
  EXPECT_EQ(f.mode0, std::vector<int>{2});
  EXPECT_EQ(stream_.frames_rendered(), 3);

  // A newer truth whose estimate has not come: the frame is the older pair's (stamp and pose).
  Eigen::Isometry3d X_WH_later = X_WH_true;
  X_WH_later.translation().x() += 0.05;
  ASSERT_FALSE(stream_.OnTruth(Head(X_WH_later, utime + 16'667), 3000));
  f = Frame(4000);
  EXPECT_EQ(f.stamp, 20'000'000u);
  EXPECT_EQ(std::memcmp(f.packet1.data() + f.packet1.size() - kPoseBytes, pose.data(), kPoseBytes), 0);
  Eigen::Isometry3d X_WH_later_est = X_WH_est;
  X_WH_later_est.translation().x() += 0.05;
  stream_.OnEstimate(X_WH_later_est, utime + 16'667);  // its estimate comes: the newer pair
  f = Frame(5000);
  EXPECT_EQ(f.stamp, 20'166'670u);
  const std::array<float, 16> later =
      PoseMatrixRowMajor(RigNodePoseForClient(X_WH_later_est, LongThrowOptions{}));
  EXPECT_EQ(std::memcmp(f.packet1.data() + f.packet1.size() - kPoseBytes, later.data(), kPoseBytes), 0);

  stream_.Disconnected(1);
  stream_.Disconnected(2);
  EXPECT_FALSE(stream_.Tick(6000));
  EXPECT_FALSE(stream_.TakeReady());
  EXPECT_EQ(stream_.frames_rendered(), 5);
}

TEST_F(DepthStreamTest, AStaleHeadRendersNothing) {
  RmDepthLongThrowConfig c;
  stream_.Configure(1, c);
  ASSERT_FALSE(stream_.OnTruth(Head(HeadLookingAtBase(), 2'000'000), 0));
  EXPECT_FALSE(stream_.Tick(600'000));  // 0.6 s after it arrived: older than stale_s
  EXPECT_FALSE(stream_.TakeReady());
  EXPECT_EQ(stream_.frames_rendered(), 0);
  EXPECT_FALSE(stream_.Tick(400'000));  // 0.4 s: rendered
  EXPECT_TRUE(stream_.WaitReady(kWaitS));
}

}  // namespace
}  // namespace orbed::hl2ss
