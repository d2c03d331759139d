#pragma once
/// @file
/// The `orbed-launch` command line (thin main in launcher_main.cc), as a library function so that
/// tests can run it in-process.
///
///   orbed-launch [common process flags] [--dry-run] LAUNCH_FILE
///
/// Commands without '/' in the launch file are looked up beside the running executable first
/// (its folder is also given to children as $ORBED_BIN_DIR). --dry-run parses the file and prints
/// the plan on `out` (one line per process under its group) instead of starting anything.
///
/// Exit codes: 0 after --help or --dry-run, else the launcher's (launcher.h: 0, 1 when a required
/// process failed or was not ready, or an `exit_stops_all` process's code); CLI11's code (non-zero)
/// for an unknown flag, a bad flag value or a missing LAUNCH_FILE (the message names it); 2 for a
/// launch file that does not parse (the message names the file and the problem); 1 when the
/// launcher cannot start. Help and the plan go to `out`, errors to `err`.

#include <ostream>

namespace orbed::launcher {

int RunLauncher(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::launcher
