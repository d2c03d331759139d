/// @file
/// orbed-monitor: prints the testbed's health (every process's heartbeat, the logger's state).
/// Subscribes: PROCESS_STATUS, LOGGER_STATUS. Publishes: PROCESS_STATUS (its own heartbeat).
#include <iostream>

#include "procs/monitor/monitor.h"

int main(int argc, char** argv) {
  CLI::App app{
      "orbed-monitor: print a table of every orbed process's heartbeat and the logger's\n"
      "state, flagging processes whose heartbeat stopped."};
  orbed::CommonFlags common("orbed-monitor");
  orbed::AddCommonFlags(&app, &common);
  orbed::monitor::MonitorOptions options;
  app.add_option("--print-period-sec", options.print_period_sec, "Table period")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--silent-after-sec", options.silent_after_sec,
                 "Heartbeat age after which a process is shown as SILENT")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  orbed::ApplyCommonFlags(common);
  try {
    orbed::monitor::Monitor monitor(common, options);
    return monitor.Run();
  } catch (const std::exception& e) {
    std::cerr << "orbed-monitor: " << e.what() << "\n";
    return 1;
  }
}
