// The SI payload: head and gaze in the device frame D computed by hand for a head looking along
// +x, and the validity flags. (The PV payloads are pv_encoder_test's, the PV stream's choices
// pv_stream_test's.)
#include "procs/hl2ss/streams.h"

#include <gtest/gtest.h>

namespace orbed::hl2ss {
namespace {

Eigen::Vector3f F3(const std::vector<uint8_t>& b, size_t at) {
  return {GetF32(b.data() + at), GetF32(b.data() + at + 4), GetF32(b.data() + at + 8)};
}

// A head at p_W = (1, 2, 1.7) looking along +x_W, upright: z_H = x_W, y_H = −z_W, x_H = −y_W.
Eigen::Isometry3d HeadLookingAlongX() {
  Eigen::Isometry3d X_WH = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d R;
  R.col(0) = Eigen::Vector3d(0, -1, 0);
  R.col(1) = Eigen::Vector3d(0, 0, -1);
  R.col(2) = Eigen::Vector3d(1, 0, 0);
  X_WH.linear() = R;
  X_WH.translation() = Eigen::Vector3d(1, 2, 1.7);
  return X_WH;
}

TEST(SpatialInput, HeadAndGazeInTheDeviceFrame) {
  // D: x_D = x_W, y_D = z_W, z_D = −y_W, so p_D = (x, z, −y).
  const SiHead h = HeadInDevice(HeadLookingAlongX());
  EXPECT_TRUE(h.position_D.isApprox(Eigen::Vector3d(1, 1.7, -2)));
  EXPECT_TRUE(h.forward_D.isApprox(Eigen::Vector3d(1, 0, 0)));
  EXPECT_TRUE(h.up_D.isApprox(Eigen::Vector3d(0, 1, 0)));

  const GazeSample gaze{Eigen::Vector3d(1, 2, 1.7), Eigen::Vector3d(0.6, 0.8, 0)};
  const std::vector<uint8_t> p = SiPayload(HeadSample{HeadLookingAlongX(), false}, gaze);
  ASSERT_EQ(p.size(), kSiPayloadBytes);
  EXPECT_EQ(GetU32(p.data()), kSiHeadValid | kSiEyeValid);
  EXPECT_TRUE(F3(p, 4).isApprox(Eigen::Vector3f(1, 1.7f, -2)));
  EXPECT_TRUE(F3(p, 16).isApprox(Eigen::Vector3f(1, 0, 0)));
  EXPECT_TRUE(F3(p, 28).isApprox(Eigen::Vector3f(0, 1, 0)));
  EXPECT_TRUE(F3(p, 40).isApprox(Eigen::Vector3f(1, 1.7f, -2)));
  EXPECT_TRUE(F3(p, 52).isApprox(Eigen::Vector3f(0.6f, 0, -0.8f)));
  for (size_t i = 64; i < p.size(); ++i) ASSERT_EQ(p[i], 0) << "hands are not tracked";
}

TEST(SpatialInput, ValidityFlagsAsTheDeviceSetsThem) {
  const GazeSample gaze{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX()};
  EXPECT_EQ(GetU32(SiPayload(HeadSample{HeadLookingAlongX(), false}, std::nullopt).data()), kSiHeadValid);
  EXPECT_EQ(GetU32(SiPayload(HeadSample{HeadLookingAlongX(), true}, gaze).data()), 0u);  // tracking lost
  EXPECT_EQ(GetU32(SiPayload(std::nullopt, gaze).data()), 0u);
}

}  // namespace
}  // namespace orbed::hl2ss
