/// @file
/// orbed-hmd: the emulated headset (HoloLens 1) and the person wearing it. Flags, channels and exit
/// codes: hmd_emulator/hmd_cli.h; the process: hmd_emulator/hmd_process.h.
#include <iostream>

#include "hmd_emulator/hmd_cli.h"

int main(int argc, char** argv) { return orbed::hmd::RunHmd(argc, argv, std::cout, std::cerr); }
