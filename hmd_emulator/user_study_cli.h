#pragma once
/// @file
/// The `orbed-user-study` tool (thin main in user_study_main.cc), as a library function so that
/// tests can run it in-process: runs the emulated ViRAAl study (user_study.h) and prints on `out`,
/// per display mode, the error statistics next to the paper's Table 1, and the rank tests comparing
/// the modes. No LCM.
///
///   orbed-user-study [--trials N] [--source DIR] [--user FILE] [--slam FILE] [--display-at WAYPOINT]...
///     --trials N             trials per display mode: a positive decimal integer (default 200)
///     --source DIR           repository root with the model, scene and configs (default
///                            orbed::SourceDir(): $ORBED_SOURCE_DIR, else the tree it was built from)
///     --user FILE, --slam FILE  overrides of hmd_emulator/config/user.yaml and slam.yaml
///     --display-at WAYPOINT  where a reflective display captures its frame (repeatable; default: the
///                            walk's first waypoint)
///
/// Exit codes: 0 report printed (or --help, on `out`); 2 bad arguments (the message on `err` names
/// the flag); 1 the study failed (unreadable file, unknown waypoint; the message on `err`).

#include <ostream>

namespace orbed::hmd {

int RunUserStudy(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::hmd
