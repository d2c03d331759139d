/// @file
/// orbed-scenario: runs the paper's ViRAAl experiment (Sec. III-B, Table 1) over the bus and exits:
/// 0 when every session finished, 1 with a one-line reason otherwise (flags in scenario_cli.h, the
/// process in scenario_process.h, the run's phases in viraal_conductor.h).
/// Subscribes: ROBOT_STATE, PLAN_CHECK_REPLY, ALIGNMENT_TRIAL, REGISTRATION, MISALIGNMENT.
/// Publishes:  PLAN_CHECK_REQUEST, SESSION_CONTROL (START / REQUEST_TRIAL / COMPUTE / STOP),
///             IIWA_COMMAND, MISALIGNMENT_REQUEST, PROCESS_STATUS (1 Hz).
/// Writes results.json to --results-dir (default $ORBED_LOG_DIR, else the working directory) and
/// prints a progress line per step and a table at the end on stdout.
#include <iostream>

#include "procs/scenario/scenario_cli.h"

int main(int argc, char** argv) { return orbed::scenario::RunScenario(argc, argv, std::cout, std::cerr); }
