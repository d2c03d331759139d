/// @file
/// orbed-igtl-bridge: the testbed over OpenIGTLink (what, flags and exit codes:
/// procs/igtl_bridge/igtl_bridge_process.h and --help).
#include <iostream>

#include "procs/igtl_bridge/igtl_bridge_process.h"

int main(int argc, char** argv) {
  return orbed::igtl_bridge::RunIgtlBridge(argc, argv, std::cout, std::cerr);
}
