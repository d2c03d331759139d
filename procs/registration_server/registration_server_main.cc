/// @file
/// orbed-registration: the registration server and its offline command line (commands, flags and
/// exit codes: procs/registration_server/registration_server_cli.h).
///
///   orbed-registration [--lcm-url URL] [--state-period-s S] [--model-centroid-m X,Y,Z] ...
///     The LCM server (registration_server_process.h).
///     Subscribes: SESSION_CONTROL, ALIGNMENT_TRIAL, LANDMARK_REQUEST, MISALIGNMENT_REQUEST.
///     Publishes:  REGISTRATION (per accepted trial, on COMPUTE, and the full state every
///                 --state-period-s), LANDMARK, MISALIGNMENT, PROCESS_STATUS (1 Hz).
///   orbed-registration mean --input FILE ...   offline SE(3) mean of a trial file; no network.
///   orbed-registration send --input FILE ...   a trial file to a running server, as one session.
///     Publishes SESSION_CONTROL, ALIGNMENT_TRIAL; subscribes REGISTRATION.
#include <iostream>

#include "procs/registration_server/registration_server_cli.h"

int main(int argc, char** argv) {
  return orbed::registration::RunRegistration(argc, argv, std::cout, std::cerr);
}
