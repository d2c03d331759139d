/// @file
/// orbed-guidance: joint-by-joint set-up guidance on GUIDANCE (what, flags and exit codes:
/// procs/guidance/guidance_process.h and --help).
#include <iostream>

#include "procs/guidance/guidance_process.h"

int main(int argc, char** argv) { return orbed::guidance::RunGuidance(argc, argv, std::cout, std::cerr); }
