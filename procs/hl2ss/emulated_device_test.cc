// The emulated device's remote-configuration answers against bytes and values computed by hand
// from hl2ss.py's ipc_rc layouts: the fixed answers, the rig node's world poses from the pose
// history (the matrix worked out below), and the long-throw camera's point mapping against its own
// mode-2 uv2xy table.
#include "procs/hl2ss/emulated_device.h"

#include <gtest/gtest.h>

namespace orbed::hl2ss {
namespace {

constexpr int64_t kOrigin = 1'700'000'000'000'000;  // the time base's origin [µs]

std::vector<uint8_t> Hex(const std::string& hex) {
  std::vector<uint8_t> out;
  for (size_t i = 0; i + 1 < hex.size(); i += 2)
    out.push_back(static_cast<uint8_t>(std::stoi(hex.substr(i, 2), nullptr, 16)));
  return out;
}

RcOutcome Answer(EmulatedDevice* device, const std::vector<uint8_t>& bytes, int64_t now_us = 0) {
  const Parsed<RcCommand> p = ParseRcCommand(bytes.data(), bytes.size());
  EXPECT_EQ(p.status, ParseStatus::kDone);
  EXPECT_EQ(p.used, bytes.size());
  return device->HandleRc(p.value, now_us);
}

std::vector<float> Floats(const std::vector<uint8_t>& bytes) {
  std::vector<float> out;
  for (size_t i = 0; i + 4 <= bytes.size(); i += 4) out.push_back(GetF32(bytes.data() + i));
  return out;
}

TEST(EmulatedDevice, AnswersWhatTheClientWaitsFor) {
  EmulatedDevice device(TimeBase{kOrigin}, {1, 2, 3, 4});
  const auto answer = [&](const std::string& hex, int64_t now_us = 0) {
    return Answer(&device, Hex(hex), now_us);
  };
  EXPECT_EQ(answer("00").reply, Hex("0100"
                                    "0200"
                                    "0300"
                                    "0400"));
  EXPECT_EQ(GetU64(answer("01").reply.data()), 133'444'736'000'000'000ULL);
  EXPECT_EQ(answer("03").reply, Hex("00"));
  device.OpenPv(MrcVideoOptions{});
  EXPECT_EQ(answer("03").reply, Hex("01"));
  EXPECT_EQ(GetU64(answer("18"
                          "00000000",
                          kOrigin + 2'000'000)
                       .reply.data()),
            20'000'000u);
  EXPECT_EQ(GetU64(answer("18"
                          "01000000",
                          0)
                       .reply.data()),
            kFiletimeOfUnixEpoch);
  // No pose recorded yet: every timestamp "not located" (16 zeros).
  EXPECT_EQ(answer("17"
                   "03000000"
                   "010000000000000002000000000000000300000000000000")
                .reply,
            std::vector<uint8_t>(3 * 64, 0));
  EXPECT_TRUE(answer("08"
                     "00000000"
                     "e8030000")
                  .reply.empty());
  EXPECT_EQ(device.pv_settings().exposure, (std::array<uint32_t, 2>{0, 1000}));
}

TEST(TimeBase, UtimeOfInvertsTicksOf) {
  const TimeBase tb{kOrigin};
  EXPECT_EQ(tb.UtimeOf(tb.TicksOf(kOrigin + 1'234'567)), kOrigin + 1'234'567);
  EXPECT_EQ(tb.UtimeOf(19), kOrigin + 1);  // 1.9 µs: the µs below
}

// By hand: a head at X_WH = translation (1, 2, 3) with W's axes; the rig node N = H with y and z
// flipped (X_HN = diag(1, −1, −1)); D has x_D = x_W, y_D = z_W, z_D = −y_W, so
// R_DW = [[1 0 0] [0 0 1] [0 −1 0]], p_DN = R_DW·(1, 2, 3) = (1, 3, −2) and
// R_DN = R_DW·diag(1, −1, −1) = [[1 0 0] [0 0 −1] [0 1 0]]. hl2ss sends X_DNᵀ row-major, i.e. the
// columns of X_DN as rows: (1 0 0 0), (0 0 1 0), (0 −1 0 0), (1 3 −2 1).
TEST(EmulatedDevice, RigNodeWorldPosesFromThePoseHistory) {
  EmulatedDevice device(TimeBase{kOrigin}, {1, 0, 0, 0});
  Eigen::Isometry3d X_WH1 = Eigen::Isometry3d::Identity(), X_WH2 = Eigen::Isometry3d::Identity();
  X_WH1.translation() = Eigen::Vector3d(1, 2, 3);
  X_WH2.translation() = Eigen::Vector3d(4, 5, 6);
  device.RecordPose(kOrigin + 1'000'000, X_WH1, true);
  device.RecordPose(kOrigin + 1'016'667, X_WH2, true);
  device.RecordPose(kOrigin + 1'033'334, X_WH2, false);  // tracking lost

  std::vector<uint8_t> command =
      Hex("17"
          "06000000");
  for (uint64_t ticks : {10'000'000ULL,  // that sample's utime exactly
                         10'080'000ULL,  // 8 ms after it, 8.667 ms before the next: the first
                         10'100'000ULL,  // 10 ms after it: the second is nearer
                         10'333'340ULL,  // the lost sample: not located
                         20'000'000ULL,  // 0.97 s after the newest: none within a period
                         0ULL})          // before the history
    PutU64(&command, ticks);
  const std::vector<float> f = Floats(Answer(&device, command).reply);
  ASSERT_EQ(f.size(), 6u * 16u);
  const std::vector<float> first = {1, 0, 0, 0, 0, 0, 1, 0, 0, -1, 0, 0, 1, 3, -2, 1};
  const std::vector<float> second = {1, 0, 0, 0, 0, 0, 1, 0, 0, -1, 0, 0, 4, 6, -5, 1};
  const auto pose = [&](int i) { return std::vector<float>(f.begin() + 16 * i, f.begin() + 16 * (i + 1)); };
  EXPECT_EQ(pose(0), first);
  EXPECT_EQ(pose(1), first);
  EXPECT_EQ(pose(2), second);
  for (int i : {3, 4, 5}) EXPECT_EQ(pose(i), std::vector<float>(16, 0.0f)) << i;
}

TEST(EmulatedDevice, TheRigNodeIsTheDepthCamerasConfiguredOne) {
  LongThrowOptions options;
  options.X_HN = Eigen::Isometry3d::Identity();  // a rig node on the head frame itself
  EmulatedDevice device(TimeBase{kOrigin}, {1, 0, 0, 0}, options);
  device.RecordPose(kOrigin, Eigen::Isometry3d::Identity(), true);
  std::vector<uint8_t> command =
      Hex("17"
          "01000000");
  PutU64(&command, 0);
  // X_DN = X_WD⁻¹ = R_DW, whose columns (1 0 0), (0 0 −1), (0 1 0) are the rows sent.
  EXPECT_EQ(Floats(Answer(&device, command).reply),
            (std::vector<float>{1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1}));
}

TEST(EmulatedDevice, MapsLongThrowPointsAsItsUv2xyTable) {
  const LongThrowOptions options;
  EmulatedDevice device(TimeBase{kOrigin}, {1, 0, 0, 0}, options);
  const std::vector<float> calibration = Floats(PackLongThrowCalibration(options));
  const size_t P = kLongThrowWidth * kLongThrowHeight;
  const int u = 17, v = 203;

  // Image to unit plane: pixel (u, v)'s centre is (u + ½, v + ½) in the sensor's convention, and
  // the image centre (160, 144) the principal ray.
  std::vector<uint8_t> command =
      Hex("16"
          "dd0e0000"    // port 3805
          "00000000"    // ImagePointToCameraUnitPlane
          "02000000");  // 2 points
  for (float c : {u + 0.5f, v + 0.5f, 160.0f, 144.0f}) PutF32(&command, c);
  const std::vector<float> xy = Floats(Answer(&device, command).reply);
  ASSERT_EQ(xy.size(), 4u);
  EXPECT_EQ(xy[0], calibration[v * kLongThrowWidth + u]);      // uv2x
  EXPECT_EQ(xy[1], calibration[P + v * kLongThrowWidth + u]);  // uv2y
  EXPECT_EQ(xy[2], 0.0f);
  EXPECT_EQ(xy[3], 0.0f);
  // By hand: x = (u + ½ − ½ − cx)/fx with cx = 159.5, fx = 160 / tan(37.5°).
  const double fx = 160.0 / std::tan(37.5 * M_PI / 180.0);
  EXPECT_NEAR(xy[0], (17 - 159.5) / fx, 1e-6);
  EXPECT_NEAR(xy[1], (203 - 143.5) / fx, 1e-6);

  // And back: the unit-plane point to the image point it came from.
  command =
      Hex("16"
          "dd0e0000"
          "01000000"  // CameraSpaceToImagePoint
          "01000000");
  PutF32(&command, xy[0]);
  PutF32(&command, xy[1]);
  const std::vector<float> uv = Floats(Answer(&device, command).reply);
  ASSERT_EQ(uv.size(), 2u);
  EXPECT_NEAR(uv[0], u + 0.5, 1e-4);
  EXPECT_NEAR(uv[1], v + 0.5, 1e-4);

  // Another sensor (3800, the left-front VLC camera) is not emulated: refused with its key.
  const RcOutcome other = Answer(&device, Hex("16"
                                              "d80e0000"
                                              "00000000"
                                              "00000000"));
  EXPECT_TRUE(other.refused);
  EXPECT_EQ(other.key, "rc/map_points_sensor");
  EXPECT_TRUE(other.reply.empty());
}

}  // namespace
}  // namespace orbed::hl2ss
