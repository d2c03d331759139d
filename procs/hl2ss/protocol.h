#pragma once
/// @file
/// The hl2ss wire protocol as a client speaks it, without sockets: ports, the time base, the packet
/// framing, and parsers for what a client sends first on each port this emulator serves. Facts
/// from hl2ss's public client (viewer/hl2ss.py and viewer/hl2ss_lnm.py of jdibenes/hl2ss, the
/// 2025 client with the sockopt argument, divisor, level and encoder options; docs/hl2ss.md).
///
/// Byte order: little-endian everywhere, as the client packs it (struct '<...').
///
/// Packets (every stream port): timestamp u64 (hl2ss ticks) | payload size u32 | payload | in
/// mode 1 a pose of 16 float32 (frames.h: PoseMatrixRowMajor). The client finds the pose by its
/// mode, not by the size field, so a mode-1 client always gets the 64 bytes.
///
/// Time base: hl2ss ticks are 100 ns since an arbitrary origin (the device's performance counter,
/// here the emulator's `qpc_origin_us`). The remote-configuration port answers the offset a client
/// adds to a tick count to get UTC as a Windows FILETIME (100 ns since 1601-01-01); so
/// utime_us = (ticks + offset - kFiletimeOfUnixEpoch) / 10 exactly for every stamp we send.
///
/// Parsers: each takes the bytes received so far and says kNeedMore, kDone (with how many bytes it
/// used and the parsed value) or kRefused (with a short key for PROCESS_STATUS and a reason). Every
/// field is range-checked; a count that announces more bytes is checked against its limit before
/// anything is allocated, so a parser never holds more than its largest legal message.
///
/// Threading: pure functions.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace orbed::hl2ss {

// ---------------------------------------------------------------------------------------------
// Ports (hl2ss.StreamPort, hl2ss.IPCPort).
inline constexpr int kPortRmDepthLongThrow = 3805;
inline constexpr int kPortRemoteConfiguration = 3809;
inline constexpr int kPortPersonalVideo = 3810;
inline constexpr int kPortSpatialInput = 3812;
inline constexpr int kPortUnityMessageQueue = 3816;  // the Unity plugin's message queue (unity_scene.h)

// ---------------------------------------------------------------------------------------------
// Time base (hl2ss.TimeBase).
inline constexpr int64_t kTicksPerSecond = 10'000'000;
/// The Unix epoch as a Windows FILETIME (100 ns ticks since 1601-01-01).
inline constexpr uint64_t kFiletimeOfUnixEpoch = 116'444'736'000'000'000ULL;

/// hl2ss ticks of orbed's clock: 10 per microsecond since `qpc_origin_us` (the emulated device's
/// power-on, µs since the Unix epoch). Stamps before the origin clamp to 0.
struct TimeBase {
  int64_t qpc_origin_us{0};
  uint64_t TicksOf(int64_t utime_us) const {
    return utime_us <= qpc_origin_us ? 0 : static_cast<uint64_t>(utime_us - qpc_origin_us) * 10;
  }
  /// What TS_GET_UTC_OFFSET answers: FILETIME(UTC) − ticks, constant for this emulator.
  uint64_t UtcOffset() const { return kFiletimeOfUnixEpoch + static_cast<uint64_t>(qpc_origin_us) * 10; }
  /// The utime [µs since the Unix epoch] of a tick count: the inverse of TicksOf (to the µs below).
  int64_t UtimeOf(uint64_t ticks) const { return qpc_origin_us + static_cast<int64_t>(ticks / 10); }
  /// The FILETIME of `utime_us` (TS_GET_CURRENT_TIME with source UTC).
  static uint64_t FiletimeOf(int64_t utime_us) {
    return kFiletimeOfUnixEpoch + static_cast<uint64_t>(utime_us) * 10;
  }
};

// ---------------------------------------------------------------------------------------------
// Framing.
inline constexpr size_t kHeaderBytes = 12;  // timestamp u64, payload size u32
inline constexpr size_t kPoseBytes = 64;    // 16 float32, mode 1 only

/// One packet as the client unpacks it; `pose` is appended when non-null.
std::vector<uint8_t> PackPacket(uint64_t timestamp, const std::vector<uint8_t>& payload,
                                const std::array<float, 16>* pose);

/// Little-endian readers/writers for the payload builders and tests.
void PutU16(std::vector<uint8_t>* out, uint16_t v);
void PutU32(std::vector<uint8_t>* out, uint32_t v);
void PutU64(std::vector<uint8_t>* out, uint64_t v);
void PutF32(std::vector<uint8_t>* out, float v);
uint16_t GetU16(const uint8_t* p);
uint32_t GetU32(const uint8_t* p);
uint64_t GetU64(const uint8_t* p);
float GetF32(const uint8_t* p);

// ---------------------------------------------------------------------------------------------
// Parse results.
enum class ParseStatus { kNeedMore, kDone, kRefused };

template <class T>
struct Parsed {
  ParseStatus status{ParseStatus::kNeedMore};
  size_t used{0};      ///< bytes consumed (kDone)
  T value{};           ///< kDone
  std::string key;     ///< kRefused: short class, e.g. "pv/width"
  std::string reason;  ///< kRefused: for the log
};

// ---------------------------------------------------------------------------------------------
// Stream modes (hl2ss.StreamMode): 0 data, 1 data + pose, 2 calibration; the PV port's mode byte
// also carries the subsystem control bits (hl2ss.py _PVCNT: START 0x04, STOP 0x08) and mode 3
// (no stream: a control-only connection).
inline constexpr uint8_t kMode0 = 0, kMode1 = 1, kMode2 = 2, kMode3 = 3;
inline constexpr uint8_t kPvStart = 0x04, kPvStop = 0x08;

/// hl2ss.VideoProfile.
inline constexpr uint8_t kProfileH264Base = 0, kProfileH264Main = 1, kProfileH264High = 2,
                         kProfileH265Main = 3, kProfileRaw = 0xFF;
/// hl2ss.H26xLevel.DEFAULT.
inline constexpr uint8_t kLevelDefault = 0xFF;
/// The encoder options a client may send (u8 count of u64 key/value pairs).
inline constexpr int kMaxEncoderOptions = 255;

/// The PV video modes served: the HoloLens 2 PV camera's own (Microsoft's locatable-camera table)
/// at the rates the emulated camera, which runs at kPvCameraHz, can deliver (those dividing it):
/// 2272×1278, 1952×1100, 1920×1080, 1280×720, 1128×636, 960×540, 896×504, 760×428, 640×360,
/// 500×282 and 424×240 at 15 and 30 Hz; 1504×846 at 5, 15 and 30 Hz. The device's 60 Hz modes
/// (1952×1100, 1504×846) are refused. The one list of PV modes: the parser checks a client's
/// against it, and pv_encoder.h SupportedPvFormats is made from it.
struct PvVideoMode {
  int width, height, framerate;
};
inline constexpr int kPvCameraHz = 30;
const std::vector<PvVideoMode>& PvVideoModes();

/// Mixed-reality-capture options sent with the START bit (hl2ss.py _create_configuration_for_mrc_video,
/// '<BBBBBBBfffII').
struct MrcVideoOptions {
  bool enable{false}, hologram_composition{false}, recording_indicator{false}, video_stabilization{false},
      blank_protected{false}, show_mesh{false}, shared{false};
  float global_opacity{0}, output_width{0}, output_height{0};
  uint32_t video_stabilization_length{0}, hologram_perspective{0};
};
inline constexpr size_t kMrcVideoOptionsBytes = 7 + 3 * 4 + 2 * 4;

/// What a client sends first on the PV port (3810).
struct PvConfig {
  uint8_t mode{kMode1};  ///< 0, 1 (stream), 2 (calibration), 3 (control only)
  bool start{false};     ///< START bit: open the subsystem with `mrc` first
  bool stop{false};      ///< STOP bit: close the subsystem after
  MrcVideoOptions mrc;   ///< with `start`
  uint16_t width{0}, height{0};
  uint8_t framerate{0};  ///< frames per second asked for (a PvVideoModes rate of the size)
  uint8_t divisor{1};    ///< send every divisor-th frame (≥ 1); modes 0 and 1
  uint8_t profile{kProfileRaw};
  uint8_t level{kLevelDefault};
  uint32_t bitrate{0};                                 ///< bits per second (> 0), for the encoder
  std::vector<std::pair<uint64_t, uint64_t>> options;  ///< encoder options, as sent
};
Parsed<PvConfig> ParsePvConfig(const uint8_t* data, size_t size);

/// What a client sends first on the RM depth long-throw port (3805): mode, and in modes 0 and 1
/// the divisor (u8 ≥ 1) and the PNG filter (u32, hl2ss.PNGFilterMode 0..6).
struct RmDepthLongThrowConfig {
  uint8_t mode{kMode1};
  uint8_t divisor{1};
  uint32_t png_filter{0};
};
Parsed<RmDepthLongThrowConfig> ParseRmDepthLongThrowConfig(const uint8_t* data, size_t size);

/// The spatial-input port (3812) takes no configuration: the client connects and reads mode-0
/// packets. Any byte it sends is refused.
struct SiConfig {};
Parsed<SiConfig> ParseSiConfig(const uint8_t* data, size_t size);

/// The spatial-input payload (hl2ss.py decode_si): valid u32 (bit 0 head, 1 eye, 2 left hand,
/// 3 right hand), head position, forward, up (3 × 3 float32), eye-ray origin and direction
/// (2 × 3 float32), 26 joints per hand × 2 hands × (orientation 4, position 3, radius 1 float32,
/// accuracy i32). All in the device frame D, metres.
inline constexpr uint32_t kSiHeadValid = 0x01, kSiEyeValid = 0x02, kSiLeftHandValid = 0x04,
                          kSiRightHandValid = 0x08;
inline constexpr int kSiHandJoints = 26;
inline constexpr size_t kSiPayloadBytes = 4 + (9 + 6) * 4 + 2 * kSiHandJoints * 9 * 4;

// ---------------------------------------------------------------------------------------------
// Remote configuration (port 3809, hl2ss.py ipc_rc): a stream of commands, each a command byte
// and its arguments; some are answered.
enum class RcCommandId : uint8_t {
  kGetApplicationVersion = 0x00,  // -> 4 × u16
  kGetUtcOffset = 0x01,           // -> u64
  kSetMarkerState = 0x02,         // u32
  kGetPvSubsystemStatus = 0x03,   // -> u8 (bool)
  kSetPvFocus = 0x04,             // 5 × u32: mode, auto range, distance, value, driver fallback
  kSetPvVideoTemporalDenoising = 0x05,
  kSetPvWhiteBalancePreset = 0x06,
  kSetPvWhiteBalanceValue = 0x07,
  kSetPvExposure = 0x08,  // 2 × u32: mode, value
  kSetPvExposurePriorityVideo = 0x09,
  kSetPvIsoSpeed = 0x0A,  // 2 × u32: mode, value
  kSetPvBacklightCompensation = 0x0B,
  kSetPvSceneMode = 0x0C,
  kSetFlatMode = 0x0D,
  kSetRmEyeSelection = 0x0E,
  kSetPvDesiredOptimization = 0x0F,
  kSetPvPrimaryUse = 0x10,
  kSetPvOpticalImageStabilization = 0x11,
  kSetPvHdrVideo = 0x12,
  kSetPvRegionsOfInterest = 0x13,  // u32 mode bits, 4 × float32: x, y, w, h
  kSetInterfacePriority = 0x14,    // u32 port, i32 priority
  kSetQuietMode = 0x15,
  kRmMapCameraPoints = 0x16,       // u32 port, u32 operation, u32 count, count × 2 float32
  kRmGetRigNodeWorldPoses = 0x17,  // u32 count, count × u64 timestamps -> count × 16 float32
  kGetCurrentTime = 0x18,          // u32 source (0 QPC, 1 UTC) -> u64
  kSetSiSamplingDelay = 0x19,      // i64 [ticks]
};
/// The largest count accepted in the two variable-length commands (a 320×288 image's pixels).
inline constexpr uint32_t kMaxRcPoints = 320 * 288;

struct RcCommand {
  RcCommandId id{RcCommandId::kGetApplicationVersion};
  std::vector<uint32_t> u;  ///< the u32 arguments in order (i32 ones as their bits)
  std::vector<float> f;     ///< float32 arguments (regions of interest; map points' coordinates)
  std::vector<uint64_t> q;  ///< u64 / i64 arguments (rig-node timestamps, sampling delay)
};
Parsed<RcCommand> ParseRcCommand(const uint8_t* data, size_t size);
/// Whether the command is answered (and the client waits for it).
bool RcAnswers(RcCommandId id);
std::string RcCommandName(RcCommandId id);

}  // namespace orbed::hl2ss
