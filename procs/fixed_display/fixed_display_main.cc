/// @file
/// orbed-fixed-display: the set-up study's fixed monitor on FIXED_VIEW (what, flags and exit codes:
/// procs/fixed_display/fixed_display_process.h and --help).
#include <iostream>

#include "procs/fixed_display/fixed_display_process.h"

int main(int argc, char** argv) {
  return orbed::fixed_display::RunFixedDisplay(argc, argv, std::cout, std::cerr);
}
