#pragma once
/// @file
/// The one check of each request and command message read by a single process, beside the
/// SESSION_CONTROL and ALIGNMENT_TRIAL checks, so every message's contract is written once in the
/// common library and the reader only adds what needs its own state (the sim: the command's age on
/// its clock, the joint limits; the server: nothing more).
///
///   IIWA_COMMAND (iiwa_command_t)          num_joints == the arm's; num_torques 0 or num_joints and
///                                          equal to the array's length; finite angles [rad] and
///                                          torques. Keys: num_joints, num_torques, non_finite.
///   PLAN_CHECK_REQUEST (plan_check_request_t)  num_joints == the arm's; finite angles [rad].
///                                          Keys: num_joints, non_finite.
///   LANDMARK_REQUEST (landmark_request_t)  num_rays in [0, max_rays] and equal to both arrays'
///                                          lengths; 3 values per row, each within kMaxRequestCoordinate
///                                          of 0 (origins [m], directions). Key: invalid.
///   MISALIGNMENT_REQUEST (misalignment_request_t)  num_pairs in [0, max_pairs], equal to both
///                                          arrays' lengths; rows as above [m]. Key: invalid.
///   ROBOT_STATE (robot_state_t), read by the conductors, the assistant, the bridges and the
///                                          fixed display: X_WR a valid world pose (CheckWorldPose:
///                                          within 10 km of W's origin); num_joints == the arm's and equal to
///                                          the joint arrays' lengths; finite angles [rad]; num_links
///                                          equal to the link arrays' lengths and at most kMaxLinks;
///                                          motion_state in range. The reason names the field.
///   COLLISION_STATUS (collision_status_t), read by orbed-setup: min_distance_m a number or +inf
///                                          (no pair checked), never NaN or −inf; num_contacts and
///                                          num_links equal to their arrays' lengths, at most
///                                          kMaxRobotStateLinks. The reason names the field.
///   HMD_CAMERA, AR_VIEW, REFLECTIVE_VIEW.image, FIXED_VIEW (image_t), read by the bridges and the
///                                          assistant: width and height in 1..kMaxImageSide [px];
///                                          num_bytes equal to the data's length; fx_px, fy_px finite
///                                          and > 0; X_WC a valid world pose; a known
///                                          pixel_format; raw formats: row_stride * height == num_bytes
///                                          and rows at least width pixels. The reason names the field.
/// Whether a landmark's rays can be triangulated, or pairs evaluated, is the server's computation,
/// not the contract.
///
/// Threading: pure functions.

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Core>
#include <orbed/collision_status_t.hpp>
#include <orbed/iiwa_command_t.hpp>
#include <orbed/image_t.hpp>
#include <orbed/landmark_request_t.hpp>
#include <orbed/misalignment_request_t.hpp>
#include <orbed/plan_check_request_t.hpp>
#include <orbed/robot_state_t.hpp>

#include "lcmtypes/contract/session_control.h"

namespace orbed {

/// Coordinates and direction components beyond this are not an operating room [m]; bounding them
/// keeps sums of squares finite.
inline constexpr double kMaxRequestCoordinate = 1e4;
/// The most links a ROBOT_STATE may carry.
inline constexpr int kMaxRobotStateLinks = 1000;

/// "" or the reason ROBOT_STATE is refused (see the file comment); keys are the reader's
/// ("<channel>/field").
std::string CheckRobotState(const orbed::robot_state_t& msg, int num_joints);

/// "" or the reason COLLISION_STATUS is refused (see the file comment).
std::string CheckCollisionStatus(const orbed::collision_status_t& msg);

/// Images larger than this on a side are refused (the HoloLens PV camera is 1280 x 720) [px].
inline constexpr int kMaxImageSide = 8192;
/// "" or the reason an image_t is refused (see the file comment).
std::string CheckImage(const orbed::image_t& msg);

struct IiwaCommand {
  int64_t utime{0};
  Eigen::VectorXd q_rad;
};
std::variant<IiwaCommand, Refusal> CheckIiwaCommand(const orbed::iiwa_command_t& msg, int num_joints);

struct PlanCheckRequest {
  int64_t utime{0};
  int64_t request_id{0};
  Eigen::VectorXd q_rad;
};
std::variant<PlanCheckRequest, Refusal> CheckPlanCheckRequest(const orbed::plan_check_request_t& msg,
                                                              int num_joints);

struct LandmarkRequest {
  int64_t utime{0};
  int64_t request_id{0};
  std::string name;
  std::vector<Eigen::Vector3d> origin_W_m;   ///< ray origins in W [m]
  std::vector<Eigen::Vector3d> direction_W;  ///< ray directions in W (any length > 0)
};
std::variant<LandmarkRequest, Refusal> CheckLandmarkRequest(const orbed::landmark_request_t& msg,
                                                            int max_rays);

struct MisalignmentRequest {
  int64_t utime{0};
  int64_t request_id{0};
  std::string session_id;
  std::vector<Eigen::Vector3d> p_W_real_m;
  std::vector<Eigen::Vector3d> p_W_virtual_m;
};
std::variant<MisalignmentRequest, Refusal> CheckMisalignmentRequest(const orbed::misalignment_request_t& msg,
                                                                    int max_pairs);

}  // namespace orbed
