/// @file
/// orbed-drake-viewer: the testbed in Drake's viewer (what, flags and exit codes:
/// procs/drake_viewer/drake_viewer_process.h and --help).
#include <iostream>

#include "procs/drake_viewer/drake_viewer_process.h"

int main(int argc, char** argv) { return orbed::viewer::RunViewerBridge(argc, argv, std::cout, std::cerr); }
