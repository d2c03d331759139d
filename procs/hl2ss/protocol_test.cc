// The hl2ss protocol parsers and framing against bytes computed by hand from hl2ss.py's struct
// formats (little-endian; e.g. rx_pv's '<BHHBBBBI' + '<B' + '<QQ' per option). The emulated
// device's remote-configuration answers: emulated_device_test.cc.
#include "procs/hl2ss/protocol.h"

#include <gtest/gtest.h>

namespace orbed::hl2ss {
namespace {

std::vector<uint8_t> Hex(const std::string& hex) {
  std::vector<uint8_t> out;
  for (size_t i = 0; i + 1 < hex.size(); i += 2)
    out.push_back(static_cast<uint8_t>(std::stoi(hex.substr(i, 2), nullptr, 16)));
  return out;
}

TEST(Framing, PacketIsTimestampSizePayloadAndPoseInMode1) {
  const std::vector<uint8_t> payload = {0xAA, 0xBB};
  EXPECT_EQ(PackPacket(0x0102030405060708ULL, payload, nullptr), Hex("0807060504030201"
                                                                     "02000000"
                                                                     "aabb"));
  std::array<float, 16> pose{};
  pose[0] = 1.0f;    // 1.0f = 0x3F800000
  pose[15] = -2.0f;  // -2.0f = 0xC0000000
  const std::vector<uint8_t> p = PackPacket(7, payload, &pose);
  ASSERT_EQ(p.size(), 12u + 2 + 64);
  EXPECT_EQ(std::vector<uint8_t>(p.begin() + 14, p.begin() + 18), Hex("0000803f"));
  EXPECT_EQ(std::vector<uint8_t>(p.end() - 4, p.end()), Hex("000000c0"));
  EXPECT_EQ(GetU32(p.data() + 8), 2u);  // the size field counts the payload only
}

TEST(TimeBase, TicksAndUtcOffsetGiveBackTheUtime) {
  const TimeBase tb{1'700'000'000'000'000};                   // µs since the Unix epoch
  EXPECT_EQ(tb.TicksOf(1'700'000'001'000'000), 10'000'000u);  // one second after the origin
  EXPECT_EQ(tb.TicksOf(1'600'000'000'000'000), 0u);
  // 116444736000000000 + 1.7e15 µs × 10 (python: 133444736000000000).
  EXPECT_EQ(tb.UtcOffset(), 133'444'736'000'000'000ULL);
  const int64_t utime = 1'700'000'123'456'789;
  EXPECT_EQ(tb.TicksOf(utime) + tb.UtcOffset() - kFiletimeOfUnixEpoch, static_cast<uint64_t>(utime) * 10);
}

// rx_pv(mode=1, width=1920, height=1080, framerate=30, divisor=1, profile=RAW, level=DEFAULT,
// bitrate=1920·1080·30·12, options={GOP size (10): 30}).
const char kPvRaw1080[] =
    "01"
    "8007"
    "3804"
    "1e"
    "01"
    "ff"
    "ff"
    "00a07e2c"
    "01"
    "0a00000000000000"
    "1e00000000000000";

TEST(PvConfig, TheClientsStreamConfigurationParsesInAnyPieces) {
  const std::vector<uint8_t> bytes = Hex(kPvRaw1080);
  ASSERT_EQ(bytes.size(), 30u);
  for (size_t n = 0; n < bytes.size(); ++n)
    EXPECT_EQ(ParsePvConfig(bytes.data(), n).status, ParseStatus::kNeedMore) << n;
  const Parsed<PvConfig> p = ParsePvConfig(bytes.data(), bytes.size());
  ASSERT_EQ(p.status, ParseStatus::kDone) << p.reason;
  EXPECT_EQ(p.used, 30u);
  EXPECT_EQ(p.value.mode, kMode1);
  EXPECT_FALSE(p.value.start);
  EXPECT_EQ(p.value.width, 1920);
  EXPECT_EQ(p.value.height, 1080);
  EXPECT_EQ(p.value.framerate, 30);
  EXPECT_EQ(p.value.divisor, 1);
  EXPECT_EQ(p.value.profile, kProfileRaw);
  EXPECT_EQ(p.value.bitrate, 746'496'000u);
  ASSERT_EQ(p.value.options.size(), 1u);
  EXPECT_EQ(p.value.options[0], std::make_pair(uint64_t{10}, uint64_t{30}));
}

TEST(PvConfig, StartStopAndCalibration) {
  // start_subsystem_pv: mode byte 0x04|3, then '<BBBBBBBfffII' (hologram composition on,
  // opacity 0.9, hologram perspective PV).
  const std::vector<uint8_t> start =
      Hex("07"
          "00010000000000"
          "6666663f"
          "00000000"
          "00000000"
          "00000000"
          "01000000");
  const Parsed<PvConfig> s = ParsePvConfig(start.data(), start.size());
  ASSERT_EQ(s.status, ParseStatus::kDone) << s.reason;
  EXPECT_EQ(s.used, 28u);
  EXPECT_TRUE(s.value.start);
  EXPECT_FALSE(s.value.stop);
  EXPECT_EQ(s.value.mode, kMode3);
  EXPECT_TRUE(s.value.mrc.hologram_composition);
  EXPECT_FLOAT_EQ(s.value.mrc.global_opacity, 0.9f);
  EXPECT_EQ(s.value.mrc.hologram_perspective, 1u);
  const std::vector<uint8_t> stop = Hex("0b");
  const Parsed<PvConfig> t = ParsePvConfig(stop.data(), stop.size());
  ASSERT_EQ(t.status, ParseStatus::kDone);
  EXPECT_TRUE(t.value.stop);
  EXPECT_EQ(t.used, 1u);
  // download_calibration_pv(1280, 720, 30): mode 2 and the format only.
  const std::vector<uint8_t> cal =
      Hex("02"
          "0005"
          "d002"
          "1e");
  const Parsed<PvConfig> c = ParsePvConfig(cal.data(), cal.size());
  ASSERT_EQ(c.status, ParseStatus::kDone) << c.reason;
  EXPECT_EQ(c.used, 6u);
  EXPECT_EQ(c.value.mode, kMode2);
  EXPECT_EQ(c.value.width, 1280);
  EXPECT_EQ(c.value.height, 720);
}

TEST(PvConfig, EveryFieldOutOfRangeIsRefusedWithItsKey) {
  const auto refused = [](std::string hex) {
    const std::vector<uint8_t> b = Hex(hex);
    const Parsed<PvConfig> p = ParsePvConfig(b.data(), b.size());
    EXPECT_EQ(p.status, ParseStatus::kRefused) << hex;
    return p.key;
  };
  std::string h = kPvRaw1080;
  EXPECT_EQ(refused("10"), "pv/mode");
  EXPECT_EQ(refused(std::string("01") + "e803" + h.substr(6)), "pv/size");    // 1000 wide
  EXPECT_EQ(refused(h.substr(0, 10) + "3c" + h.substr(12)), "pv/framerate");  // 60 fps
  EXPECT_EQ(refused(h.substr(0, 12) + "00" + h.substr(14)), "pv/divisor");
  EXPECT_EQ(refused(h.substr(0, 14) + "07" + h.substr(16)), "pv/profile");
  EXPECT_EQ(refused(h.substr(0, 16) + "07" + h.substr(18)), "pv/level");
  EXPECT_EQ(refused(h.substr(0, 18) + "00000000" + h.substr(26)), "pv/bitrate");
  EXPECT_EQ(refused("07"
                    "02010000000000"
                    "6666663f"
                    "00000000"
                    "00000000"
                    "00000000"
                    "01000000"),
            "pv/mrc");
  EXPECT_EQ(refused("07"
                    "00010000000000"
                    "0000c07f"
                    "00000000"
                    "00000000"
                    "00000000"
                    "01000000"),
            "pv/mrc");  // NaN
}

TEST(RmDepthLongThrowConfig, ModeDivisorAndPngFilter) {
  const std::vector<uint8_t> b =
      Hex("01"
          "01"
          "05000000");  // mode 1, divisor 1, PAETH
  const Parsed<RmDepthLongThrowConfig> p = ParseRmDepthLongThrowConfig(b.data(), b.size());
  ASSERT_EQ(p.status, ParseStatus::kDone);
  EXPECT_EQ(p.used, 6u);
  EXPECT_EQ(p.value.png_filter, 5u);
  EXPECT_EQ(ParseRmDepthLongThrowConfig(b.data(), 5).status, ParseStatus::kNeedMore);
  const std::vector<uint8_t> cal = Hex("02");
  EXPECT_EQ(ParseRmDepthLongThrowConfig(cal.data(), 1).used, 1u);
  const std::vector<uint8_t> bad =
      Hex("01"
          "01"
          "07000000");
  EXPECT_EQ(ParseRmDepthLongThrowConfig(bad.data(), bad.size()).key, "rm_depth/png_filter");
  const std::vector<uint8_t> mode = Hex("03");
  EXPECT_EQ(ParseRmDepthLongThrowConfig(mode.data(), 1).key, "rm_depth/mode");
}

TEST(SiConfig, NothingIsExpectedAndAnyByteRefused) {
  EXPECT_EQ(ParseSiConfig(nullptr, 0).status, ParseStatus::kDone);
  const uint8_t one = 0;
  EXPECT_EQ(ParseSiConfig(&one, 1).key, "si/unexpected");
  EXPECT_EQ(kSiPayloadBytes, 4u + 15 * 4 + 2 * 26 * 9 * 4);  // 1936
}

TEST(RcCommand, FixedAndVariableLengthCommands) {
  const std::vector<uint8_t> offset = Hex("01");
  const Parsed<RcCommand> o = ParseRcCommand(offset.data(), 1);
  ASSERT_EQ(o.status, ParseStatus::kDone);
  EXPECT_EQ(o.value.id, RcCommandId::kGetUtcOffset);
  // pv_set_focus: '<BIIIII' manual (3), full range (0), infinity (0), 1000, driver fallback enabled (0).
  const std::vector<uint8_t> focus =
      Hex("04"
          "03000000"
          "00000000"
          "00000000"
          "e8030000"
          "00000000");
  const Parsed<RcCommand> f = ParseRcCommand(focus.data(), focus.size());
  ASSERT_EQ(f.status, ParseStatus::kDone) << f.reason;
  EXPECT_EQ(f.used, 21u);
  EXPECT_EQ(f.value.u, (std::vector<uint32_t>{3, 0, 0, 1000, 0}));
  EXPECT_EQ(ParseRcCommand(focus.data(), 20).status, ParseStatus::kNeedMore);
  // si_set_sampling_delay: '<Bq' 333333.
  const std::vector<uint8_t> delay =
      Hex("19"
          "1516050000000000");
  const Parsed<RcCommand> d = ParseRcCommand(delay.data(), delay.size());
  ASSERT_EQ(d.status, ParseStatus::kDone);
  EXPECT_EQ(static_cast<int64_t>(d.value.q[0]), 333333);
  // rm_get_rignode_world_poses: '<BI' count 2, then 2 × u64.
  const std::vector<uint8_t> rig =
      Hex("17"
          "02000000"
          "0100000000000000"
          "0200000000000000");
  const Parsed<RcCommand> r = ParseRcCommand(rig.data(), rig.size());
  ASSERT_EQ(r.status, ParseStatus::kDone);
  EXPECT_EQ(r.used, 21u);
  EXPECT_EQ(r.value.q, (std::vector<uint64_t>{1, 2}));
}

TEST(RcCommand, UnknownOutOfRangeAndHugeCountsAreRefusedBeforeTheirBytes) {
  const auto key = [](const std::string& hex) {
    const std::vector<uint8_t> b = Hex(hex);
    const Parsed<RcCommand> p = ParseRcCommand(b.data(), b.size());
    EXPECT_EQ(p.status, ParseStatus::kRefused) << hex;
    return p.key;
  };
  EXPECT_EQ(key("7f"), "rc/unknown");
  EXPECT_EQ(key("08"
                "00000000"
                "32000000"),
            "rc/pv_exposure");  // manual 50 < 100
  EXPECT_EQ(key("0a"
                "00000000"
                "10270000"),
            "rc/pv_iso_speed");  // 10000 > 3200
  EXPECT_EQ(key("0c"
                "01000000"),
            "rc/pv_scene_mode");
  EXPECT_EQ(key("14"
                "d0070000"
                "00000000"),
            "rc/interface_priority");  // port 2000
  EXPECT_EQ(key("17"
                "ffffffff"),
            "rc/rig_poses");  // before 34 GB of stamps
  EXPECT_EQ(key("16"
                "dd0e0000"
                "00000000"
                "ffffffff"),
            "rc/map_points");
  EXPECT_EQ(key("19"
                "0000000000000080"),
            "rc/si_sampling_delay");  // INT64_MIN
}

}  // namespace
}  // namespace orbed::hl2ss
