/// @file
/// orbed-foxglove-bridge: the testbed live in Foxglove (what, flags and exit codes:
/// procs/foxglove_bridge/foxglove_bridge_process.h and --help).
#include <iostream>

#include "procs/foxglove_bridge/foxglove_bridge_process.h"

int main(int argc, char** argv) {
  return orbed::foxglove::RunFoxgloveBridge(argc, argv, std::cout, std::cerr);
}
