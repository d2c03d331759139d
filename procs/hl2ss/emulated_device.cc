#include "procs/hl2ss/emulated_device.h"

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
      out.reply.assign(static_cast<size_t>(c.u[0]) * kPoseBytes, 0);
      break;
    case RcCommandId::kRmMapCameraPoints:
      out.refused = true;
      out.key = "rc/map_points";
      out.reason = "mapping research-mode camera points is not emulated";
      break;
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
