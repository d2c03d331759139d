#include "procs/hl2ss/streams.h"

#include <stdexcept>

#include "procs/hl2ss/frames.h"

namespace orbed::hl2ss {

SiHead HeadInDevice(const Eigen::Isometry3d& X_WH) {
  const Eigen::Matrix3d R_DW = R_WD().transpose();
  SiHead h;
  h.position_D = R_DW * X_WH.translation();
  h.forward_D = R_DW * X_WH.linear() * Eigen::Vector3d::UnitZ();
  h.up_D = R_DW * X_WH.linear() * -Eigen::Vector3d::UnitY();
  return h;
}

std::vector<uint8_t> SiPayload(const std::optional<HeadSample>& head, const std::optional<GazeSample>& gaze) {
  std::vector<uint8_t> out;
  out.reserve(kSiPayloadBytes);
  const bool head_valid = head.has_value() && !head->tracking_lost;
  const bool eye_valid = head_valid && gaze.has_value();
  PutU32(&out, (head_valid ? kSiHeadValid : 0) | (eye_valid ? kSiEyeValid : 0));
  const auto put3 = [&out](const Eigen::Vector3d& v) {
    for (int i = 0; i < 3; ++i) PutF32(&out, static_cast<float>(v[i]));
  };
  if (head_valid) {
    const SiHead h = HeadInDevice(head->X_WH);
    put3(h.position_D);
    put3(h.forward_D);
    put3(h.up_D);
  } else {
    for (int i = 0; i < 9; ++i) PutF32(&out, 0.0f);
  }
  if (eye_valid) {
    const Eigen::Matrix3d R_DW = R_WD().transpose();
    put3(R_DW * gaze->origin_W_m);
    put3(R_DW * gaze->direction_W);
  } else {
    for (int i = 0; i < 6; ++i) PutF32(&out, 0.0f);
  }
  out.resize(kSiPayloadBytes, 0);  // both hands: not tracked
  return out;
}

std::vector<uint8_t> Nv12FromBgr(const cv::Mat& bgr, int stride) {
  if (bgr.type() != CV_8UC3 || bgr.cols % 2 || bgr.rows % 2 || stride < bgr.cols)
    throw std::invalid_argument("Nv12FromBgr: an 8-bit BGR picture of even size and a stride >= its width");
  const int w = bgr.cols, h = bgr.rows;
  std::vector<uint8_t> out(static_cast<size_t>(stride) * h * 3 / 2, 0);
  // BT.601 video range in 16-bit fixed point (coefficient × 65536 / 255, rounded):
  //   Y  = 16  + ( 65.481 R + 128.553 G + 24.966 B) / 255
  //   Cb = 128 + (−37.797 R −  74.203 G + 112.0  B) / 255
  //   Cr = 128 + ( 112.0  R −  93.786 G −  18.214 B) / 255
  constexpr int32_t kYR = 16829, kYG = 33039, kYB = 6416;
  constexpr int32_t kUR = -9714, kUG = -19070, kUB = 28784;
  constexpr int32_t kVR = 28784, kVG = -24103, kVB = -4681;
  const auto clamp8 = [](int32_t v) { return static_cast<uint8_t>(v < 0 ? 0 : v > 255 ? 255 : v); };
  for (int r = 0; r < h; ++r) {
    const uint8_t* p = bgr.ptr<uint8_t>(r);
    uint8_t* y = out.data() + static_cast<size_t>(r) * stride;
    for (int c = 0; c < w; ++c, p += 3)
      y[c] = clamp8((kYR * p[2] + kYG * p[1] + kYB * p[0] + (16 << 16) + (1 << 15)) >> 16);
  }
  uint8_t* uv_plane = out.data() + static_cast<size_t>(stride) * h;
  for (int r = 0; r < h / 2; ++r) {  // chroma of each 2 × 2 block's sums: the mean's, ÷ 4 = >> 2 more
    const uint8_t* p0 = bgr.ptr<uint8_t>(2 * r);
    const uint8_t* p1 = bgr.ptr<uint8_t>(2 * r + 1);
    uint8_t* uv = uv_plane + static_cast<size_t>(r) * stride;
    for (int c = 0; c < w / 2; ++c, p0 += 6, p1 += 6) {
      const int32_t B = p0[0] + p0[3] + p1[0] + p1[3], G = p0[1] + p0[4] + p1[1] + p1[4],
                    R = p0[2] + p0[5] + p1[2] + p1[5];
      uv[2 * c] = clamp8((kUR * R + kUG * G + kUB * B + (128 << 18) + (1 << 17)) >> 18);
      uv[2 * c + 1] = clamp8((kVR * R + kVG * G + kVB * B + (128 << 18) + (1 << 17)) >> 18);
    }
  }
  return out;
}

std::vector<uint8_t> BasicPvTrailer(const PvFrameInfo& info) {
  std::vector<uint8_t> out;
  out.reserve(kPvTrailerBytes);
  PutF32(&out, static_cast<float>(info.fx_px));
  PutF32(&out, static_cast<float>(info.fy_px));
  PutF32(&out, static_cast<float>(info.cx_px));
  PutF32(&out, static_cast<float>(info.cy_px));
  const PvSettings& s = *info.settings;
  PutU64(&out,
         s.exposure[0] == 0 ? static_cast<uint64_t>(s.exposure[1]) * 100 : 0);  // exposure time [100 ns]
  PutU64(&out, 0);  // exposure compensation (2 × u64)
  PutU64(&out, 0);
  PutU32(&out, 0);                                         // lens position
  PutU32(&out, 0);                                         // focus state
  PutU32(&out, s.iso_speed[0] == 0 ? s.iso_speed[1] : 0);  // ISO speed
  PutU32(&out, s.white_balance_value * 25);                // white balance [K] (0 when automatic)
  for (int i = 0; i < 5; ++i) PutF32(&out, 0.0f);          // ISO gains (2), white-balance gains (3)
  PutU16(&out, static_cast<uint16_t>(info.width));
  PutU16(&out, static_cast<uint16_t>(info.height));
  return out;
}

std::vector<uint8_t> RawPvPayload(const cv::Mat& bgr, const PvFrameInfo& info) {
  std::vector<uint8_t> out = Nv12FromBgr(bgr, PvStride(bgr.cols));
  const std::vector<uint8_t> trailer = BasicPvTrailer(info);
  out.insert(out.end(), trailer.begin(), trailer.end());
  return out;
}

PvEncoderFactory RawOnlyPvEncoderFactory() {
  return [](const PvConfig& config, std::string* refusal) -> PvPayloadFn {
    if (config.profile == kProfileRaw) return RawPvPayload;
    *refusal = "video profile " + std::to_string(config.profile) +
               ": H.264/H.265 encoding is not built into this orbed-hl2ss (RAW, profile 255, is served)";
    return nullptr;
  };
}

}  // namespace orbed::hl2ss
