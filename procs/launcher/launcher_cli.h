#pragma once
/// @file
/// The `orbed-launch` command line (thin main in launcher_main.cc), as a library function so that
/// tests can run it in-process.
///
///   orbed-launch [common process flags] [--host NAME] [--arg NAME=VALUE]... [--dry-run]
///                [--show-args [--json]] LAUNCH_FILE
///   orbed-launch [common process flags] --deputy NAME [--log-root DIR] [--orphan-timeout-s S]
///
/// The first starts a launch; processes whose `host:` is neither left out nor --host (default
/// $ORBED_HOST, else the machine's hostname) are started through the deputy of that name. The
/// second is that deputy (deputy.h): run it on each other host, on the same LCM URL (e.g. with
/// --lan); its heartbeat is named "deputy-NAME" unless --name is given.
///
/// Commands without '/' in the launch file are looked up beside the running executable first
/// (its folder is also given to children as $ORBED_BIN_DIR). --dry-run parses the file and prints
/// the plan on `out` (one line per process under its group) instead of starting anything;
/// --show-args prints the file's arguments (launch_file.h) with their values, as a table or JSON.
/// A bad --arg (no '=', a name the launch does not declare, given twice) is refused with code 2
/// before anything starts.
///
/// Exit codes: 0 after --help, --dry-run or --show-args, else the launcher's (launcher.h: 0, 1 when a
/// required process failed or was not ready, or an `exit_stops_all` process's code); CLI11's code (non-zero)
/// for an unknown flag, a bad flag value or a missing LAUNCH_FILE (the message names it; a
/// LAUNCH_FILE given with --deputy is such an error too); 2 for a
/// launch file that does not parse (the message names the file and the problem); 1 when the
/// launcher cannot start. Help and the plan go to `out`, errors to `err`.

#include <ostream>

namespace orbed::launcher {

int RunLauncher(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::launcher
