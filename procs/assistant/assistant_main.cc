/// @file
/// orbed-assistant: the emulated set-up assistant (what, flags and exit codes:
/// procs/assistant/assistant_process.h and --help).
#include <iostream>

#include "procs/assistant/assistant_process.h"

int main(int argc, char** argv) { return orbed::assistant::RunAssistant(argc, argv, std::cout, std::cerr); }
