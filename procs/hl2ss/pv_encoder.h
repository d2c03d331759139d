#pragma once
/// @file
/// The front (photo/video, PV) camera of an emulated HoloLens 2 as an hl2ss client receives it:
/// the payload of one PV packet (the picture, encoded, then the 80-byte metadata trailer) and the
/// mode-2 calibration. Pure library: the server (another file) frames packets, parses the
/// client's configuration and owns the sockets and clocks.
///
/// Protocol facts are hl2ss's public Python client (viewer/hl2ss.py, hl2ss_lnm.py, hl2ss_3dcv.py
/// of github.com/jdibenes/hl2ss, read in its 2025 form with the UNIX_EPOCH time base; the PV
/// layouts are unchanged from the 2024 form) and its server's PV channel:
///   payload     = image | trailer (80 bytes, little-endian):
///                 focal length f32[2] @0, principal point f32[2] @8, exposure time u64 @16 [100 ns],
///                 exposure compensation u64[2] @24, lens position u32 @40, focus state u32 @44,
///                 ISO speed u32 @48, white balance u32 @52 [K], ISO gains f32[2] @56,
///                 white-balance gains f32[3] @64, resolution u16[2] @76 (width, height).
///   RAW (0xFF)  image = NV12 with rows padded to stride = (width + 63) & ~63: height rows of Y,
///               then height/2 rows of interleaved U, V (the client cuts each row to width and
///               converts with OpenCV's COLOR_YUV2BGR_NV12: BT.601, limited range).
///   H.264       image = one Annex-B access unit that starts with a 6-byte access unit delimiter
///               (00 00 00 01 09 10): the client drops the first 6 bytes of every payload before
///               parsing, as the device's encoder starts each unit with one.
///   H.265       image = one Annex-B access unit, parsed whole.
/// Every client connection gets its own PvEncoder, so its first payload is an IDR picture carrying
/// the parameter sets (SPS and PPS, and the VPS for H.265) in band; every later IDR, one per GOP
/// (the client's CODECAPI_AVEncMPVGOPSize, default = the frame rate: one a second), carries them
/// again. No B-frames: each call returns the access unit of the picture it was given.
/// ForceKeyFrame makes the next picture an IDR (with its parameter sets) whatever the GOP, for a
/// client that lost a packet: H.264 and H.265 cannot be decoded past a lost picture until the next
/// IDR; the GOP counts on from it.
///
/// Profiles: the client's VideoProfile byte: 0 H.264 baseline, 1 main, 2 high, 3 H.265 main (the
/// client's default), 255 raw. The level byte and the other encoder options are not honoured
/// (libx264/libx265 choose the level). Bitrate: the client's, in bit/s (hl2ss_lnm's default is
/// width·height·fps·12/75 for H.264, /150 for H.265).
///
/// Frames: C orbed's camera (x right, y down, z forward), Ĉ the device's camera convention
/// (frames.h), N the rig node the research-mode sensors are calibrated against (rm_depth.h).
/// Pixel coordinates: orbed's (pixel centres at integers, geometry/camera_model.h); the focal
/// length and principal point sent are geometry::Intrinsics' values scaled to the requested size.
///
/// Threading: a PvEncoder is used by one thread at a time. The free functions are pure.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "geometry/camera_model.h"

namespace orbed::hl2ss {

/// hl2ss's VideoProfile byte.
enum class VideoProfile : std::uint8_t {
  kH264Base = 0,
  kH264Main = 1,
  kH264High = 2,
  kH265Main = 3,
  kRaw = 0xFF
};

/// The profile for a configuration byte, or nullopt for an unknown one.
std::optional<VideoProfile> VideoProfileFromByte(std::uint8_t byte);

/// A PV video mode: size and frame rate.
struct PvFormat {
  int width_px{1920};
  int height_px{1080};
  int framerate_hz{30};
};

/// The modes accepted: protocol.h PvVideoModes (the device's modes the 30 Hz emulated camera can
/// serve), the one list the client's configuration is parsed against too. The client's raw stride
/// is (width + 63) & ~63 for every one.
const std::vector<PvFormat>& SupportedPvFormats();

/// nullopt when `format` is a supported mode, else why not (names the accepted sizes or rates).
std::optional<std::string> CheckPvFormat(const PvFormat& format);

/// The row stride of a raw NV12 picture of this width [bytes]: (width + 63) & ~63.
int PvRawStride(int width_px);

/// What a client asks of its PV stream (the server parses the bytes into this).
struct PvEncoderConfig {
  PvFormat format;
  VideoProfile profile{VideoProfile::kH265Main};
  /// The client's divisor: the server sends every divisor-th picture (1 … 255), so the encoder
  /// sees framerate / divisor pictures a second.
  int divisor{1};
  std::uint32_t bitrate_bps{0};  ///< > 0 unless raw; at most kMaxBitrateBps
  int gop_frames{30};            ///< IDR period [pictures encoded], 1 … 600; ignored for raw
  int threads{1};                ///< encoder threads, 1 … 8 (the emulation's choice, not the client's)
};
inline constexpr std::uint32_t kMaxBitrateBps = 200'000'000;

/// nullopt when the configuration can be encoded, else why not.
std::optional<std::string> CheckPvEncoderConfig(const PvEncoderConfig& config);

/// The emulated camera's capture metadata (the trailer's fields other than the intrinsics and the
/// resolution). Defaults (documented choices, not measured on a device): 1/60 s exposure, no
/// exposure compensation, a fixed-focus lens (position 0, state FOCUSED = 3), ISO 100, 4500 K
/// white balance (operating-room light), unit ISO and white-balance gains.
struct PvCaptureMetadata {
  std::uint64_t exposure_time_hns{166'667};  ///< [100 ns]
  std::array<std::uint64_t, 2> exposure_compensation{0, 0};
  std::uint32_t lens_position{0};
  std::uint32_t focus_state{3};
  std::uint32_t iso_speed{100};
  std::uint32_t white_balance_k{4500};
  std::array<float, 2> iso_gains{1.0f, 1.0f};
  std::array<float, 3> white_balance_gains{1.0f, 1.0f, 1.0f};
};

inline constexpr int kPvTrailerBytes = 80;

/// `K` of a picture resized to width × height: each axis scaled about pixel edges (u' = s(u + ½)
/// − ½), as cv::resize maps pixels.
geometry::Intrinsics ScaleIntrinsics(const geometry::Intrinsics& K, int width_px, int height_px);

/// The 80-byte trailer for a picture of K's size.
std::array<std::uint8_t, kPvTrailerBytes> PackPvTrailer(const geometry::Intrinsics& K,
                                                        const PvCaptureMetadata& metadata);

/// The mode-2 calibration, 52 float32 (208 bytes) in the client's order: focal length (2),
/// principal point (2), radial distortion (3: 0, a pinhole), tangential distortion (2: 0),
/// projection (16: the matrix the client itself builds from f and c, row-vector convention,
/// [[−fx 0 0 0] [0 fy 0 0] [cx cy 1 0] [0 0 0 1]], mapping Ĉ to pixels), extrinsics (16: the
/// rig node to the camera, row-vector convention, [p_Ĉ 1] = [p_N 1]·E, so E = X_ĈNᵀ), the Media
/// Foundation intrinsics (4: fx, fy, cx, cy) and extrinsics (7: p_NĈ, then the quaternion of
/// R_NĈ as x, y, z, w). `K` at the requested size; X_NC the camera C in the rig node N.
std::vector<std::uint8_t> PackPvCalibration(const geometry::Intrinsics& K, const Eigen::Isometry3d& X_NC);

/// NV12 of a BGR picture (CV_8UC3, even width and height) with rows padded to `stride_px` (≥ width;
/// padding bytes 0): Y then interleaved UV, BT.601 limited range (OpenCV's BGR→I420). Appended to
/// *out.
void AppendNv12(const cv::Mat& bgr, int stride_px, std::vector<std::uint8_t>* out);

class PvEncoder {
 public:
  /// nullptr and *error set when the configuration is refused or the codec cannot be opened.
  static std::unique_ptr<PvEncoder> Create(const PvEncoderConfig& config, std::string* error);
  ~PvEncoder();
  PvEncoder(const PvEncoder&) = delete;
  PvEncoder& operator=(const PvEncoder&) = delete;

  /// One packet's payload for `bgr` (CV_8UC3, any size: resized to the configured one when it
  /// differs) taken by a camera with intrinsics `K_picture` (of bgr's size): the image as
  /// configured, then the trailer. Replaces *payload. False and *error, before any work, on a
  /// picture that is not BGR, is larger than 4096 pixels a side or does not match K_picture (size,
  /// finite positive focal lengths), and on an encoder failure.
  bool Encode(const cv::Mat& bgr, const geometry::Intrinsics& K_picture, const PvCaptureMetadata& metadata,
              std::vector<std::uint8_t>* payload, std::string* error);

  /// The next picture encoded is an IDR carrying the parameter sets (see the file comment). No
  /// effect for raw, whose pictures are all independent.
  void ForceKeyFrame() { key_frame_next_ = true; }

  const PvEncoderConfig& config() const { return config_; }
  std::int64_t frames() const { return frames_; }  ///< pictures encoded so far

 private:
  struct Codec;
  explicit PvEncoder(const PvEncoderConfig& config);
  bool EncodeVideo(const cv::Mat& bgr, std::vector<std::uint8_t>* payload, std::string* error);

  PvEncoderConfig config_;
  std::unique_ptr<Codec> codec_;  // null for raw
  cv::Mat resized_, i420_;
  std::int64_t frames_{0};
  bool key_frame_next_{false};
};

}  // namespace orbed::hl2ss
