#pragma once
/// @file
/// The orbed-load command line (thin main in load_main.cc): runs the testbed at --factor times its
/// nominal rates for --duration-s (load_run.h) and prints the tables (load_report.h).
///
/// Flags: --factor F (default 10, in [0.1, 16]); --duration-s S (default 60, from when every process
/// is ready); --rss-early-s S (default 10: the early resident-memory sample); --warmup-s S (default 5:
/// rates are accounted from the first heartbeat after it); --max-rss-growth-percent P (default 10);
/// --launch-file FILE (default scripts/launch/load.yaml); --log-dir DIR (required); --bin-dir DIR
/// (default: beside this executable).
///
/// Exit codes: 0 when no process died or was respawned, no resident memory grew by more than P %
/// and orbed-launch exited 0; 1 otherwise (each failure named on `err`) or when the testbed did not
/// come up; CLI11's code for a bad flag. Tables on `out`, progress on `err`.
/// Run it inside a private network namespace: `scripts/orbed load` does.

#include <ostream>

namespace orbed::load {

int RunLoadCli(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::load
