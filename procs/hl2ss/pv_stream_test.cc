// The PV stream's choices: the client's bytes as an encoder configuration (hl2ss_lnm's defaults,
// the GOP option key 10, every refusal's key), the trailer fields from RC settings in the
// client's units converted by hand, the pacer's frames listed by hand, and the mode-2
// calibration's extrinsics against a rig node and camera placed by hand.
#include "procs/hl2ss/pv_stream.h"

#include <cstring>

#include <gtest/gtest.h>

#include "procs/hl2ss/frames.h"

namespace orbed::hl2ss {
namespace {

PvConfig Client(uint16_t w, uint16_t h, uint8_t profile) {
  PvConfig c;
  c.mode = kMode1;
  c.width = w;
  c.height = h;
  c.framerate = 30;
  c.divisor = 1;
  c.profile = profile;
  c.bitrate = w * h * 30u * 12u / 150u;  // hl2ss_lnm's H.265 default
  return c;
}

TEST(PvStream, ClientConfigurationBecomesTheEncoders) {
  PvRefusal refusal;
  PvConfig c = Client(1920, 1080, kProfileH265Main);
  c.divisor = 2;
  c.options = {{kEncoderOptionGopSize, 15}, {16, 1}};  // GOP 15; low latency (accepted, not honoured)
  const auto e = PvEncoderConfigFromClient(c, 1, &refusal);
  ASSERT_TRUE(e) << refusal.reason;
  EXPECT_EQ(e->format.width_px, 1920);
  EXPECT_EQ(e->format.height_px, 1080);
  EXPECT_EQ(e->format.framerate_hz, 30);
  EXPECT_EQ(e->profile, VideoProfile::kH265Main);
  EXPECT_EQ(e->divisor, 2);
  EXPECT_EQ(e->bitrate_bps, 1920u * 1080 * 30 * 12 / 150);
  EXPECT_EQ(e->gop_frames, 15);

  c.options.clear();  // no GOP option: one IDR a second at the client's frame rate
  c.framerate = 15;
  EXPECT_EQ(PvEncoderConfigFromClient(c, 1, &refusal)->gop_frames, 15);
  c.options = {{kEncoderOptionGopSize, 0}};  // 0: "encoder chooses" -> the same default
  EXPECT_EQ(PvEncoderConfigFromClient(c, 1, &refusal)->gop_frames, 15);

  EXPECT_EQ(PvEncoderConfigFromClient(Client(424, 240, kProfileH264Base), 1, &refusal)->profile,
            VideoProfile::kH264Base);
  EXPECT_EQ(PvEncoderConfigFromClient(Client(1280, 720, kProfileRaw), 1, &refusal)->profile,
            VideoProfile::kRaw);
}

TEST(PvStream, EachRefusalHasItsKey) {
  const auto key_of = [](const PvConfig& c) {
    PvRefusal refusal;
    EXPECT_FALSE(PvEncoderConfigFromClient(c, 1, &refusal));
    EXPECT_FALSE(refusal.reason.empty());
    return refusal.key;
  };
  EXPECT_EQ(key_of(Client(1280, 720, 7)), "pv/profile");
  EXPECT_EQ(key_of(Client(1000, 1000, kProfileH264Main)), "pv/size");
  PvConfig c = Client(1280, 720, kProfileH264Main);
  c.framerate = 60;
  EXPECT_EQ(key_of(c), "pv/framerate");
  c = Client(1280, 720, kProfileH264Main);
  c.bitrate = kMaxBitrateBps + 1;
  EXPECT_EQ(key_of(c), "pv/bitrate");
  c = Client(1280, 720, kProfileH264Main);
  c.options = {{kEncoderOptionGopSize, kMaxGopFrames + 1}};
  EXPECT_EQ(key_of(c), "pv/gop");
}

// One list of modes: what the parser accepts is what the encoder serves, and nothing else.
TEST(PvStream, TheParserAcceptsExactlyTheModesTheEncoderServes) {
  ASSERT_EQ(SupportedPvFormats().size(), PvVideoModes().size());
  EXPECT_EQ(PvVideoModes().size(), 25u);  // 11 sizes × (15, 30 Hz), 1504×846 × (5, 15, 30 Hz)
  // Every size the parser could meet (the device's, the 60 Hz ones included) at 1 … 60 Hz: the
  // parser's verdict on the client's bytes equals the encoder's on that mode.
  int accepted = 0;
  for (const auto& [w, h] : std::vector<std::pair<int, int>>{{2272, 1278},
                                                             {1952, 1100},
                                                             {1920, 1080},
                                                             {1504, 846},
                                                             {1280, 720},
                                                             {1128, 636},
                                                             {960, 540},
                                                             {896, 504},
                                                             {760, 428},
                                                             {640, 360},
                                                             {500, 282},
                                                             {424, 240},
                                                             {1000, 1000}}) {
    for (int hz = 1; hz <= 60; ++hz) {
      std::vector<uint8_t> bytes = {kMode1};  // rx_pv's '<BHHBBBBIB' with no encoder options
      PutU16(&bytes, static_cast<uint16_t>(w));
      PutU16(&bytes, static_cast<uint16_t>(h));
      bytes.insert(bytes.end(), {static_cast<uint8_t>(hz), 1, kProfileH264Main, kLevelDefault});
      PutU32(&bytes, 5'000'000);
      bytes.push_back(0);
      const Parsed<PvConfig> parsed = ParsePvConfig(bytes.data(), bytes.size());
      const bool encoder_serves = !CheckPvFormat({w, h, hz});
      EXPECT_EQ(parsed.status == ParseStatus::kDone, encoder_serves) << w << "x" << h << " at " << hz;
      if (parsed.status != ParseStatus::kDone) continue;
      ++accepted;
      PvRefusal refusal;
      EXPECT_TRUE(PvEncoderConfigFromClient(parsed.value, 1, &refusal)) << refusal.reason;
    }
  }
  EXPECT_EQ(accepted, 25);
}

TEST(PvStream, TrailerFieldsFromTheSettingsTheClientSet) {
  PvSettings s;  // as the device starts: automatic exposure and ISO, no white-balance value
  const PvCaptureMetadata defaults;
  PvCaptureMetadata m = PvCaptureMetadataFromSettings(s);
  EXPECT_EQ(m.exposure_time_hns, defaults.exposure_time_hns);
  EXPECT_EQ(m.iso_speed, defaults.iso_speed);
  EXPECT_EQ(m.white_balance_k, defaults.white_balance_k);
  s.exposure = {0, 10000};      // manual, 10 000 µs (the device: TimeSpan(10 × value)) = 100 000 ticks
  s.iso_speed = {0, 400};       // manual, ISO 400
  s.white_balance_value = 200;  // × 25 K = 5000 K
  m = PvCaptureMetadataFromSettings(s);
  EXPECT_EQ(m.exposure_time_hns, 100000u);
  EXPECT_EQ(m.iso_speed, 400u);
  EXPECT_EQ(m.white_balance_k, 5000u);
  EXPECT_EQ(m.focus_state, defaults.focus_state);
}

TEST(PvStream, PacerTakesEvery30OverFpsThenAppliesTheDivisor) {
  PvConfig c;
  c.framerate = 15;
  c.divisor = 2;
  PvPacer pacer(c);
  std::vector<int> sent;
  for (int i = 0; i < 12; ++i)
    if (pacer.Next()) sent.push_back(i);
  EXPECT_EQ(sent, (std::vector<int>{0, 4, 8}));
  c.framerate = 5;  // 1504×846's slowest mode: every sixth camera frame
  c.divisor = 1;
  PvPacer slow(c);
  sent.clear();
  for (int i = 0; i < 13; ++i)
    if (slow.Next()) sent.push_back(i);
  EXPECT_EQ(sent, (std::vector<int>{0, 6, 12}));
}

TEST(PvStream, AfterALossOnlyTheKeyFrameAskedForAndWhatFollowsAreSent) {
  PvKeyFrameGate video(true);
  EXPECT_TRUE(video.Pass(false)) << "no loss yet: every picture";
  EXPECT_TRUE(video.OnDropped()) << "ask the encoder for a key frame";
  EXPECT_FALSE(video.Pass(false)) << "encoded before the request: undecodable after the loss";
  EXPECT_FALSE(video.Pass(false));
  EXPECT_TRUE(video.Pass(true)) << "the key frame";
  EXPECT_TRUE(video.Pass(false)) << "and the pictures after it";
  PvKeyFrameGate raw(false);
  EXPECT_FALSE(raw.OnDropped()) << "raw pictures are independent";
  EXPECT_TRUE(raw.Pass(false));
}

TEST(PvStream, CalibrationIsTheCameraOnTheRigNodeAtTheRequestedSize) {
  // K at 1280×720 asked at 1920×1080: ×1.5 about pixel edges.
  geometry::Intrinsics K;
  K.fx_px = 1000;
  K.fy_px = 1002;
  K.cx_px = 639.5;
  K.cy_px = 359.5;
  // A head turned 90° about W's z at (1, 2, 1.6); the camera 8 cm ahead of it, 2 cm up (H: y down).
  Eigen::Isometry3d X_WH = Eigen::Isometry3d::Identity();
  X_WH.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X_WH.translation() = Eigen::Vector3d(1, 2, 1.6);
  Eigen::Isometry3d X_HC = Eigen::Isometry3d::Identity();
  X_HC.translation() = Eigen::Vector3d(0, -0.02, 0.08);
  const Eigen::Isometry3d X_HN = X_CCh();  // the rig node: the head with the device's axes
  const std::vector<uint8_t> bytes = PvCalibrationFor(K, 1920, 1080, X_WH, X_WH * X_HC, X_HN);
  ASSERT_EQ(bytes.size(), 52u * 4);
  std::vector<float> f(52);
  std::memcpy(f.data(), bytes.data(), bytes.size());
  EXPECT_FLOAT_EQ(f[0], 1500.0f);
  EXPECT_FLOAT_EQ(f[1], 1503.0f);
  EXPECT_FLOAT_EQ(f[2], 959.5f);  // (639.5 + 0.5)·1.5 − 0.5
  EXPECT_FLOAT_EQ(f[3], 539.5f);
  // Extrinsics (row-vector, N → Ĉ): N is H flipped (y up, z back), Ĉ is C flipped the same way, so
  // Ĉ is N translated by X_HC's offset in N: p_Ĉ = p_N − (0, 0.02, −0.08).
  Eigen::Matrix4d E;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) E(r, c) = f[25 + 4 * r + c];
  const Eigen::RowVector4d p_Ch = Eigen::RowVector4d(0.1, 0.2, 0.3, 1) * E;
  EXPECT_NEAR(p_Ch[0], 0.1, 1e-6);
  EXPECT_NEAR(p_Ch[1], 0.2 - 0.02, 1e-6);
  EXPECT_NEAR(p_Ch[2], 0.3 + 0.08, 1e-6);
}

}  // namespace
}  // namespace orbed::hl2ss
