/// @file
/// orbed-render-snapshot: writes the docs' pictures of what the testbed's headset shows,
/// camera_frame.png and reflective_view.png (what, flags and exit codes:
/// hmd_emulator/render_snapshot.h). Publishes and subscribes nothing.
#include <iostream>

#include "hmd_emulator/render_snapshot.h"

int main(int argc, char** argv) { return orbed::hmd::RunRenderSnapshot(argc, argv, std::cout, std::cerr); }
