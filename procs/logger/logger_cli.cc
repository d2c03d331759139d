#include "procs/logger/logger_cli.h"

#include <cstdint>
#include <exception>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

#include "procs/logger/logger.h"
#include "runtime/flags.h"

namespace orbed::logger {

int RunLogger(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-logger: record LCM traffic to a standard LCM event log (playable with lcm-logplayer)\n"
      "and write manifest.json beside it. Stops cleanly on SIGINT/SIGTERM."};
  CommonFlags common("orbed-logger");
  AddCommonFlags(&app, &common);
  LoggerOptions options;
  app.add_option("--log-dir", options.log_dir, "Folder for the log; file named by start time")
      ->capture_default_str();
  app.add_option("--file", options.file, "Explicit log path (overrides --log-dir naming)");
  app.add_option("--manifest", options.manifest,
                 "Manifest path (default: manifest.json in the log's folder)");
  app.add_option("--channels", options.channels, "Regular expression of channels to record")
      ->capture_default_str();
  app.add_option("--queue-events", options.queue_capacity_events,
                 "Queue bound in events; overflow is dropped and counted")
      ->check(orbed::PositiveNumber())
      ->capture_default_str();
  int64_t queue_mb = options.queue_capacity_bytes >> 20;
  app.add_option("--queue-mb", queue_mb, "Queue bound in MiB")
      ->check(orbed::PositiveNumber())
      ->capture_default_str();
  app.add_option("--flush-interval-s", options.flush_interval_s,
                 "Flush period: after a SIGKILL the log is valid up to the last flush")
      ->check(orbed::PositiveNumber())
      ->capture_default_str();
  app.add_option("--hash-file", options.hash_files,
                 "File whose SHA-256 goes into the manifest (repeatable: URDF, scene, ...)");
  if (const auto code = ParseCommandLine(&app, common, argc, argv, out, err)) return *code;
  options.queue_capacity_bytes = queue_mb << 20;
  for (int i = 0; i < argc; ++i) options.command_line += (i ? " " : "") + std::string(argv[i]);
  try {
    Logger logger(common, options);
    return logger.Run();
  } catch (const std::invalid_argument& e) {  // a bad flag value (e.g. the --channels regex)
    err << "orbed-logger: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << "orbed-logger: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace orbed::logger
