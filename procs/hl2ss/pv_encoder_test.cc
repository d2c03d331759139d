// PV payloads against independent readers: libavcodec's H.264 and HEVC decoders fed the way the
// hl2ss client feeds them, the BT.601 formula by hand for raw NV12, hand-packed trailer bytes, and
// the client's projection math (hl2ss_3dcv) for the calibration.
#include "procs/hl2ss/pv_encoder.h"

#include <cmath>
#include <cstring>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "procs/hl2ss/frames.h"
#include "procs/hl2ss/pv_client_decoder.h"

extern "C" {
#include <libavcodec/avcodec.h>
}

namespace orbed::hl2ss {
namespace {

// A picture with smooth gradients, flat patches and sharp edges (what the camera shows).
cv::Mat TestPicture(int w, int h, int shift = 0) {
  cv::Mat bgr(h, w, CV_8UC3);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      bgr.at<cv::Vec3b>(v, u) =
          cv::Vec3b(static_cast<uchar>(40 + 150 * u / w), static_cast<uchar>(60 + 120 * v / h),
                    static_cast<uchar>(90 + 80 * ((u + v + shift) % 200) / 200));
    }
  }
  cv::rectangle(bgr, cv::Rect(w / 4 + shift, h / 4, w / 5, h / 4), cv::Scalar(30, 110, 230), cv::FILLED);
  cv::circle(bgr, cv::Point(2 * w / 3, h / 2), h / 6, cv::Scalar(200, 200, 200), cv::FILLED);
  return bgr;
}

double Psnr(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  diff.convertTo(diff, CV_64F);
  const cv::Scalar per = cv::mean(diff.mul(diff));  // per channel
  const double m = (per[0] + per[1] + per[2]) / 3;
  return m <= 0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / m);
}

// NAL unit types in an Annex-B stream (after each 00 00 01 start code).
std::vector<int> NalTypes(const std::vector<std::uint8_t>& s, bool hevc) {
  std::vector<int> types;
  for (size_t i = 0; i + 3 < s.size(); ++i) {
    if (s[i] == 0 && s[i + 1] == 0 && s[i + 2] == 1) {
      types.push_back(hevc ? (s[i + 3] >> 1) & 0x3F : s[i + 3] & 0x1F);
      i += 2;
    }
  }
  return types;
}
bool Has(const std::vector<int>& v, int x) { return std::find(v.begin(), v.end(), x) != v.end(); }

std::vector<std::uint8_t> ImagePart(const std::vector<std::uint8_t>& payload) {
  return {payload.begin(), payload.end() - kPvTrailerBytes};
}

PvEncoderConfig Config(int w, int h, VideoProfile profile) {
  PvEncoderConfig c;
  c.format = {w, h, 30};
  c.profile = profile;
  const double factor = profile == VideoProfile::kH265Main ? 1.0 / 150 : 1.0 / 75;  // hl2ss_lnm's default
  c.bitrate_bps = static_cast<std::uint32_t>(w * h * 30 * 12 * factor);
  c.gop_frames = 30;
  return c;
}

TEST(PvFormat, DeviceModesAcceptedOthersRefusedWithReason) {
  EXPECT_FALSE(CheckPvFormat({1920, 1080, 30}));
  EXPECT_FALSE(CheckPvFormat({1280, 720, 30}));
  EXPECT_FALSE(CheckPvFormat({1280, 720, 15}));
  EXPECT_FALSE(CheckPvFormat({1504, 846, 5}));
  EXPECT_TRUE(CheckPvFormat({1504, 846, 60}));  // the device's, but the emulated camera runs at 30 Hz
  const auto rate = CheckPvFormat({1280, 720, 60});
  ASSERT_TRUE(rate);
  EXPECT_NE(rate->find("15, 30 Hz"), std::string::npos) << *rate;
  const auto size = CheckPvFormat({800, 600, 30});
  ASSERT_TRUE(size);
  EXPECT_NE(size->find("not a video mode"), std::string::npos) << *size;
  EXPECT_FALSE(CheckPvFormat({2272, 1278, 30}));
  EXPECT_FALSE(CheckPvFormat({896, 504, 15}));
  EXPECT_EQ(SupportedPvFormats().size(), 25u);  // 11 sizes × 2 rates, 1504×846 × 3
}

TEST(PvFormat, ConfigChecks) {
  PvEncoderConfig c = Config(1280, 720, VideoProfile::kH264Main);
  EXPECT_FALSE(CheckPvEncoderConfig(c));
  c.bitrate_bps = 0;
  EXPECT_TRUE(CheckPvEncoderConfig(c));
  c.profile = VideoProfile::kRaw;
  EXPECT_FALSE(CheckPvEncoderConfig(c));  // raw has no bitrate
  c = Config(1280, 720, VideoProfile::kH265Main);
  c.gop_frames = 0;
  EXPECT_TRUE(CheckPvEncoderConfig(c));
  c = Config(1280, 720, VideoProfile::kH265Main);
  c.divisor = 0;
  EXPECT_TRUE(CheckPvEncoderConfig(c));
  c.divisor = 2;
  EXPECT_FALSE(CheckPvEncoderConfig(c));
  EXPECT_EQ(VideoProfileFromByte(3), VideoProfile::kH265Main);
  EXPECT_EQ(VideoProfileFromByte(0xFF), VideoProfile::kRaw);
  EXPECT_FALSE(VideoProfileFromByte(4));
  std::string error;
  c.format.framerate_hz = 31;
  EXPECT_EQ(PvEncoder::Create(c, &error), nullptr);
  EXPECT_NE(error.find("not 31"), std::string::npos) << error;
}

TEST(PvTrailer, BytesAreTheClientsLayout) {
  geometry::Intrinsics K;  // 1280×720, fx 1545.4, fy 1551.2, cx 597.2, cy 322.1
  PvCaptureMetadata m;
  m.exposure_time_hns = 166667;  // 0x28B0B
  m.exposure_compensation = {0x0102030405060708ULL, 2};
  m.lens_position = 7;
  m.focus_state = 3;
  m.iso_speed = 100;
  m.white_balance_k = 4500;  // 0x1194
  m.iso_gains = {1.0f, 2.0f};
  m.white_balance_gains = {0.5f, 1.0f, -2.0f};
  const auto t = PackPvTrailer(K, m);
  // Hand-packed, little-endian, at the offsets hl2ss.py's decode_pv reads.
  std::array<std::uint8_t, 80> e{};
  const auto f32 = [&](int at, float v) { std::memcpy(e.data() + at, &v, 4); };
  f32(0, 1545.4f);
  f32(4, 1551.2f);
  f32(8, 597.2f);
  f32(12, 322.1f);
  const std::uint8_t exposure[8] = {0x0B, 0x8B, 0x02, 0, 0, 0, 0, 0};
  std::memcpy(e.data() + 16, exposure, 8);
  const std::uint8_t comp[16] = {0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01, 2, 0, 0, 0, 0, 0, 0, 0};
  std::memcpy(e.data() + 24, comp, 16);
  e[40] = 7;
  e[44] = 3;
  e[48] = 100;
  e[52] = 0x94;
  e[53] = 0x11;
  f32(56, 1.0f);
  f32(60, 2.0f);
  f32(64, 0.5f);
  f32(68, 1.0f);
  f32(72, -2.0f);
  e[76] = 0x00;  // 1280 = 0x0500
  e[77] = 0x05;
  e[78] = 0xD0;  // 720 = 0x02D0
  e[79] = 0x02;
  EXPECT_EQ(t, e);
  // 1.0f is 00 00 80 3F.
  EXPECT_EQ(t[59], 0x3F);
  EXPECT_EQ(t[58], 0x80);
}

TEST(PvRaw, Nv12MatchesTheBt601FormulaByHand) {
  // 2×2 blocks of one colour each, so the chroma subsampling rule does not matter.
  const int w = 8, h = 4;
  cv::Mat bgr(h, w, CV_8UC3);
  const cv::Vec3b colors[8] = {{0, 0, 0},   {255, 255, 255}, {0, 0, 255},   {0, 255, 0},
                               {255, 0, 0}, {30, 110, 230},  {200, 50, 20}, {128, 128, 128}};
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) bgr.at<cv::Vec3b>(v, u) = colors[(v / 2) * (w / 2) + u / 2];
  const int stride = 64;
  std::vector<std::uint8_t> nv12;
  AppendNv12(bgr, stride, &nv12);
  ASSERT_EQ(nv12.size(), static_cast<size_t>(stride * h * 3 / 2));
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const cv::Vec3b c = bgr.at<cv::Vec3b>(v, u);
      const double B = c[0], G = c[1], R = c[2];
      const double Y = 16 + (65.481 * R + 128.553 * G + 24.966 * B) / 255;
      EXPECT_NEAR(nv12[v * stride + u], Y, 1.0) << u << "," << v;
      if (v % 2 == 0 && u % 2 == 0) {
        const double U = 128 + (-37.797 * R - 74.203 * G + 112.0 * B) / 255;
        const double V = 128 + (112.0 * R - 93.786 * G - 18.214 * B) / 255;
        const std::uint8_t* uv = nv12.data() + stride * h + (v / 2) * stride + u;
        EXPECT_NEAR(uv[0], U, 1.0) << u << "," << v;
        EXPECT_NEAR(uv[1], V, 1.0) << u << "," << v;
      }
    }
    for (int u = w; u < stride; ++u) EXPECT_EQ(nv12[v * stride + u], 0);  // padding
  }
}

TEST(PvRaw, PayloadIsStridedNv12ThenTrailer) {
  std::string error;
  auto enc = PvEncoder::Create(Config(1128, 636, VideoProfile::kRaw), &error);
  ASSERT_TRUE(enc) << error;
  const cv::Mat bgr = TestPicture(1280, 720);
  std::vector<std::uint8_t> payload;
  ASSERT_TRUE(enc->Encode(bgr, geometry::Intrinsics::HoloLensPv(), {}, &payload, &error)) << error;
  EXPECT_EQ(PvRawStride(1128), 1152);
  EXPECT_EQ(PvRawStride(1920), 1920);
  ASSERT_EQ(payload.size(), static_cast<size_t>(1152 * 636 * 3 / 2 + 80));
  // The client's raw decode: rows of the stride cut to the width, OpenCV's NV12 → BGR.
  cv::Mat nv12(636 * 3 / 2, 1152, CV_8UC1, payload.data());
  cv::Mat decoded;
  cv::cvtColor(nv12.colRange(0, 1128).clone(), decoded, cv::COLOR_YUV2BGR_NV12);
  cv::Mat expected;
  cv::resize(bgr, expected, cv::Size(1128, 636), 0, 0, cv::INTER_AREA);
  EXPECT_GT(Psnr(decoded, expected), 35.0);
  // Resolution in the trailer.
  EXPECT_EQ(payload[payload.size() - 4] | payload[payload.size() - 3] << 8, 1128);
  EXPECT_EQ(payload[payload.size() - 2] | payload[payload.size() - 1] << 8, 636);
}

void ExpectDecodes(VideoProfile profile, int w, int h, double min_psnr_db) {
  const bool hevc = profile == VideoProfile::kH265Main;
  std::string error;
  auto enc = PvEncoder::Create(Config(w, h, profile), &error);
  ASSERT_TRUE(enc) << error;
  PvClientDecoder dec(hevc);
  double worst = 99;
  for (int i = 0; i < 4; ++i) {
    const cv::Mat bgr = TestPicture(1280, 720, 8 * i);
    std::vector<std::uint8_t> payload;
    ASSERT_TRUE(enc->Encode(bgr, geometry::Intrinsics::HoloLensPv(), {}, &payload, &error)) << error;
    const std::vector<std::uint8_t> image = ImagePart(payload);
    float f_trailer[4];  // the intrinsics of the picture sent, not of the one given
    std::memcpy(f_trailer, payload.data() + image.size(), sizeof(f_trailer));
    const geometry::Intrinsics K_sent = ScaleIntrinsics(geometry::Intrinsics::HoloLensPv(), w, h);
    EXPECT_FLOAT_EQ(f_trailer[0], static_cast<float>(K_sent.fx_px));
    EXPECT_FLOAT_EQ(f_trailer[3], static_cast<float>(K_sent.cy_px));
    if (!hevc) {
      ASSERT_GE(image.size(), 6u);
      EXPECT_EQ(std::vector<std::uint8_t>(image.begin(), image.begin() + 6),
                (std::vector<std::uint8_t>{0, 0, 0, 1, 0x09, 0x10}));
    }
    const std::vector<int> nals = NalTypes(image, hevc);
    if (i == 0) {  // a new client's first unit: IDR with its parameter sets
      if (hevc) {
        EXPECT_TRUE(Has(nals, 32) && Has(nals, 33) && Has(nals, 34)) << "VPS, SPS, PPS";
        EXPECT_TRUE(Has(nals, 19) || Has(nals, 20)) << "IDR";
      } else {
        EXPECT_TRUE(Has(nals, 7) && Has(nals, 8)) << "SPS, PPS";
        EXPECT_TRUE(Has(nals, 5)) << "IDR";
      }
    }
    const cv::Mat decoded = dec.Decode(image);
    ASSERT_FALSE(decoded.empty()) << "frame " << i;
    ASSERT_EQ(decoded.cols, w);
    ASSERT_EQ(decoded.rows, h);
    if (i == 0) {
      EXPECT_TRUE(dec.last_was_key());
    }
    cv::Mat expected = bgr;
    if (w != 1280) cv::resize(bgr, expected, cv::Size(w, h), 0, 0, cv::INTER_AREA);
    worst = std::min(worst, Psnr(decoded, expected));
  }
  EXPECT_GT(worst, min_psnr_db);
  const int expected_profile = profile == VideoProfile::kH264Base   ? FF_PROFILE_H264_CONSTRAINED_BASELINE
                               : profile == VideoProfile::kH264Main ? FF_PROFILE_H264_MAIN
                               : profile == VideoProfile::kH264High ? FF_PROFILE_H264_HIGH
                                                                    : FF_PROFILE_HEVC_MAIN;
  EXPECT_EQ(dec.profile(), expected_profile);
  std::printf("profile %d %dx%d: worst PSNR %.1f dB\n", static_cast<int>(profile), w, h, worst);
}

TEST(PvVideo, H264MainDecodesToThePicture) { ExpectDecodes(VideoProfile::kH264Main, 1280, 720, 36.0); }
TEST(PvVideo, H264BaseAndHighDecode) {
  ExpectDecodes(VideoProfile::kH264Base, 640, 360, 33.0);
  ExpectDecodes(VideoProfile::kH264High, 640, 360, 33.0);
}
TEST(PvVideo, H265MainResizedTo1080pDecodes) { ExpectDecodes(VideoProfile::kH265Main, 1920, 1080, 36.0); }

TEST(PvVideo, EachConnectionStartsWithAnIdrAndTheGopRepeatsIt) {
  std::string error;
  PvEncoderConfig c = Config(640, 360, VideoProfile::kH264High);
  c.gop_frames = 3;
  auto enc = PvEncoder::Create(c, &error);
  ASSERT_TRUE(enc) << error;
  std::vector<bool> idr;
  for (int i = 0; i < 7; ++i) {
    std::vector<std::uint8_t> payload;
    ASSERT_TRUE(
        enc->Encode(TestPicture(1280, 720, i), geometry::Intrinsics::HoloLensPv(), {}, &payload, &error));
    const auto nals = NalTypes(ImagePart(payload), false);
    idr.push_back(Has(nals, 5) && Has(nals, 7));
  }
  EXPECT_EQ(idr, (std::vector<bool>{true, false, false, true, false, false, true}));
  EXPECT_EQ(enc->frames(), 7);
}

// After a lost packet the client's decoder needs an IDR: a forced one decodes on a fresh decoder
// (one that saw nothing before, as a decoder past the loss), where the P picture before it does not.
TEST(PvVideo, AForcedKeyFrameDecodesOnAFreshDecoder) {
  for (VideoProfile profile : {VideoProfile::kH264Main, VideoProfile::kH265Main}) {
    const bool hevc = profile == VideoProfile::kH265Main;
    std::string error;
    auto enc = PvEncoder::Create(Config(640, 360, profile), &error);  // GOP 30: no IDR but the first
    ASSERT_TRUE(enc) << error;
    std::vector<std::vector<std::uint8_t>> images;
    for (int i = 0; i < 6; ++i) {
      if (i == 4) enc->ForceKeyFrame();
      std::vector<std::uint8_t> payload;
      const cv::Mat bgr = TestPicture(1280, 720, 6 * i);
      ASSERT_TRUE(enc->Encode(bgr, geometry::Intrinsics::HoloLensPv(), {}, &payload, &error)) << error;
      images.push_back(ImagePart(payload));
      const std::vector<int> nals = NalTypes(images.back(), hevc);
      const bool idr = hevc ? Has(nals, 19) || Has(nals, 20) : Has(nals, 5);
      const bool sps = hevc ? Has(nals, 32) && Has(nals, 33) && Has(nals, 34) : Has(nals, 7) && Has(nals, 8);
      EXPECT_EQ(idr, i == 0 || i == 4) << static_cast<int>(profile) << " picture " << i;
      EXPECT_EQ(sps, i == 0 || i == 4) << static_cast<int>(profile) << " picture " << i;
      if (i != 4) continue;
      PvClientDecoder fresh(hevc);
      const cv::Mat decoded = fresh.Decode(images.back());
      ASSERT_FALSE(decoded.empty()) << static_cast<int>(profile);
      EXPECT_TRUE(fresh.last_was_key());
      cv::Mat expected;
      cv::resize(bgr, expected, cv::Size(640, 360), 0, 0, cv::INTER_AREA);
      EXPECT_GT(Psnr(decoded, expected), 30.0) << static_cast<int>(profile);
    }
    PvClientDecoder fresh(hevc);  // the P picture before the forced IDR: nothing to decode from
    EXPECT_TRUE(fresh.Decode(images[3]).empty()) << static_cast<int>(profile);
    PvClientDecoder after(hevc);  // and the P picture after it decodes once the IDR was seen
    ASSERT_FALSE(after.Decode(images[4]).empty());
    EXPECT_FALSE(after.Decode(images[5]).empty()) << static_cast<int>(profile);
  }
}

TEST(PvVideo, TwoThreadsStillReturnEachPicturesUnit) {
  for (VideoProfile profile : {VideoProfile::kH264High, VideoProfile::kH265Main}) {
    std::string error;
    PvEncoderConfig c = Config(640, 360, profile);
    c.threads = 2;
    auto enc = PvEncoder::Create(c, &error);
    ASSERT_TRUE(enc) << error;
    PvClientDecoder dec(profile == VideoProfile::kH265Main);
    for (int i = 0; i < 3; ++i) {
      std::vector<std::uint8_t> payload;
      ASSERT_TRUE(enc->Encode(TestPicture(1280, 720, 5 * i), geometry::Intrinsics::HoloLensPv(), {}, &payload,
                              &error))
          << static_cast<int>(profile) << " picture " << i << ": " << error;
      EXPECT_FALSE(dec.Decode(ImagePart(payload)).empty()) << static_cast<int>(profile) << " picture " << i;
    }
  }
}

TEST(PvVideo, RefusesABadPictureBeforeEncoding) {
  std::string error;
  auto enc = PvEncoder::Create(Config(1280, 720, VideoProfile::kH264Main), &error);
  ASSERT_TRUE(enc) << error;
  std::vector<std::uint8_t> payload;
  const geometry::Intrinsics K = geometry::Intrinsics::HoloLensPv();
  EXPECT_FALSE(enc->Encode(cv::Mat(720, 1280, CV_8UC1, cv::Scalar(0)), K, {}, &payload, &error));
  EXPECT_FALSE(enc->Encode(TestPicture(640, 360), K, {}, &payload, &error));  // not K's size
  EXPECT_NE(error.find("differs"), std::string::npos) << error;
  geometry::Intrinsics big = K;
  big.width_px = 5000;
  EXPECT_FALSE(enc->Encode(cv::Mat(720, 5000, CV_8UC3), big, {}, &payload, &error));
  EXPECT_NE(error.find("4096"), std::string::npos) << error;
  geometry::Intrinsics nan = K;
  nan.fx_px = std::nan("");
  EXPECT_FALSE(enc->Encode(TestPicture(1280, 720), nan, {}, &payload, &error));
  EXPECT_EQ(enc->frames(), 0);
  EXPECT_TRUE(enc->Encode(TestPicture(1280, 720), K, {}, &payload, &error)) << error;
}

TEST(PvVideo, HoldsTheClientsBitrate) {
  // Busy content (noise scrolling by), so the rate control, not the picture, sets the size.
  cv::Mat noise(240, 424 + 64, CV_8UC3);
  const geometry::Intrinsics K = ScaleIntrinsics(geometry::Intrinsics::HoloLensPv(), 424, 240);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(noise, noise, cv::Size(9, 9), 2.0);
  for (VideoProfile profile : {VideoProfile::kH264Main, VideoProfile::kH265Main}) {
    for (std::uint32_t bps : {300'000u, 1'200'000u}) {
      PvEncoderConfig c = Config(424, 240, profile);
      c.bitrate_bps = bps;
      std::string error;
      auto enc = PvEncoder::Create(c, &error);
      ASSERT_TRUE(enc) << error;
      size_t bytes = 0;
      for (int i = 0; i < 60; ++i) {  // two seconds at 30 Hz; the second one counted
        std::vector<std::uint8_t> payload;
        ASSERT_TRUE(enc->Encode(noise.colRange(i, i + 424).clone(), K, {}, &payload, &error)) << error;
        if (i >= 30) bytes += payload.size() - kPvTrailerBytes;
      }
      const double measured_bps = 8.0 * bytes;
      std::printf("profile %d at %u bit/s: %.0f bit/s\n", static_cast<int>(profile), bps, measured_bps);
      EXPECT_GT(measured_bps, 0.8 * bps);
      EXPECT_LT(measured_bps, 1.25 * bps);  // measured 0.97 … 1.11 of it
    }
  }
}

TEST(PvIntrinsics, ScaledAboutPixelEdges) {
  const geometry::Intrinsics K = geometry::Intrinsics::HoloLensPv();
  const geometry::Intrinsics K2 = ScaleIntrinsics(K, 1920, 1080);
  EXPECT_DOUBLE_EQ(K2.fx_px, 1.5 * K.fx_px);
  EXPECT_DOUBLE_EQ(K2.cx_px, 1.5 * (K.cx_px + 0.5) - 0.5);
  EXPECT_EQ(K2.width_px, 1920);
}

// hl2ss_3dcv's row-vector math.
Eigen::Matrix4d RowMajor(const std::vector<float>& f, int at) {
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = f[at + 4 * r + c];
  return m;
}
Eigen::Vector2d ClientProject(const Eigen::Vector3d& p, const Eigen::Matrix4d& P) {
  const Eigen::Vector3d h = (p.transpose() * P.topLeftCorner<3, 3>() + P.block<1, 3>(3, 0)).transpose();
  return h.head<2>() / h.z();
}

TEST(PvCalibration, ProjectsAKnownPointWhereTheCameraModelDoes) {
  const geometry::Intrinsics K = ScaleIntrinsics(geometry::Intrinsics::HoloLensPv(), 1920, 1080);
  Eigen::Isometry3d X_NC = Eigen::Isometry3d::Identity();
  X_NC.linear() = Eigen::AngleAxisd(0.1, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  X_NC.translation() = Eigen::Vector3d(0.02, -0.05, 0.01);
  const std::vector<std::uint8_t> bytes = PackPvCalibration(K, X_NC);
  ASSERT_EQ(bytes.size(), 52u * 4);
  std::vector<float> f(52);
  std::memcpy(f.data(), bytes.data(), bytes.size());
  EXPECT_FLOAT_EQ(f[0], static_cast<float>(K.fx_px));
  EXPECT_FLOAT_EQ(f[3], static_cast<float>(K.cy_px));
  for (int i = 4; i < 9; ++i) EXPECT_EQ(f[i], 0.0f);

  // A camera in the world looking at a point; the pose it reports in mode 1.
  const Eigen::Isometry3d X_WC = geometry::LookAt({1.0, -2.0, 1.6}, {1.3, 0.4, 0.9});
  const Eigen::Vector3d p_W(1.45, 0.2, 1.05);
  const std::array<float, 16> pose_f = PoseMatrixRowMajor(CameraPoseForClient(X_WC));
  const Eigen::Matrix4d pose = RowMajor(std::vector<float>(pose_f.begin(), pose_f.end()), 0);
  const Eigen::Vector3d p_D = X_WD().inverse() * p_W;

  Eigen::Vector2d expected;
  ASSERT_TRUE(geometry::Project(geometry::MakeCameraMatrix(K.K(), X_WC), p_W, &expected));
  // hl2ss.create_pv_intrinsics(f, c), world_to_reference = inv(pose), no extrinsics.
  Eigen::Matrix4d intrinsics = Eigen::Matrix4d::Zero();
  intrinsics(0, 0) = -f[0];
  intrinsics(1, 1) = f[1];
  intrinsics(2, 0) = f[2];
  intrinsics(2, 1) = f[3];
  intrinsics(2, 2) = 1;
  intrinsics(3, 3) = 1;
  EXPECT_TRUE(RowMajor(f, 9).isApprox(intrinsics)) << "the projection field is the client's intrinsics";
  const Eigen::Vector2d uv = ClientProject(p_D, pose.inverse() * intrinsics);
  EXPECT_NEAR(uv.x(), expected.x(), 0.02);
  EXPECT_NEAR(uv.y(), expected.y(), 0.02);
  // The same through hl2ss_3dcv.pv_fix_calibration (extrinsics = I·diag(1, −1, −1, 1), +fx).
  Eigen::Matrix4d fixed = intrinsics;
  fixed(0, 0) = f[0];
  const Eigen::Matrix4d R = Eigen::Vector4d(1, -1, -1, 1).asDiagonal();
  const Eigen::Vector2d uv2 = ClientProject(p_D, pose.inverse() * R * fixed);
  EXPECT_NEAR(uv2.x(), expected.x(), 0.02);
  EXPECT_NEAR(uv2.y(), expected.y(), 0.02);

  // Extrinsics: rig node → Ĉ in the row-vector convention, and the Media Foundation pose p, q.
  const Eigen::Matrix4d E = RowMajor(f, 25);
  const Eigen::Vector3d p_N(0.3, -0.2, 0.5);
  const Eigen::Vector4d p_Ch = Eigen::Vector4d(p_N.x(), p_N.y(), p_N.z(), 1).transpose() * E;
  const Eigen::Vector3d expected_Ch = (X_NC * X_CCh()).inverse() * p_N;
  EXPECT_NEAR((p_Ch.head<3>() - expected_Ch).norm(), 0, 1e-6);
  EXPECT_FLOAT_EQ(f[41], static_cast<float>(K.fx_px));  // intrinsics_mf
  const Eigen::Vector3d t(f[45], f[46], f[47]);
  const Eigen::Quaterniond q(f[51], f[48], f[49], f[50]);
  EXPECT_NEAR((t - X_NC.translation()).norm(), 0, 1e-6);
  EXPECT_NEAR((q.toRotationMatrix() - (X_NC * X_CCh()).linear()).norm(), 0, 1e-6);
}

}  // namespace
}  // namespace orbed::hl2ss
