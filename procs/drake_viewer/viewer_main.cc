/// @file
/// orbed-drake-viewer: the testbed in Drake's viewer (what, flags and exit codes:
/// procs/drake_viewer/viewer_bridge.h and --help).
#include <iostream>

#include "procs/drake_viewer/viewer_bridge.h"

int main(int argc, char** argv) { return orbed::viewer::RunViewerBridge(argc, argv, std::cout, std::cerr); }
