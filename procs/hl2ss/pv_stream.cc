#include "procs/hl2ss/pv_stream.h"

namespace orbed::hl2ss {

std::optional<PvRefusal> CheckPvClientFormat(const PvConfig& client) {
  const PvFormat format{client.width, client.height, client.framerate};
  const std::optional<std::string> why = CheckPvFormat(format);
  if (!why) return std::nullopt;
  bool size_known = false;
  for (const PvFormat& f : SupportedPvFormats())
    size_known = size_known || (f.width_px == client.width && f.height_px == client.height);
  return PvRefusal{size_known ? "pv/framerate" : "pv/size", *why};
}

std::optional<PvEncoderConfig> PvEncoderConfigFromClient(const PvConfig& client, int threads,
                                                         PvRefusal* refusal) {
  const auto refuse = [refusal](const std::string& key, const std::string& reason) {
    *refusal = PvRefusal{key, reason};
    return std::nullopt;
  };
  const std::optional<VideoProfile> profile = VideoProfileFromByte(client.profile);
  if (!profile) return refuse("pv/profile", "video profile " + std::to_string(client.profile));
  PvEncoderConfig c;
  c.format = {client.width, client.height, client.framerate};
  c.profile = *profile;
  c.divisor = client.divisor;
  c.bitrate_bps = client.bitrate;
  c.threads = threads;
  c.gop_frames = client.framerate;
  for (const auto& [key, value] : client.options) {
    if (key != kEncoderOptionGopSize || value == 0) continue;
    if (value > static_cast<std::uint64_t>(kMaxGopFrames))
      return refuse("pv/gop", "GOP size " + std::to_string(value) + " pictures (at most " +
                                  std::to_string(kMaxGopFrames) + ")");
    c.gop_frames = static_cast<int>(value);
  }
  if (auto format_refusal = CheckPvClientFormat(client)) {
    *refusal = *format_refusal;
    return std::nullopt;
  }
  if (c.profile != VideoProfile::kRaw && c.bitrate_bps > kMaxBitrateBps)
    return refuse("pv/bitrate", "bitrate " + std::to_string(c.bitrate_bps) + " bit/s (at most " +
                                    std::to_string(kMaxBitrateBps) + ")");
  if (auto why = CheckPvEncoderConfig(c)) return refuse("pv/config", *why);
  return c;
}

PvCaptureMetadata PvCaptureMetadataFromSettings(const PvSettings& s) {
  PvCaptureMetadata m;
  if (s.exposure[0] == 0) m.exposure_time_hns = static_cast<std::uint64_t>(s.exposure[1]) * 10;
  if (s.iso_speed[0] == 0) m.iso_speed = s.iso_speed[1];
  if (s.white_balance_value != 0) m.white_balance_k = s.white_balance_value * 25;
  return m;
}

std::vector<std::uint8_t> PvCalibrationFor(const geometry::Intrinsics& K_camera, int width_px, int height_px,
                                           const Eigen::Isometry3d& X_WH, const Eigen::Isometry3d& X_WC,
                                           const Eigen::Isometry3d& X_HN) {
  const Eigen::Isometry3d X_HC = X_WH.inverse() * X_WC;
  return PackPvCalibration(ScaleIntrinsics(K_camera, width_px, height_px), X_HN.inverse() * X_HC);
}

}  // namespace orbed::hl2ss
