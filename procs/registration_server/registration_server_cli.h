#pragma once
/// @file
/// The `orbed-registration` command line (thin main in registration_server_main.cc), as a library function so
/// that tests can run it in-process.
///
///   orbed-registration [common process flags] [--state-period-s S] [--model-centroid-m X Y Z]
///                      [--k-mad K] [--min-ray-angle-deg A] [--<name>-channel CHANNEL]...
///     The LCM server (registration_server_process.h) until SIGINT/SIGTERM or --duration-s.
///   orbed-registration mean --input FILE [--robust] [--json] [--model-centroid-m X Y Z]
///     The offline SE(3) mean of a trial file (mean_command.h); touches no network.
///   orbed-registration send --input FILE [--session-id ID] [--robust] [--timeout-s S]
///     Sends a trial file to a running server and prints its mean (send_command.h); uses the
///     top-level --lcm-url and channel flags.
///
/// Exit codes: 0 after --help or a clean stop; CLI11's code (non-zero) for an unknown flag or a bad
/// flag value (the message names the flag); `mean` and `send` exit with their command's code (2 bad
/// input, 1 no result); 1 when the server cannot start. Help and results go to `out`, errors to
/// `err`.

#include <ostream>

namespace orbed::registration {

int RunRegistration(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::registration
