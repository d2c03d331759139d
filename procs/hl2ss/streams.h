#pragma once
/// @file
/// The payloads of the streams this part serves, from orbed's messages, without sockets or bus:
///
/// Spatial input (3812, mode 0, protocol.h kSiPayloadBytes): the head as the device reports it
/// (HMD_POSE's X_WH, the SLAM estimate) as position, forward and up in D (frames.h; forward = the
/// head's +z, up = its −y: H is x right, y down, z along the line of sight), and the eye-gaze ray
/// (GAZE_RAY's origin and direction) in D. Validity flags as the device sets them: head valid when
/// a pose is known and tracking is not LOST (the device's pointer pose is then unavailable), eye
/// valid only with a valid head and a known ray; hands are never tracked (flags 0, joints zero).
///
/// Personal video (3810, modes 0 and 1): a frame's payload comes from a PvPayloadFn, made per
/// client by a PvEncoderFactory from the client's configuration, so that an encoder keeping state
/// between frames (H.264/H.265) drops in; RawPvEncoder serves the RAW profile: NV12 (BT.601 video
/// range, chroma the mean of each 2 × 2 block) with rows padded to a 64-byte stride as the device
/// sends (hl2ss.py pv_get_video_stride), then the 80-byte metadata trailer (BasicPvTrailer: focal
/// length, principal point and resolution filled in, the exposure fields from the RC settings,
/// the rest 0). The pose in mode 1 is HMD_CAMERA's X_WC (the estimate) converted with frames.h
/// CameraPoseForClient.
///
/// Threading: pure functions; a PvPayloadFn is called from one thread.

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "procs/hl2ss/emulated_device.h"
#include "procs/hl2ss/protocol.h"

namespace orbed::hl2ss {

// ---------------------------------------------------------------------------------------------
// Spatial input.
struct HeadSample {
  Eigen::Isometry3d X_WH;  ///< the SLAM estimate
  bool tracking_lost{false};
};
struct GazeSample {
  Eigen::Vector3d origin_W_m;
  Eigen::Vector3d direction_W;  ///< unit
};
/// Head position, forward and up in D (frames.h), as the SI payload carries them.
struct SiHead {
  Eigen::Vector3d position_D, forward_D, up_D;
};
SiHead HeadInDevice(const Eigen::Isometry3d& X_WH);
/// The SI payload (kSiPayloadBytes) from what is known now (nullopt = unknown or stale).
std::vector<uint8_t> SiPayload(const std::optional<HeadSample>& head, const std::optional<GazeSample>& gaze);

// ---------------------------------------------------------------------------------------------
// Personal video.
/// What one PV frame is, for the payload function: the picture's stamp and camera at the size the
/// client asked for.
struct PvFrameInfo {
  uint64_t timestamp{0};                          ///< hl2ss ticks
  int width{0}, height{0};                        ///< of `bgr`, the client's size
  double fx_px{0}, fy_px{0}, cx_px{0}, cy_px{0};  ///< intrinsics at that size
  const PvSettings* settings{nullptr};            ///< the RC settings (never null when called)
};
/// One frame's payload (encoded picture and trailer) from the picture at the client's size.
using PvPayloadFn = std::function<std::vector<uint8_t>(const cv::Mat& bgr, const PvFrameInfo& info)>;
/// Makes a client's payload function from its configuration, or returns nullptr and says why
/// (`*refusal`) when the configuration is not served.
using PvEncoderFactory = std::function<PvPayloadFn(const PvConfig& config, std::string* refusal)>;

/// The device's row stride for a PV width (64-byte aligned).
inline int PvStride(int width) { return (width + 63) & ~63; }
/// BGR (8-bit, even width and height) to NV12 rows of `stride` bytes: Y plane, then interleaved UV.
std::vector<uint8_t> Nv12FromBgr(const cv::Mat& bgr, int stride);
/// The 80-byte PV metadata trailer (hl2ss.py decode_pv's layout).
inline constexpr size_t kPvTrailerBytes = 80;
std::vector<uint8_t> BasicPvTrailer(const PvFrameInfo& info);
/// The RAW profile's payload: Nv12FromBgr at PvStride, then BasicPvTrailer.
std::vector<uint8_t> RawPvPayload(const cv::Mat& bgr, const PvFrameInfo& info);
/// The factory this part ships: RAW served, H.264/H.265 refused until an encoder is attached.
PvEncoderFactory RawOnlyPvEncoderFactory();

/// Which HMD_CAMERA frames (30 Hz) a PV client gets: at 15 fps every second one, then every
/// divisor-th of those. Call once per camera frame; true = send this one.
class PvPacer {
 public:
  explicit PvPacer(const PvConfig& config)
      : skip_(config.framerate == 15 ? 2 : 1), divisor_(config.divisor) {}
  bool Next() {
    const bool camera_due = (count_++ % skip_) == 0;
    if (!camera_due) return false;
    return (sent_++ % divisor_) == 0;
  }

 private:
  int64_t skip_, divisor_, count_{0}, sent_{0};
};

}  // namespace orbed::hl2ss
