/// @file
/// orbed-setup: one user's part of the robot set-up study (what, flags and exit codes:
/// procs/setup/setup_process.h and --help).
#include <iostream>

#include "procs/setup/setup_process.h"

int main(int argc, char** argv) { return orbed::setup::RunSetup(argc, argv, std::cout, std::cerr); }
