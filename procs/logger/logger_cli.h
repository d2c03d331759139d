#pragma once
/// @file
/// The `orbed-logger` command line (thin main in logger_main.cc), as a library function so that
/// tests can run it in-process.
///
/// Flags: the common process flags (runtime/flags.h) and --log-dir, --file, --manifest,
/// --channels (a regular expression), --queue-events, --queue-mb, --flush-interval-s,
/// --hash-file (repeatable); see --help for their defaults and logger.h for what they do.
///
/// Exit codes: 0 after --help or a clean stop (SIGINT/SIGTERM, --duration-s); CLI11's code
/// (non-zero) for an unknown flag or a bad flag value (the message names the flag); 2 for a bad
/// value found when the logger starts (e.g. a --channels that is no regular expression); 1 when
/// the log cannot be written. Help goes to `out`, flag errors to `err`.

#include <ostream>

namespace orbed::logger {

int RunLogger(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace orbed::logger
