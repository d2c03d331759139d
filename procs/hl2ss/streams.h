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
/// The front camera (PV) is pv_stream.h and pv_encoder.h.
///
/// Threading: pure functions.

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

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

}  // namespace orbed::hl2ss
