// The SI and PV payloads: head and gaze in the device frame D computed by hand for a head looking
// along +x, the validity flags, NV12 values from the BT.601 formulas for pure colours, and the NV12
// a client gets decoded back with OpenCV's own NV12 reader (as hl2ss.py does with
// cv2.COLOR_YUV2BGR_NV12).
#include "procs/hl2ss/streams.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

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

TEST(PersonalVideo, Nv12OfPureColoursFollowsBt601VideoRange) {
  // Columns 0-1 white, 2-3 red (B, G, R = 0, 0, 255); two rows.
  cv::Mat bgr(2, 4, CV_8UC3, cv::Scalar(255, 255, 255));
  bgr(cv::Rect(2, 0, 2, 2)).setTo(cv::Scalar(0, 0, 255));
  const std::vector<uint8_t> nv12 = Nv12FromBgr(bgr, 64);
  ASSERT_EQ(nv12.size(), 64u * 3);
  // White: Y = 16 + 219 = 235, Cb = Cr = 128. Red: Y = 16 + 65.481 = 81.5 -> 81,
  // Cb = 128 - 37.797 = 90.2 -> 90, Cr = 128 + 112 = 240.
  EXPECT_EQ(nv12[0], 235);
  EXPECT_EQ(nv12[64 + 1], 235);
  EXPECT_EQ(nv12[2], 81);
  EXPECT_EQ(nv12[64 + 3], 81);
  EXPECT_EQ(nv12[4], 0) << "padding to the stride";
  EXPECT_EQ(nv12[128 + 0], 128);
  EXPECT_EQ(nv12[128 + 1], 128);
  EXPECT_EQ(nv12[128 + 2], 90);
  EXPECT_EQ(nv12[128 + 3], 240);
}

TEST(PersonalVideo, RawPayloadDecodesAsTheClientDecodesIt) {
  // A smooth picture (chroma subsampling loses nothing visible): what hl2ss.py does to a RAW
  // payload (strip the 80-byte trailer, reshape to 1.5·height rows, cut to width, NV12 → BGR).
  const int w = 424, h = 240;
  cv::Mat bgr(h, w, CV_8UC3);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c)
      bgr.at<cv::Vec3b>(r, c) = cv::Vec3b(static_cast<uint8_t>(40 + c / 3), static_cast<uint8_t>(30 + r / 2),
                                          static_cast<uint8_t>(200 - c / 4));
  PvSettings settings;
  PvFrameInfo info;
  info.width = w;
  info.height = h;
  info.fx_px = 300;
  info.fy_px = 301;
  info.cx_px = 211.5;
  info.cy_px = 119.5;
  info.settings = &settings;
  const std::vector<uint8_t> payload = RawPvPayload(bgr, info);
  const int stride = PvStride(w);
  EXPECT_EQ(stride, 448);
  ASSERT_EQ(payload.size(), static_cast<size_t>(stride) * h * 3 / 2 + kPvTrailerBytes);
  const uint8_t* trailer = payload.data() + payload.size() - kPvTrailerBytes;
  EXPECT_FLOAT_EQ(GetF32(trailer + 0), 300.0f);
  EXPECT_FLOAT_EQ(GetF32(trailer + 4), 301.0f);
  EXPECT_FLOAT_EQ(GetF32(trailer + 8), 211.5f);
  EXPECT_FLOAT_EQ(GetF32(trailer + 12), 119.5f);
  EXPECT_EQ(GetU16(trailer + 76), w);
  EXPECT_EQ(GetU16(trailer + 78), h);
  cv::Mat nv12(h * 3 / 2, stride, CV_8UC1, const_cast<uint8_t*>(payload.data()));
  cv::Mat decoded;
  cv::cvtColor(nv12(cv::Rect(0, 0, w, h * 3 / 2)).clone(), decoded, cv::COLOR_YUV2BGR_NV12);
  cv::Mat diff;
  cv::absdiff(decoded, bgr, diff);
  double max_diff = 0;
  cv::minMaxLoc(diff.reshape(1), nullptr, &max_diff);
  EXPECT_LE(max_diff, 3) << "BT.601 both ways: rounding only";
}

TEST(PersonalVideo, PacerHalvesFor15FpsThenAppliesTheDivisor) {
  PvConfig c;
  c.framerate = 15;
  c.divisor = 2;
  PvPacer pacer(c);
  std::vector<int> sent;
  for (int i = 0; i < 12; ++i)
    if (pacer.Next()) sent.push_back(i);
  EXPECT_EQ(sent, (std::vector<int>{0, 4, 8}));
}

TEST(PersonalVideo, OnlyRawIsServedUntilAnEncoderIsAttached) {
  PvEncoderFactory factory = RawOnlyPvEncoderFactory();
  PvConfig c;
  std::string why;
  c.profile = kProfileRaw;
  EXPECT_TRUE(factory(c, &why));
  c.profile = kProfileH265Main;
  EXPECT_FALSE(factory(c, &why));
  EXPECT_NE(why.find("H.264/H.265"), std::string::npos);
}

}  // namespace
}  // namespace orbed::hl2ss
