/// @file
/// orbed-user-study: the ViRAAl experiment without the bus, for as many trials as wanted (what,
/// flags and exit codes: experiments/viraal/study_cli.h). Publishes and subscribes nothing.
#include <iostream>

#include "experiments/viraal/study_cli.h"

int main(int argc, char** argv) { return orbed::study::RunUserStudy(argc, argv, std::cout, std::cerr); }
