#include "lcmtypes/contract/requests.h"

#include <cmath>
#include <limits>

#include "lcmtypes/contract/conversions.h"
#include "lcmtypes/contract/validation.h"

namespace orbed {
namespace {

// Rows of an N×3 message array (sized by the decoder) as vectors; "" or the reason.
std::string ReadRows(const std::vector<std::vector<double>>& rows, int32_t count, int max,
                     const std::string& what, std::vector<Eigen::Vector3d>* out) {
  if (count < 0 || count > max || static_cast<size_t>(count) != rows.size()) {
    return what + ": count " + std::to_string(count) + " is outside [0, " + std::to_string(max) +
           "] or does not match the array";
  }
  out->clear();
  for (size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].size() != 3) return what + "[" + std::to_string(i) + "]: expected 3 values";
    const std::string bounded =
        CheckBounded(rows[i].data(), 3, kMaxRequestCoordinate, what + "[" + std::to_string(i) + "]");
    if (!bounded.empty()) return bounded;
    out->emplace_back(rows[i][0], rows[i][1], rows[i][2]);
  }
  return "";
}

}  // namespace

std::variant<IiwaCommand, Refusal> CheckIiwaCommand(const orbed::iiwa_command_t& msg, int num_joints) {
  std::string error = CheckSize(msg.num_joints, num_joints, "num_joints");
  if (error.empty())
    error = CheckSize(static_cast<int64_t>(msg.joint_position.size()), num_joints, "joint_position");
  if (!error.empty()) return Refusal{"num_joints", error};
  if (!(msg.num_torques == 0 || msg.num_torques == msg.num_joints) ||
      static_cast<size_t>(msg.num_torques) != msg.joint_torque.size()) {
    return Refusal{"num_torques", "num_torques is " + std::to_string(msg.num_torques) + " with " +
                                      std::to_string(msg.joint_torque.size()) +
                                      " torques, expected 0 or num_joints (" + std::to_string(num_joints) +
                                      ")"};
  }
  error = FirstError(
      {CheckFinite(msg.joint_position, "joint_position"), CheckFinite(msg.joint_torque, "joint_torque")});
  if (!error.empty()) return Refusal{"non_finite", error};
  return IiwaCommand{msg.utime, ToVectorX(msg.joint_position)};
}

std::variant<PlanCheckRequest, Refusal> CheckPlanCheckRequest(const orbed::plan_check_request_t& msg,
                                                              int num_joints) {
  std::string error = CheckSize(msg.num_joints, num_joints, "num_joints");
  if (error.empty())
    error = CheckSize(static_cast<int64_t>(msg.joint_position.size()), num_joints, "joint_position");
  if (!error.empty()) return Refusal{"num_joints", error};
  error = CheckFinite(msg.joint_position, "joint_position");
  if (!error.empty()) return Refusal{"non_finite", error};
  return PlanCheckRequest{msg.utime, msg.request_id, ToVectorX(msg.joint_position)};
}

std::variant<LandmarkRequest, Refusal> CheckLandmarkRequest(const orbed::landmark_request_t& msg,
                                                            int max_rays) {
  LandmarkRequest request{msg.utime, msg.request_id, msg.name, {}, {}};
  std::string problem =
      ReadRows(msg.origin_W_m, msg.num_rays, max_rays, "LANDMARK_REQUEST.origin_W_m", &request.origin_W_m);
  if (problem.empty()) {
    problem = ReadRows(msg.direction_W, msg.num_rays, max_rays, "LANDMARK_REQUEST.direction_W",
                       &request.direction_W);
  }
  if (!problem.empty()) return Refusal{"invalid", problem};
  return request;
}

std::variant<MisalignmentRequest, Refusal> CheckMisalignmentRequest(const orbed::misalignment_request_t& msg,
                                                                    int max_pairs) {
  MisalignmentRequest request{msg.utime, msg.request_id, msg.session_id, {}, {}};
  std::string problem = ReadRows(msg.p_W_real_m, msg.num_pairs, max_pairs, "MISALIGNMENT_REQUEST.p_W_real_m",
                                 &request.p_W_real_m);
  if (problem.empty()) {
    problem = ReadRows(msg.p_W_virtual_m, msg.num_pairs, max_pairs, "MISALIGNMENT_REQUEST.p_W_virtual_m",
                       &request.p_W_virtual_m);
  }
  if (!problem.empty()) return Refusal{"invalid", problem};
  return request;
}

std::string CheckRobotState(const orbed::robot_state_t& msg, int num_joints) {
  return FirstError(
      {CheckWorldPose(msg.X_WR, "ROBOT_STATE.X_WR"),
       CheckSize(msg.num_joints, num_joints, "ROBOT_STATE.num_joints"),
       CheckLength(msg.num_joints, msg.joint_position.size(), num_joints, "ROBOT_STATE.num_joints"),
       CheckLength(msg.num_joints, msg.joint_limit_hit.size(), num_joints, "ROBOT_STATE.joint_limit_hit"),
       CheckFinite(msg.joint_position, "ROBOT_STATE.joint_position"),
       CheckLength(msg.num_links, msg.X_RL.size(), kMaxRobotStateLinks, "ROBOT_STATE.num_links"),
       CheckLength(msg.num_links, msg.link_names.size(), kMaxRobotStateLinks, "ROBOT_STATE.link_names"),
       CheckEnum(msg.motion_state, orbed::robot_state_t::MOTION_IDLE,
                 orbed::robot_state_t::MOTION_IN_COLLISION, "ROBOT_STATE.motion_state")});
}

std::string CheckImage(const orbed::image_t& msg) {
  if (msg.width <= 0 || msg.height <= 0 || msg.width > kMaxImageSide || msg.height > kMaxImageSide)
    return "image: size " + std::to_string(msg.width) + " x " + std::to_string(msg.height) + " px";
  if (msg.num_bytes != static_cast<int64_t>(msg.data.size())) return "image: num_bytes differs from the data";
  if (!(msg.fx_px > 0) || !(msg.fy_px > 0) || !std::isfinite(msg.fx_px) || !std::isfinite(msg.fy_px))
    return "image: fx_px, fy_px must be finite and > 0";
  const std::string pose = CheckWorldPose(msg.X_WC, "image.X_WC");
  if (!pose.empty()) return pose;
  if (msg.pixel_format == orbed::image_t::FORMAT_JPEG) return "";
  const int channels = msg.pixel_format == orbed::image_t::FORMAT_GRAY8 ? 1 : 3;
  if (msg.pixel_format < orbed::image_t::FORMAT_GRAY8 || msg.pixel_format > orbed::image_t::FORMAT_BGR8)
    return "image: pixel_format " + std::to_string(msg.pixel_format);
  if (msg.row_stride < channels * msg.width ||
      static_cast<int64_t>(msg.row_stride) * msg.height != static_cast<int64_t>(msg.num_bytes))
    return "image: row_stride and height do not give num_bytes";
  return "";
}

std::string CheckCollisionStatus(const orbed::collision_status_t& msg) {
  if (std::isnan(msg.min_distance_m) || msg.min_distance_m == -std::numeric_limits<double>::infinity())
    return "COLLISION_STATUS.min_distance_m: expected a number or +inf";
  return FirstError(
      {CheckLength(msg.num_contacts, msg.contacts.size(), kMaxRobotStateLinks,
                   "COLLISION_STATUS.num_contacts"),
       CheckLength(msg.num_links, msg.link_names.size(), kMaxRobotStateLinks, "COLLISION_STATUS.link_names"),
       CheckLength(msg.num_links, msg.link_clearance_m.size(), kMaxRobotStateLinks,
                   "COLLISION_STATUS.link_clearance_m")});
}

}  // namespace orbed
