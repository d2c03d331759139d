#include "procs/hl2ss/emulated_device.h"

#include "procs/hl2ss/frames.h"

namespace orbed::hl2ss {

RcOutcome EmulatedDevice::HandleRc(const RcCommand& c, int64_t now_us) {
  RcOutcome out;
  switch (c.id) {
    case RcCommandId::kGetApplicationVersion:
      for (uint16_t v : app_version_) PutU16(&out.reply, v);
      break;
    case RcCommandId::kGetUtcOffset:
      PutU64(&out.reply, time_base_.UtcOffset());
      break;
    case RcCommandId::kGetPvSubsystemStatus:
      out.reply.push_back(pv_open_ ? 1 : 0);
      break;
    case RcCommandId::kGetCurrentTime:
      PutU64(&out.reply, c.u[0] == 0 ? time_base_.TicksOf(now_us) : TimeBase::FiletimeOf(now_us));
      break;
    case RcCommandId::kRmGetRigNodeWorldPoses:
      out.reply.reserve(c.q.size() * kPoseBytes);
      for (uint64_t ticks : c.q) {
        const std::optional<Eigen::Isometry3d> X_WH = history_.Find(time_base_.UtimeOf(ticks));
        const std::array<float, 16> pose =
            X_WH ? PoseMatrixRowMajor(RigNodePoseForClient(*X_WH, depth_camera_)) : std::array<float, 16>{};
        for (float v : pose) PutF32(&out.reply, v);
      }
      break;
    case RcCommandId::kRmMapCameraPoints: {
      if (c.u[0] != static_cast<uint32_t>(kPortRmDepthLongThrow)) {
        out.refused = true;
        out.key = "rc/map_points_sensor";
        out.reason = "mapping points of the research-mode camera on port " + std::to_string(c.u[0]) +
                     ": only the long-throw depth camera (" + std::to_string(kPortRmDepthLongThrow) +
                     ") is emulated";
        break;
      }
      const geometry::Intrinsics& K = depth_camera_.intrinsics;
      out.reply.reserve(c.f.size() * 4);
      for (size_t i = 0; i + 1 < c.f.size(); i += 2) {
        const Eigen::Vector2d in(c.f[i], c.f[i + 1]);
        const Eigen::Vector2d mapped =
            c.u[1] == 0 ? LongThrowImagePointToUnitPlane(K, in) : LongThrowUnitPlaneToImagePoint(K, in);
        PutF32(&out.reply, static_cast<float>(mapped.x()));
        PutF32(&out.reply, static_cast<float>(mapped.y()));
      }
      break;
    }
    case RcCommandId::kSetMarkerState:
      marker_ = c.u[0] != 0;
      break;
    case RcCommandId::kSetPvFocus:
      for (int i = 0; i < 5; ++i) pv_.focus[i] = c.u[i];
      break;
    case RcCommandId::kSetPvVideoTemporalDenoising:
      pv_.temporal_denoising = c.u[0];
      break;
    case RcCommandId::kSetPvWhiteBalancePreset:
      pv_.white_balance_preset = c.u[0];
      break;
    case RcCommandId::kSetPvWhiteBalanceValue:
      pv_.white_balance_value = c.u[0];
      break;
    case RcCommandId::kSetPvExposure:
      pv_.exposure = {c.u[0], c.u[1]};
      break;
    case RcCommandId::kSetPvExposurePriorityVideo:
      pv_.exposure_priority_video = c.u[0];
      break;
    case RcCommandId::kSetPvIsoSpeed:
      pv_.iso_speed = {c.u[0], c.u[1]};
      break;
    case RcCommandId::kSetPvBacklightCompensation:
      pv_.backlight_compensation = c.u[0];
      break;
    case RcCommandId::kSetPvSceneMode:
      pv_.scene_mode = c.u[0];
      break;
    case RcCommandId::kSetFlatMode:
      flat_mode_ = c.u[0] != 0;
      break;
    case RcCommandId::kSetRmEyeSelection:
      eye_selection_ = c.u[0] != 0;
      break;
    case RcCommandId::kSetPvDesiredOptimization:
      pv_.desired_optimization = c.u[0];
      break;
    case RcCommandId::kSetPvPrimaryUse:
      pv_.primary_use = c.u[0];
      break;
    case RcCommandId::kSetPvOpticalImageStabilization:
      pv_.optical_image_stabilization = c.u[0];
      break;
    case RcCommandId::kSetPvHdrVideo:
      pv_.hdr_video = c.u[0];
      break;
    case RcCommandId::kSetPvRegionsOfInterest:
    case RcCommandId::kSetInterfacePriority:
      break;  // accepted; nothing in the emulation depends on them
    case RcCommandId::kSetQuietMode:
      quiet_mode_ = c.u[0] != 0;
      break;
    case RcCommandId::kSetSiSamplingDelay:
      si_sampling_delay_ticks_ = static_cast<int64_t>(c.q[0]);
      break;
  }
  return out;
}

}  // namespace orbed::hl2ss
