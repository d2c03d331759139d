#pragma once
/// @file
/// Channel names of the orbed bus, defined once. Every process takes these as defaults and lets a
/// flag override them. Types per channel are in lcmtypes/ and docs/channels.md.

#include <cctype>
#include <string>

namespace orbed::channels {

inline constexpr char kIiwaStatus[] = "IIWA_STATUS";                    // iiwa_status_t, sim, 200 Hz
inline constexpr char kIiwaCommand[] = "IIWA_COMMAND";                  // iiwa_command_t, → sim
inline constexpr char kRobotState[] = "ROBOT_STATE";                    // robot_state_t, sim, 200 Hz
inline constexpr char kCollisionStatus[] = "COLLISION_STATUS";          // collision_status_t, sim
inline constexpr char kPlanCheckRequest[] = "PLAN_CHECK_REQUEST";       // plan_check_request_t, → sim
inline constexpr char kPlanCheckReply[] = "PLAN_CHECK_REPLY";           // plan_check_reply_t, sim
inline constexpr char kHmdPose[] = "HMD_POSE";                          // hmd_pose_t (estimate), 60 Hz
inline constexpr char kHmdPoseTruth[] = "HMD_POSE_TRUTH";               // hmd_pose_t (truth), 60 Hz
inline constexpr char kHmdCamera[] = "HMD_CAMERA";                      // image_t (JPEG), 30 Hz
inline constexpr char kArView[] = "AR_VIEW";                            // image_t (JPEG)
inline constexpr char kGazeRay[] = "GAZE_RAY";                          // gaze_ray_t
inline constexpr char kReflectiveView[] = "REFLECTIVE_VIEW";            // reflective_view_t, 30 Hz
inline constexpr char kAlignmentTrial[] = "ALIGNMENT_TRIAL";            // alignment_trial_t
inline constexpr char kRegistration[] = "REGISTRATION";                 // registration_t
inline constexpr char kSessionControl[] = "SESSION_CONTROL";            // session_control_t
inline constexpr char kLandmarkRequest[] = "LANDMARK_REQUEST";          // landmark_request_t
inline constexpr char kLandmark[] = "LANDMARK";                         // landmark_t
inline constexpr char kMisalignmentRequest[] = "MISALIGNMENT_REQUEST";  // misalignment_request_t
inline constexpr char kMisalignment[] = "MISALIGNMENT";                 // misalignment_t
inline constexpr char kGuidance[] = "GUIDANCE";                         // guidance_t, 30 Hz
inline constexpr char kSetupTask[] = "SETUP_TASK";                      // setup_task_t, orbed-setup
inline constexpr char kSetupResult[] = "SETUP_RESULT";                  // setup_result_t, orbed-assistant
inline constexpr char kProcessStatus[] = "PROCESS_STATUS";              // process_status_t, 1 Hz each
inline constexpr char kLoggerStatus[] = "LOGGER_STATUS";                // logger_status_t, 1 Hz
inline constexpr char kIgtlTarget[] = "IGTL_TARGET";                    // target_pose_t, orbed-igtl-bridge
inline constexpr char kFixedView[] = "FIXED_VIEW";                      // image_t (JPEG), orbed-fixed-display
inline constexpr char kSimClock[] = "SIM_CLOCK";                        // sim_clock_t, sim, once per tick
inline constexpr char kSimClockAck[] = "SIM_CLOCK_ACK";  // sim_clock_ack_t, each follower, per lockstep round
inline constexpr char kDeputyCommand[] = "DEPUTY_COMMAND";  // deputy_command_t, launcher, 5 Hz per deputy
inline constexpr char kDeputyStatus[] = "DEPUTY_STATUS";    // deputy_status_t, each deputy, 5 Hz
inline constexpr char kHolograms[] = "HOLOGRAMS";  // hologram_scene_t, orbed-hl2ss, per change and 1 Hz

/// A name that may suffix channels: 1..32 characters of a-z, 0-9 and _ (an arm's, a headset's).
inline bool IsInstanceName(const std::string& name) {
  return !name.empty() && name.size() <= 32 &&
         name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_") == std::string::npos;
}
inline constexpr char kInstanceNameRule[] = "1..32 characters of a-z, 0-9 and _";

/// `channel` + "_" + `name` in capitals, or `channel` for name "": how one of several arms or
/// headsets names its channels.
inline std::string Suffixed(const std::string& channel, const std::string& name) {
  if (name.empty()) return channel;
  std::string suffix = name;
  for (char& c : suffix) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return channel + "_" + suffix;
}

/// A channel of one of several arms: ForArm("IIWA_STATUS", "a1") == "IIWA_STATUS_A1";
/// a single arm ("") keeps the plain name, so Drake's tools still find IIWA_STATUS and IIWA_COMMAND.
inline std::string ForArm(const std::string& channel, const std::string& arm) {
  return Suffixed(channel, arm);
}

/// A channel of one of several headsets: ForHeadset("HMD_CAMERA", "h1") ==
/// "HMD_CAMERA_H1"; a single headset ("") keeps the plain name.
inline std::string ForHeadset(const std::string& channel, const std::string& headset) {
  return Suffixed(channel, headset);
}

/// Every channel above (tools that address channels by index: the fuzz targets and their corpora;
/// new channels are appended so that the indices of the old ones stay).
inline constexpr const char* kAllChannels[] = {
    kIiwaStatus,      kIiwaCommand,    kRobotState,          kCollisionStatus, kPlanCheckRequest,
    kPlanCheckReply,  kHmdPose,        kHmdPoseTruth,        kHmdCamera,       kArView,
    kGazeRay,         kReflectiveView, kAlignmentTrial,      kRegistration,    kSessionControl,
    kLandmarkRequest, kLandmark,       kMisalignmentRequest, kMisalignment,    kGuidance,
    kProcessStatus,   kLoggerStatus,   kSetupTask,           kSetupResult,     kIgtlTarget,
    kFixedView,       kSimClock,       kSimClockAck,         kDeputyCommand,   kDeputyStatus,
    kHolograms};

}  // namespace orbed::channels
