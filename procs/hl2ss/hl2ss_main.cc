/// @file
/// orbed-hl2ss: the emulated headset served over the hl2ss protocol (what, flags and exit codes:
/// procs/hl2ss/hl2ss_process.h and --help).
#include <iostream>

#include "procs/hl2ss/hl2ss_process.h"

int main(int argc, char** argv) { return orbed::hl2ss::RunHl2ss(argc, argv, std::cout, std::cerr); }
