#include "procs/monitor/monitor_cli.h"

#include <exception>

#include <CLI/CLI.hpp>

#include "procs/monitor/monitor.h"
#include "runtime/flags.h"

namespace orbed::monitor {

int RunMonitor(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-monitor: print a table of every orbed process's heartbeat and the logger's\n"
      "state, flagging processes whose heartbeat stopped."};
  CommonFlags common("orbed-monitor");
  AddCommonFlags(&app, &common);
  MonitorOptions options;
  options.out = &out;
  app.add_option("--print-period-s", options.print_period_s, "Table period")
      ->check(orbed::PositiveNumber())
      ->capture_default_str();
  app.add_option("--silent-after-s", options.silent_after_s,
                 "Heartbeat age after which a process is shown as SILENT")
      ->check(orbed::PositiveNumber())
      ->capture_default_str();
  if (const auto code = ParseCommandLine(&app, common, argc, argv, out, err)) return *code;
  try {
    Monitor monitor(common, options);
    return monitor.Run();
  } catch (const std::exception& e) {
    err << "orbed-monitor: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace orbed::monitor
