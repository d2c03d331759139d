/// @file
/// orbed-logger: records LCM traffic to a standard LCM event log plus manifest.json (flags and exit
/// codes: procs/logger/logger_cli.h).
/// Subscribes: every channel matching --channels (default all).
/// Publishes: LOGGER_STATUS (logger_status_t, 1 Hz), PROCESS_STATUS (1 Hz).
#include <iostream>

#include "procs/logger/logger_cli.h"

int main(int argc, char** argv) { return orbed::logger::RunLogger(argc, argv, std::cout, std::cerr); }
