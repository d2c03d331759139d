/// @file
/// orbed-monitor: prints the testbed's health (every process's heartbeat, the logger's state); flags
/// and exit codes: procs/monitor/monitor_cli.h.
/// Subscribes: PROCESS_STATUS, LOGGER_STATUS. Publishes: PROCESS_STATUS (its own heartbeat).
#include <iostream>

#include "procs/monitor/monitor_cli.h"

int main(int argc, char** argv) { return orbed::monitor::RunMonitor(argc, argv, std::cout, std::cerr); }
