/// @file
/// orbed-setup-study: the robot set-up study without the bus, for as many users and studies as
/// wanted (what, flags and exit codes: experiments/setup/setup_study_cli.h). Publishes and
/// subscribes nothing.
#include <iostream>

#include "experiments/setup/setup_study_cli.h"

int main(int argc, char** argv) { return orbed::setup::RunSetupStudy(argc, argv, std::cout, std::cerr); }
