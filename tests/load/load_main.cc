/// @file
/// orbed-load: the testbed at F times its nominal rates, measured; flags and exit codes:
/// tests/load/load_cli.h.
#include <iostream>

#include "tests/load/load_cli.h"

int main(int argc, char** argv) { return orbed::load::RunLoadCli(argc, argv, std::cout, std::cerr); }
