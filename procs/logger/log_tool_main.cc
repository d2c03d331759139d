/// @file
/// orbed-log: info, check and cut of LCM event logs (what, flags and exit codes: procs/logger/log_tool.h).
#include <iostream>

#include "procs/logger/log_tool.h"

int main(int argc, char** argv) { return orbed::logger::RunLogTool(argc, argv, std::cout, std::cerr); }
