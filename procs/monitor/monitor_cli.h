#pragma once
/// @file
/// The `orbed-monitor` command line (thin main in monitor_main.cc), as a library function so that
/// tests can run it in-process.
///
/// Flags: the common process flags (runtime/flags.h), --print-period-s (table period) and
/// --silent-after-s (heartbeat age shown as SILENT), both > 0; see monitor.h.
///
/// Exit codes: 0 after --help or a clean stop (SIGINT/SIGTERM, --duration-s); CLI11's code
/// (non-zero) for an unknown flag or a bad flag value (the message names the flag); 1 when the
/// monitor fails (e.g. LCM cannot be opened). Help goes to `out`, flag errors to `err`.

#include <ostream>

namespace orbed::monitor {

int RunMonitor(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::monitor
