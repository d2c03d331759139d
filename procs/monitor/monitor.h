#pragma once
/// @file
/// orbed-monitor's engine: watches the testbed's health. Keeps the latest PROCESS_STATUS of every
/// process and the latest LOGGER_STATUS, prints a compact table every `print_period_s` (with each
/// process's host), and flags a process as SILENT when its heartbeat is older than
/// `silent_after_s`. The moments a process falls silent and is heard again are printed at once
/// (checked every 0.1 s), e.g. "hmd on hostC: SILENT (no heartbeat for 3.0 s)" and "hmd on hostC:
/// heard again after 5.2 s": a partition or a hung process shows without waiting for the table.
///
/// Threading: everything on the Process::Run thread.

#include <iostream>
#include <map>
#include <string>

#include <orbed/logger_status_t.hpp>
#include <orbed/process_status_t.hpp>

#include "runtime/process.h"

namespace orbed::monitor {

struct MonitorOptions {
  double print_period_s = 5.0;
  double silent_after_s = 3.0;
  /// Where the table is printed every print_period_s (nullptr: nowhere).
  std::ostream* out = &std::cout;
};

class Monitor {
 public:
  Monitor(const CommonFlags& flags, MonitorOptions options);
  int Run() { return process_.Run(); }
  /// The table as it would be printed now (receive-time ages measured against `now_utime`).
  std::string Table(int64_t now_utime) const;
  /// The lines for processes that fell silent since the last call (receive-time ages against
  /// `now_utime`); each is said once until the process is heard again.
  std::string NewlySilent(int64_t now_utime);
  Process& process() { return process_; }

 private:
  struct Seen {
    orbed::process_status_t status;
    int64_t recv_utime = 0;
    bool silent = false;  // said to be silent, not heard since
  };
  MonitorOptions options_;
  Process process_;
  std::map<std::string, Seen> processes_;
  bool have_logger_ = false;
  orbed::logger_status_t logger_{};
};

}  // namespace orbed::monitor
