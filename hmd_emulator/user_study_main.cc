/// @file
/// orbed-user-study: runs the emulated ViRAAl study (user_study.h) and prints, per display mode, the
/// error statistics next to the paper's Table 1, and the rank tests comparing the modes (flags and
/// exit codes: hmd_emulator/user_study_cli.h). No LCM: publishes and subscribes nothing.
#include <iostream>

#include "hmd_emulator/user_study_cli.h"

int main(int argc, char** argv) { return orbed::hmd::RunUserStudy(argc, argv, std::cout, std::cerr); }
