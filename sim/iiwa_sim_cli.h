#pragma once
/// @file
/// The `orbed-iiwa-sim` command line (thin main in iiwa_sim_main.cc), as a library function so that
/// tests can run it in-process.
///
/// Flags: the common process flags (runtime/flags.h); --urdf, --scene (default: the shipped
/// model and OR scene, under $ORBED_SOURCE_DIR, else the source tree it was built from);
/// --period-s (> 0, default 0.005 = 200 Hz); --initial-q-deg q1,...,q7; --stale-command-s,
/// --stop-margin-m, --report-distance-m (>= 0); --robot-name; one flag per channel name. See
/// --help for the defaults and iiwa_sim.h for what they do.
///
/// Exit codes: 0 after --help or a clean stop (SIGINT/SIGTERM, --duration-s); CLI11's code
/// (non-zero) for an unknown flag or a bad flag value (the message names the flag); 1 when the sim
/// cannot start (unreadable URDF or scene, bad --initial-q-deg, ...) or fails. Help goes to `out`,
/// errors to `err`.

#include <ostream>

namespace orbed::sim {

int RunIiwaSim(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::sim
