#include "procs/hl2ss/protocol.h"

#include <cmath>
#include <cstring>

namespace orbed::hl2ss {
namespace {

template <class T>
Parsed<T> NeedMore() {
  return {};
}

template <class T>
Parsed<T> Refuse(const std::string& key, const std::string& reason) {
  Parsed<T> p;
  p.status = ParseStatus::kRefused;
  p.key = key;
  p.reason = reason;
  return p;
}

template <class T>
Parsed<T> Done(size_t used, T value) {
  Parsed<T> p;
  p.status = ParseStatus::kDone;
  p.used = used;
  p.value = std::move(value);
  return p;
}

std::string OutOf(const std::string& what, int64_t value, int64_t lo, int64_t hi) {
  return what + " " + std::to_string(value) + " outside " + std::to_string(lo) + ".." + std::to_string(hi);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
void PutU16(std::vector<uint8_t>* out, uint16_t v) {
  for (int i = 0; i < 2; ++i) out->push_back(static_cast<uint8_t>(v >> (8 * i)));
}
void PutU32(std::vector<uint8_t>* out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<uint8_t>(v >> (8 * i)));
}
void PutU64(std::vector<uint8_t>* out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out->push_back(static_cast<uint8_t>(v >> (8 * i)));
}
void PutF32(std::vector<uint8_t>* out, float v) {
  uint32_t bits;
  std::memcpy(&bits, &v, 4);
  PutU32(out, bits);
}
uint16_t GetU16(const uint8_t* p) { return static_cast<uint16_t>(p[0] | (p[1] << 8)); }
uint32_t GetU32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | (static_cast<uint32_t>(p[1]) << 8) |
         (static_cast<uint32_t>(p[2]) << 16) | (static_cast<uint32_t>(p[3]) << 24);
}
uint64_t GetU64(const uint8_t* p) { return GetU32(p) | (static_cast<uint64_t>(GetU32(p + 4)) << 32); }
float GetF32(const uint8_t* p) {
  const uint32_t bits = GetU32(p);
  float v;
  std::memcpy(&v, &bits, 4);
  return v;
}

std::vector<uint8_t> PackPacket(uint64_t timestamp, const std::vector<uint8_t>& payload,
                                const std::array<float, 16>* pose) {
  std::vector<uint8_t> out;
  out.reserve(kHeaderBytes + payload.size() + (pose ? kPoseBytes : 0));
  PutU64(&out, timestamp);
  PutU32(&out, static_cast<uint32_t>(payload.size()));
  out.insert(out.end(), payload.begin(), payload.end());
  if (pose)
    for (float v : *pose) PutF32(&out, v);
  return out;
}

// ---------------------------------------------------------------------------------------------
const std::vector<PvVideoMode>& PvVideoModes() {
  static const std::vector<PvVideoMode> kModes = [] {
    std::vector<PvVideoMode> m;
    for (const auto& [w, h] : std::vector<std::pair<int, int>>{{2272, 1278},
                                                               {1952, 1100},
                                                               {1920, 1080},
                                                               {1280, 720},
                                                               {1128, 636},
                                                               {960, 540},
                                                               {896, 504},
                                                               {760, 428},
                                                               {640, 360},
                                                               {500, 282},
                                                               {424, 240}})
      for (int hz : {15, 30}) m.push_back({w, h, hz});
    for (int hz : {5, 15, 30}) m.push_back({1504, 846, hz});
    return m;
  }();
  return kModes;
}

namespace {

// "" or why the video format is refused (and *key its class).
std::string CheckVideoFormat(uint16_t width, uint16_t height, uint8_t framerate, std::string* key) {
  bool size_known = false;
  for (const PvVideoMode& m : PvVideoModes()) {
    if (m.width != width || m.height != height) continue;
    if (m.framerate == framerate) return "";
    size_known = true;
  }
  if (!size_known) {
    *key = "pv/size";
    return "video size " + std::to_string(width) + "x" + std::to_string(height) +
           " is not one the camera offers";
  }
  *key = "pv/framerate";
  return "framerate " + std::to_string(framerate) + " at " + std::to_string(width) + "x" +
         std::to_string(height) + " is not a mode the emulated camera serves (protocol.h PvVideoModes)";
}

bool KnownLevel(uint8_t level) {
  static const uint8_t kLevels[] = {10,  11,  12,  13,  20,  21,  22,  30,  31,           32,
                                    40,  41,  42,  50,  51,  52,  60,  63,  90,           93,
                                    120, 123, 150, 153, 156, 180, 183, 186, kLevelDefault};
  for (uint8_t l : kLevels)
    if (l == level) return true;
  return false;
}

}  // namespace

Parsed<PvConfig> ParsePvConfig(const uint8_t* data, size_t size) {
  if (size < 1) return NeedMore<PvConfig>();
  PvConfig c;
  const uint8_t m = data[0];
  if (m & 0xF0) return Refuse<PvConfig>("pv/mode", "mode byte " + std::to_string(m) + " has bits above 0x0F");
  c.mode = m & 0x03;
  c.start = (m & kPvStart) != 0;
  c.stop = (m & kPvStop) != 0;
  size_t at = 1;
  if (c.start) {
    if (size < at + kMrcVideoOptionsBytes) return NeedMore<PvConfig>();
    const uint8_t* p = data + at;
    for (int i = 0; i < 7; ++i)
      if (p[i] > 1)
        return Refuse<PvConfig>("pv/mrc", "MRC flag " + std::to_string(i) + " is " + std::to_string(p[i]));
    c.mrc.enable = p[0];
    c.mrc.hologram_composition = p[1];
    c.mrc.recording_indicator = p[2];
    c.mrc.video_stabilization = p[3];
    c.mrc.blank_protected = p[4];
    c.mrc.show_mesh = p[5];
    c.mrc.shared = p[6];
    c.mrc.global_opacity = GetF32(p + 7);
    c.mrc.output_width = GetF32(p + 11);
    c.mrc.output_height = GetF32(p + 15);
    c.mrc.video_stabilization_length = GetU32(p + 19);
    c.mrc.hologram_perspective = GetU32(p + 23);
    if (!(c.mrc.global_opacity >= 0.0f && c.mrc.global_opacity <= 1.0f))
      return Refuse<PvConfig>("pv/mrc", "global opacity outside 0..1");
    if (!(c.mrc.output_width >= 0.0f && c.mrc.output_width <= 8192.0f) ||
        !(c.mrc.output_height >= 0.0f && c.mrc.output_height <= 8192.0f))
      return Refuse<PvConfig>("pv/mrc", "MRC output size outside 0..8192");
    if (c.mrc.video_stabilization_length > 30)
      return Refuse<PvConfig>("pv/mrc",
                              OutOf("video stabilization length", c.mrc.video_stabilization_length, 0, 30));
    if (c.mrc.hologram_perspective > 1)
      return Refuse<PvConfig>("pv/mrc", OutOf("hologram perspective", c.mrc.hologram_perspective, 0, 1));
    at += kMrcVideoOptionsBytes;
  }
  if (c.mode == kMode3) return Done(at, std::move(c));
  // Modes 0, 1, 2: the video format.
  if (size < at + 5) return NeedMore<PvConfig>();
  c.width = GetU16(data + at);
  c.height = GetU16(data + at + 2);
  c.framerate = data[at + 4];
  at += 5;
  std::string key;
  const std::string problem = CheckVideoFormat(c.width, c.height, c.framerate, &key);
  if (!problem.empty()) return Refuse<PvConfig>(key, problem);
  if (c.mode == kMode2) return Done(at, std::move(c));
  // Modes 0 and 1: divisor, profile, level, bitrate, encoder options.
  if (size < at + 8) return NeedMore<PvConfig>();
  c.divisor = data[at];
  c.profile = data[at + 1];
  c.level = data[at + 2];
  c.bitrate = GetU32(data + at + 3);
  const uint8_t count = data[at + 7];
  at += 8;
  if (c.divisor < 1) return Refuse<PvConfig>("pv/divisor", "divisor 0");
  if (c.profile > kProfileH265Main && c.profile != kProfileRaw)
    return Refuse<PvConfig>("pv/profile", "video profile " + std::to_string(c.profile));
  if (!KnownLevel(c.level)) return Refuse<PvConfig>("pv/level", "H.26x level " + std::to_string(c.level));
  if (c.bitrate == 0) return Refuse<PvConfig>("pv/bitrate", "bitrate 0");
  if (size < at + 16u * count) return NeedMore<PvConfig>();
  for (int i = 0; i < count; ++i)
    c.options.emplace_back(GetU64(data + at + 16 * i), GetU64(data + at + 16 * i + 8));
  at += 16u * count;
  return Done(at, std::move(c));
}

Parsed<RmDepthLongThrowConfig> ParseRmDepthLongThrowConfig(const uint8_t* data, size_t size) {
  if (size < 1) return NeedMore<RmDepthLongThrowConfig>();
  RmDepthLongThrowConfig c;
  c.mode = data[0];
  if (c.mode > kMode2) return Refuse<RmDepthLongThrowConfig>("rm_depth/mode", OutOf("mode", c.mode, 0, 2));
  if (c.mode == kMode2) return Done<RmDepthLongThrowConfig>(1, c);
  if (size < 6) return NeedMore<RmDepthLongThrowConfig>();
  c.divisor = data[1];
  c.png_filter = GetU32(data + 2);
  if (c.divisor < 1) return Refuse<RmDepthLongThrowConfig>("rm_depth/divisor", "divisor 0");
  if (c.png_filter > 6)
    return Refuse<RmDepthLongThrowConfig>("rm_depth/png_filter", OutOf("PNG filter", c.png_filter, 0, 6));
  return Done<RmDepthLongThrowConfig>(6, c);
}

Parsed<SiConfig> ParseSiConfig(const uint8_t* /*data*/, size_t size) {
  if (size > 0)
    return Refuse<SiConfig>("si/unexpected", "the spatial-input port takes no bytes from a client");
  return Done<SiConfig>(0, SiConfig{});
}

// ---------------------------------------------------------------------------------------------
namespace {

struct RcShape {
  int u32s;  // fixed u32 arguments after the command byte
  int i64s;  // fixed 64-bit arguments
};

// Fixed argument shapes by command (the two variable-length ones are handled apart).
bool Shape(uint8_t id, RcShape* s) {
  switch (static_cast<RcCommandId>(id)) {
    case RcCommandId::kGetApplicationVersion:
    case RcCommandId::kGetUtcOffset:
    case RcCommandId::kGetPvSubsystemStatus:
      *s = {0, 0};
      return true;
    case RcCommandId::kSetPvFocus:
      *s = {5, 0};
      return true;
    case RcCommandId::kSetPvExposure:
    case RcCommandId::kSetPvIsoSpeed:
    case RcCommandId::kSetInterfacePriority:
      *s = {2, 0};
      return true;
    case RcCommandId::kSetPvRegionsOfInterest:
      *s = {5, 0};  // mode and the 4 floats' bits
      return true;
    case RcCommandId::kSetSiSamplingDelay:
      *s = {0, 1};
      return true;
    case RcCommandId::kSetMarkerState:
    case RcCommandId::kSetPvVideoTemporalDenoising:
    case RcCommandId::kSetPvWhiteBalancePreset:
    case RcCommandId::kSetPvWhiteBalanceValue:
    case RcCommandId::kSetPvExposurePriorityVideo:
    case RcCommandId::kSetPvBacklightCompensation:
    case RcCommandId::kSetPvSceneMode:
    case RcCommandId::kSetFlatMode:
    case RcCommandId::kSetRmEyeSelection:
    case RcCommandId::kSetPvDesiredOptimization:
    case RcCommandId::kSetPvPrimaryUse:
    case RcCommandId::kSetPvOpticalImageStabilization:
    case RcCommandId::kSetPvHdrVideo:
    case RcCommandId::kSetQuietMode:
    case RcCommandId::kGetCurrentTime:
      *s = {1, 0};
      return true;
    default:
      return false;
  }
}

// "" or why the fixed arguments of `c` are refused.
std::string CheckRcArguments(const RcCommand& c) {
  const auto in = [&](size_t i, int64_t lo, int64_t hi, const char* what) -> std::string {
    const int64_t v = c.u[i];
    return v < lo || v > hi ? OutOf(what, v, lo, hi) : "";
  };
  switch (c.id) {
    case RcCommandId::kSetMarkerState:
      return in(0, 0, 1, "marker state");
    case RcCommandId::kSetPvFocus: {
      std::string r = in(0, 0, 3, "focus mode");
      if (r.empty()) r = in(1, 0, 2, "auto focus range");
      if (r.empty() && c.u[2] != 0 && c.u[2] != 2)
        r = "manual focus distance " + std::to_string(c.u[2]) + " (0 or 2)";
      if (r.empty()) r = in(3, 170, 10000, "focus value");
      if (r.empty()) r = in(4, 0, 1, "driver fallback");
      return r;
    }
    case RcCommandId::kSetPvVideoTemporalDenoising:
      return in(0, 0, 1, "temporal denoising");
    case RcCommandId::kSetPvWhiteBalancePreset:
      return in(0, 0, 7, "white balance preset");
    case RcCommandId::kSetPvWhiteBalanceValue:
      return in(0, 2300 / 25, 7500 / 25, "white balance value");
    case RcCommandId::kSetPvExposure: {
      const std::string r = in(0, 0, 1, "exposure mode");
      return r.empty() ? in(1, 1000 / 10, 660000 / 10, "exposure value") : r;
    }
    case RcCommandId::kSetPvExposurePriorityVideo:
      return in(0, 0, 1, "exposure priority");
    case RcCommandId::kSetPvIsoSpeed: {
      const std::string r = in(0, 0, 1, "ISO speed mode");
      return r.empty() ? in(1, 100, 3200, "ISO speed value") : r;
    }
    case RcCommandId::kSetPvBacklightCompensation:
      return in(0, 0, 1, "backlight compensation");
    case RcCommandId::kSetPvSceneMode:
      return c.u[0] == 1 ? "scene mode 1 (not a mode)" : in(0, 0, 12, "scene mode");
    case RcCommandId::kSetFlatMode:
      return in(0, 0, 1, "flat mode");
    case RcCommandId::kSetRmEyeSelection:
      return in(0, 0, 1, "eye selection");
    case RcCommandId::kSetPvDesiredOptimization:
      return in(0, 0, 6, "desired optimization");
    case RcCommandId::kSetPvPrimaryUse:
      return in(0, 0, 2, "primary use");
    case RcCommandId::kSetPvOpticalImageStabilization:
      return in(0, 0, 1, "optical image stabilization");
    case RcCommandId::kSetPvHdrVideo:
      return in(0, 0, 2, "HDR video");
    case RcCommandId::kSetQuietMode:
      return in(0, 0, 1, "quiet mode");
    case RcCommandId::kGetCurrentTime:
      return in(0, 0, 1, "time source");
    case RcCommandId::kSetPvRegionsOfInterest: {
      if (c.u[0] & ~0x1FFFu) return "region-of-interest mode has bits above 12";
      if ((c.u[0] & 0x7F) > 100) return OutOf("region-of-interest weight", c.u[0] & 0x7F, 0, 100);
      for (float v : c.f)
        if (!std::isfinite(v) || std::fabs(v) > 1e5f) return "region of interest not finite or beyond 1e5";
      if (c.f[2] < 0 || c.f[3] < 0) return "region of interest of negative size";
      return "";
    }
    case RcCommandId::kSetInterfacePriority: {
      if (c.u[0] < 3800 || c.u[0] > 3821) return OutOf("interface port", c.u[0], 3800, 3821);
      const int32_t priority = static_cast<int32_t>(c.u[1]);
      return priority < -2 || priority > 2 ? OutOf("interface priority", priority, -2, 2) : "";
    }
    case RcCommandId::kSetSiSamplingDelay: {
      const int64_t delay = static_cast<int64_t>(c.q[0]);
      return delay < -kTicksPerSecond || delay > kTicksPerSecond
                 ? "sampling delay " + std::to_string(delay) + " ticks beyond ±1 s"
                 : "";
    }
    default:
      return "";
  }
}

}  // namespace

Parsed<RcCommand> ParseRcCommand(const uint8_t* data, size_t size) {
  if (size < 1) return NeedMore<RcCommand>();
  RcCommand c;
  const uint8_t id = data[0];
  c.id = static_cast<RcCommandId>(id);
  if (c.id == RcCommandId::kRmMapCameraPoints) {
    if (size < 13) return NeedMore<RcCommand>();
    const uint32_t port = GetU32(data + 1), operation = GetU32(data + 5), count = GetU32(data + 9);
    if (port < 3800 || port > 3805)
      return Refuse<RcCommand>("rc/map_points", OutOf("camera port", port, 3800, 3805));
    if (operation > 1) return Refuse<RcCommand>("rc/map_points", OutOf("operation", operation, 0, 1));
    if (count > kMaxRcPoints)
      return Refuse<RcCommand>("rc/map_points", OutOf("point count", count, 0, kMaxRcPoints));
    const size_t total = 13 + static_cast<size_t>(count) * 8;
    if (size < total) return NeedMore<RcCommand>();
    c.u = {port, operation, count};
    for (size_t i = 0; i < 2u * count; ++i) {
      c.f.push_back(GetF32(data + 13 + 4 * i));
      if (!std::isfinite(c.f.back())) return Refuse<RcCommand>("rc/map_points", "a point is not finite");
    }
    return Done(total, std::move(c));
  }
  if (c.id == RcCommandId::kRmGetRigNodeWorldPoses) {
    if (size < 5) return NeedMore<RcCommand>();
    const uint32_t count = GetU32(data + 1);
    if (count > kMaxRcPoints)
      return Refuse<RcCommand>("rc/rig_poses", OutOf("timestamp count", count, 0, kMaxRcPoints));
    const size_t total = 5 + static_cast<size_t>(count) * 8;
    if (size < total) return NeedMore<RcCommand>();
    c.u = {count};
    for (size_t i = 0; i < count; ++i) c.q.push_back(GetU64(data + 5 + 8 * i));
    return Done(total, std::move(c));
  }
  RcShape shape;
  if (!Shape(id, &shape)) return Refuse<RcCommand>("rc/unknown", "unknown command " + std::to_string(id));
  const size_t total = 1 + 4 * static_cast<size_t>(shape.u32s) + 8 * static_cast<size_t>(shape.i64s);
  if (size < total) return NeedMore<RcCommand>();
  for (int i = 0; i < shape.u32s; ++i) c.u.push_back(GetU32(data + 1 + 4 * i));
  for (int i = 0; i < shape.i64s; ++i) c.q.push_back(GetU64(data + 1 + 4 * shape.u32s + 8 * i));
  if (c.id == RcCommandId::kSetPvRegionsOfInterest) {
    for (int i = 1; i < 5; ++i) c.f.push_back(GetF32(data + 1 + 4 * i));
    c.u.resize(1);
  }
  const std::string problem = CheckRcArguments(c);
  if (!problem.empty()) return Refuse<RcCommand>("rc/" + RcCommandName(c.id), problem);
  return Done(total, std::move(c));
}

bool RcAnswers(RcCommandId id) {
  switch (id) {
    case RcCommandId::kGetApplicationVersion:
    case RcCommandId::kGetUtcOffset:
    case RcCommandId::kGetPvSubsystemStatus:
    case RcCommandId::kRmMapCameraPoints:
    case RcCommandId::kRmGetRigNodeWorldPoses:
    case RcCommandId::kGetCurrentTime:
      return true;
    default:
      return false;
  }
}

std::string RcCommandName(RcCommandId id) {
  static const char* const kNames[] = {"application_version",
                                       "utc_offset",
                                       "marker_state",
                                       "pv_subsystem_status",
                                       "pv_focus",
                                       "pv_temporal_denoising",
                                       "pv_white_balance_preset",
                                       "pv_white_balance_value",
                                       "pv_exposure",
                                       "pv_exposure_priority",
                                       "pv_iso_speed",
                                       "pv_backlight_compensation",
                                       "pv_scene_mode",
                                       "flat_mode",
                                       "rm_eye_selection",
                                       "pv_desired_optimization",
                                       "pv_primary_use",
                                       "pv_optical_image_stabilization",
                                       "pv_hdr_video",
                                       "pv_regions_of_interest",
                                       "interface_priority",
                                       "quiet_mode",
                                       "map_points",
                                       "rig_poses",
                                       "current_time",
                                       "si_sampling_delay"};
  const auto i = static_cast<size_t>(id);
  return i < sizeof(kNames) / sizeof(kNames[0]) ? kNames[i] : "unknown";
}

}  // namespace orbed::hl2ss
