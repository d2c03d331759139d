/// @file
/// orbed-launch: starts, watches, restarts and stops the testbed from a YAML launch file; flags and
/// exit codes: procs/launcher/launcher_cli.h.
/// Subscribes: PROCESS_STATUS (readiness). Publishes: PROCESS_STATUS (its own heartbeat).
#include <iostream>

#include "procs/launcher/launcher_cli.h"

int main(int argc, char** argv) { return orbed::launcher::RunLauncher(argc, argv, std::cout, std::cerr); }
