#pragma once
/// @file
/// The orbed-hmd command line (thin main in hmd_main.cc), as a library so that tests can run it
/// in-process: parses the flags with CLI11, builds HmdProcess (hmd_process.h) and runs it.
///   Subscribes: IIWA_STATUS (q), ROBOT_STATE (X_WR), SESSION_CONTROL (START / RESET / STOP /
///               REQUEST_TRIAL), REGISTRATION (X_WV_mean, where the hologram is drawn).
///   Publishes:  HMD_POSE + HMD_POSE_TRUTH (hmd_pose_t, --pose-hz, 60 Hz), HMD_CAMERA (image_t JPEG,
///               --camera-hz, 30 Hz), GAZE_RAY (gaze_ray_t, 10 Hz), REFLECTIVE_VIEW
///               (reflective_view_t, 30 Hz per display, --displays), AR_VIEW (image_t JPEG, 5 Hz),
///               ALIGNMENT_TRIAL (alignment_trial_t, one per REQUEST_TRIAL, or per Enter with
///               --interactive), PROCESS_STATUS at 1 Hz. Channel names can be overridden by flags.
/// Exit codes: 0 after a clean stop or --help; CLI11's code (non-zero) for a bad flag, with the
/// message on `err`; 1 when the process cannot start (one line on `err`) or fails.
/// Output: --help prints the usage on `out`; the process logs through base/log.h.

#include <ostream>

namespace orbed::hmd {

int RunHmd(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::hmd
