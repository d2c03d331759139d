#pragma once
/// @file
/// The `orbed-render-snapshot` tool (thin main in render_snapshot_main.cc), as a library function so
/// that tests can run it in-process. It writes the pictures of what the testbed's headset shows, for
/// docs/processes.md:
///   DIR/camera_frame.png     an HMD_CAMERA frame: the shipped OR scene and the real iiwa, rendered
///                            from a bedside head pose (HoloLens PV intrinsics)
///   DIR/reflective_view.png  a REFLECTIVE_VIEW: a frame captured from the foot of the table (the
///                            real robot from the TRUE pose) with the virtual robot drawn as a
///                            hologram from the device's estimate of that pose (2 cm, 0.8 deg SLAM
///                            error) and a registration X_WV that is 3 cm / 2 deg off
/// and one line naming them on `out`. Deterministic (no randomness).
///
///   orbed-render-snapshot [--out DIR]
///     DIR: an existing folder; default docs/images under the source tree (orbed::SourceDir():
///     $ORBED_SOURCE_DIR, else the tree it was built from), which also holds the model and scene.
///
/// Exit codes: 0 pictures written (or --help, on `out`); 2 bad arguments (an unknown flag, a missing
/// or nonexistent --out folder; the message on `err`); 1 the pictures could not be made or written.

#include <ostream>

namespace orbed::hmd {

int RunRenderSnapshot(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::hmd
