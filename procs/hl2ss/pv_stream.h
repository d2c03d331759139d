#pragma once
/// @file
/// What the PV port (3810) serves a client, from its parsed configuration (protocol.h PvConfig)
/// and the emulated device's state, without sockets, threads or bus:
///   - PvEncoderConfigFromClient: the client's bytes as a pv_encoder.h configuration, or a refusal
///     with its counted key: "pv/profile" (a profile byte pv_encoder does not know), "pv/size" and
///     "pv/framerate" (a mode pv_encoder.h SupportedPvFormats does not list), "pv/bitrate" (above
///     kMaxBitrateBps), "pv/gop" (a GOP above 600 pictures). The parser (protocol.h) refuses most
///     of these first under the same keys; these checks keep pv_encoder's the one definition.
///     The GOP is the client's CODECAPI_AVEncMPVGOPSize encoder option (hl2ss.py
///     H26xEncoderProperty key 10); absent or 0 (the Media Foundation encoder's "choose"), it is
///     the frame rate, hl2ss_lnm's default: one IDR a second. Other encoder options and the level
///     byte are accepted and not honoured (pv_encoder.h).
///   - PvCaptureMetadataFromSettings: the trailer's capture fields from the RC settings the client
///     set (emulated_device.h PvSettings): exposure time when exposure is manual (mode 0; value in
///     µs → ×10 ticks of 100 ns, as the device server's TimeSpan(10 × value)), ISO speed when manual (mode
///     0), white balance when a value was set (units of 25 K); every other field, and those not set,
///     pv_encoder.h's documented PvCaptureMetadata defaults.
///   - PvPacer: which 30 Hz camera frames a client gets (a mode's rate divides 30, protocol.h
///     PvVideoModes: 15 fps every second one, 5 fps every sixth; then every divisor-th of those).
///   - PvKeyFrameGate: after a packet to an H.264/H.265 client is lost (its send queue full), the
///     client decodes nothing until an IDR: its encoder is asked for one and the pictures finished
///     before it are withheld, so the next picture sent is that IDR. Raw clients are not gated.
///   - PvCalibrationFor: the mode-2 answer: pv_encoder.h PackPvCalibration with K the camera's
///     (HMD_CAMERA's) scaled to the requested size and X_NC = X_HN⁻¹ · X_HC, X_HC = X_WH⁻¹ · X_WC
///     from one HMD_POSE (the estimate), N the rig node of rm_depth.h (LongThrowOptions::X_HN).
///
/// Frames: W world, H head, C orbed's camera, N the rig node. Units: SI; pixels as geometry::
/// Intrinsics (pixel centres at integers).
/// Threading: pure functions; a PvPacer is used by one thread.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "geometry/camera_model.h"
#include "procs/hl2ss/emulated_device.h"
#include "procs/hl2ss/protocol.h"
#include "procs/hl2ss/pv_encoder.h"

namespace orbed::hl2ss {

/// hl2ss.py H26xEncoderProperty.CODECAPI_AVEncMPVGOPSize.
inline constexpr std::uint64_t kEncoderOptionGopSize = 10;
inline constexpr int kMaxGopFrames = 600;

/// A refusal: the PROCESS_STATUS key and the reason for the log.
struct PvRefusal {
  std::string key, reason;
};

/// nullopt when the client's size and frame rate are a mode the emulated camera offers (pv_encoder.h
/// SupportedPvFormats), else the refusal ("pv/size", "pv/framerate"). For every mode but 3.
std::optional<PvRefusal> CheckPvClientFormat(const PvConfig& client);

/// The encoder configuration for a mode-0/1 client, or the refusal (see the file comment).
/// `threads`: the encoder threads (the emulation's choice).
std::optional<PvEncoderConfig> PvEncoderConfigFromClient(const PvConfig& client, int threads,
                                                         PvRefusal* refusal);

/// The trailer's capture fields from the RC settings (see the file comment).
PvCaptureMetadata PvCaptureMetadataFromSettings(const PvSettings& settings);

/// Which HMD_CAMERA frames (kPvCameraHz) a PV client gets: every (30 / framerate)-th, then every
/// divisor-th of those. Call once per camera frame; true = send this one. A framerate that does
/// not divide 30 (never parsed) counts as 30.
class PvPacer {
 public:
  explicit PvPacer(const PvConfig& config)
      : skip_(config.framerate > 0 && kPvCameraHz % config.framerate == 0 ? kPvCameraHz / config.framerate
                                                                          : 1),
        divisor_(config.divisor < 1 ? 1 : config.divisor) {}
  bool Next() {
    const bool camera_due = (count_++ % skip_) == 0;
    if (!camera_due) return false;
    return (sent_++ % divisor_) == 0;
  }

 private:
  std::int64_t skip_, divisor_, count_{0}, sent_{0};
};

/// See the file comment. One per PV client, used by the process thread.
class PvKeyFrameGate {
 public:
  explicit PvKeyFrameGate(bool video) : video_(video) {}
  /// A packet to the client was dropped. True: ask its encoder for a key frame.
  bool OnDropped() {
    awaiting_ = video_;
    return video_;
  }
  /// Whether to send a finished picture (`key_frame`: encoded as the key frame asked for); false:
  /// withhold it (the client could not decode it).
  bool Pass(bool key_frame) {
    if (awaiting_ && !key_frame) return false;
    awaiting_ = false;
    return true;
  }

 private:
  bool video_;
  bool awaiting_{false};
};

/// The mode-2 bytes for a client asking `width_px` × `height_px`: K_camera (the camera's, at its
/// own size) scaled to that size; the camera on the rig node from one HMD_POSE's X_WH and X_WC.
std::vector<std::uint8_t> PvCalibrationFor(const geometry::Intrinsics& K_camera, int width_px, int height_px,
                                           const Eigen::Isometry3d& X_WH, const Eigen::Isometry3d& X_WC,
                                           const Eigen::Isometry3d& X_HN);

}  // namespace orbed::hl2ss
