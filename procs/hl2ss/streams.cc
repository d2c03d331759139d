#include "procs/hl2ss/streams.h"

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

}  // namespace orbed::hl2ss
