#pragma once
/// @file
/// The emulated device's state as hl2ss clients change and read it, without sockets: the
/// remote-configuration (RC, port 3809) commands' answers and settings, and the PV subsystem that a
/// client opens and closes through the PV port's control bits (protocol.h PvConfig start/stop).
///
/// What the answers mean (hl2ss.py ipc_rc):
///   application version  4 × u16, the --app-version this emulator was given
///   UTC offset           u64 FILETIME − ticks (protocol.h TimeBase::UtcOffset)
///   PV subsystem status  u8: 1 while open
///   current time         u64: ticks (source 0, QPC) or FILETIME (source 1, UTC) of `now_us`
///   rig-node world poses count × 16 float32: for each timestamp (hl2ss ticks, converted to a utime
///                        by the time base), the rig node's pose X_DN (frames.h layout) of the
///                        head estimate the PoseHistory finds for it (pose_history.h: that utime's
///                        HMD_POSE, or the nearest within one period), through rm_depth.h
///                        RigNodePoseForClient with the depth camera's options; none: 16 zeros,
///                        what the client's is_valid_pose reads as "not located"
///   map camera points    count × 2 float32, one per point sent, for the long-throw depth camera
///                        (port 3805) only: operation 0 maps image points (the sensor API's
///                        convention, integer coordinates at pixel corners) to the unit plane,
///                        operation 1 unit-plane points to image points, through rm_depth.h's
///                        mapping functions of the depth camera's intrinsics (the ones its mode-2
///                        uv2xy table comes from). Other sensors are not emulated: refused
///                        "rc/map_points_sensor".
/// The PV settings (focus, exposure, white balance, ISO, ...) are kept as sent, for the PV metadata
/// trailer; they do not change the emulated picture. The SI sampling delay is kept
/// (si_sampling_delay_ticks) but the SI stream samples the latest pose.
///
/// Threading: not thread-safe; one thread calls everything.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "procs/hl2ss/pose_history.h"
#include "procs/hl2ss/protocol.h"
#include "procs/hl2ss/rm_depth.h"

namespace orbed::hl2ss {

/// The PV camera settings a client set over RC (0 = never set; the client's units).
struct PvSettings {
  std::array<uint32_t, 5> focus{};  ///< mode, auto range, distance, value, driver fallback
  uint32_t temporal_denoising{0};
  uint32_t white_balance_preset{0};
  uint32_t white_balance_value{0};  ///< [25 K]
  std::array<uint32_t, 2> exposure{1,
                                   0};  ///< mode (1 auto), value [µs] (the device sets TimeSpan(10 × value))
  uint32_t exposure_priority_video{0};
  std::array<uint32_t, 2> iso_speed{1, 0};  ///< mode (1 auto), value
  uint32_t backlight_compensation{0};
  uint32_t scene_mode{0};
  uint32_t desired_optimization{0};
  uint32_t primary_use{0};
  uint32_t optical_image_stabilization{0};
  uint32_t hdr_video{0};
};

/// What the device does with one RC command: the bytes to answer (maybe none), or a refusal.
struct RcOutcome {
  std::vector<uint8_t> reply;
  bool refused{false};
  std::string key, reason;
};

class EmulatedDevice {
 public:
  /// `depth_camera`: the long-throw camera's options as its stream is configured (its rig node
  /// and intrinsics answer 0x17 and 0x16); `history`: where RecordPose keeps the estimates.
  EmulatedDevice(const TimeBase& time_base, std::array<uint16_t, 4> app_version,
                 const LongThrowOptions& depth_camera = {}, PoseHistory history = PoseHistory())
      : time_base_(time_base), app_version_(app_version), depth_camera_(depth_camera), history_(history) {}

  const TimeBase& time_base() const { return time_base_; }
  /// Applies or answers one parsed command at `now_us` (µs since the Unix epoch).
  RcOutcome HandleRc(const RcCommand& command, int64_t now_us);

  bool pv_open() const { return pv_open_; }
  void OpenPv(const MrcVideoOptions& options) {
    pv_open_ = true;
    mrc_ = options;
  }
  void ClosePv() { pv_open_ = false; }
  const MrcVideoOptions& mrc() const { return mrc_; }
  const PvSettings& pv_settings() const { return pv_; }
  int64_t si_sampling_delay_ticks() const { return si_sampling_delay_ticks_; }
  bool marker() const { return marker_; }
  /// One HMD_POSE: the head's estimate at `utime` [µs], located unless tracking was lost.
  void RecordPose(int64_t utime, const Eigen::Isometry3d& X_WH, bool located) {
    history_.Add({utime, X_WH, located});
  }

 private:
  TimeBase time_base_;
  std::array<uint16_t, 4> app_version_;
  LongThrowOptions depth_camera_;
  PoseHistory history_;
  bool pv_open_{false};
  MrcVideoOptions mrc_;
  PvSettings pv_;
  int64_t si_sampling_delay_ticks_{0};
  bool marker_{false}, flat_mode_{false}, quiet_mode_{false}, eye_selection_{false};
};

}  // namespace orbed::hl2ss
